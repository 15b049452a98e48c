/// What the adaptive methods measure their local error on: outputs of the system (rf.simulate's
/// error_on), or the state itself.
///
/// A step's error estimate e = (e_q, e_q̇) (2 nq) moves an output z(t, q, q̇) by δz = (∂z/∂q) e_q and its
/// rate by δż = (∂z/∂q) e_q̇, through the Jacobians at the step's start (the change of the Jacobian
/// with e_q, second order in the step's error, is left out). The velocity part counts as the
/// displacement it makes over the step, h δż, so that a mode the output does not see is not resolved
/// for its velocities either. The norm is the largest, over the outputs k,
///   ε_k = max(|δz_k|, h |δż_k|) / (atol + rtol · scale_k),
/// |·| Euclidean for a point (3) and a body, scale_k for points and bodies the larger of the model's size
/// L (m) and the farthest a body's centre of mass has moved from where it started (a motion that outgrows
/// the model, such as a diverging linear model, is then held relative to itself), and for coordinates,
/// element forces and loop reactions the largest |z_k| reached so far.
///
/// Kinds of output:
///   Bodies      every body with mass: the RMS displacement of its material, √(|δc|² + δθᵀ I_C δθ / m)
///               for the small rigid motion (δθ, δc) of its frame (I_C its inertia about the centre of
///               mass c, m its mass), m; the default of rf.simulate;
///   Point       a point fixed on a body, m;
///   Coordinate  a free coordinate q_k, m or rad;
///   Element     a force element's axial force F(t, l, l̇), N: δF = F_l δl + F_l̇ δl̇ (no velocity part);
///   Loop        a loop closure's multipliers λ (its reaction rows, N or N·m), by forward differences
///               of the constrained forward dynamics along e (no velocity part).
#pragma once

#include <algorithm>
#include <memory>
#include <vector>

#include "rigidfem/system.hpp"

namespace rigidfem {

struct OutputSpec {
  enum class Kind { Bodies, Point, Coordinate, Element, Loop };
  Kind kind = Kind::Bodies;
  int index = -1;          ///< Point: the body; Coordinate: index in q; Element, Loop: their index
  Vec3 r = Vec3::Zero();   ///< Point: m, in the body's frame
};

/// The outputs an error is measured on, with the scratch of their evaluation (one per run: not shared
/// between threads).
class ErrorMeasure {
 public:
  /// Checks the outputs (std::invalid_argument naming `error_on`) and measures the model's size L at
  /// (t0, q0): the diagonal of the box holding the bodies' origins and centres of mass and the joint
  /// frames on the ground (1 m for a model of no extent).
  ErrorMeasure(const System& sys, std::vector<OutputSpec> outputs, double t0, const VecX& q0);

  /// The linearisation point, the state y = [q, q̇, s] (2 nq + nz) at t (a step's start): the
  /// coordinates' axes, the elements' directions and derivatives, the loops' multipliers, and the
  /// running scales.
  void at(double t, const VecX& y);
  /// max_k ε_k (see the file comment) of the error e (2 nq) over the step h, with atol, rtol.
  double norm(const Eigen::Ref<const VecX>& e, double h, double atol, double rtol);

  double length() const { return L_; }  ///< L, m
  /// max(L, the farthest a centre of mass has moved from its place at t0 so far), m: the scale of points and bodies
  double reach() const { return std::max(L_, moved_); }

 private:
  /// δ_p = (δθ, δo) (6, ground coordinates at the origin) of every body for the coordinate changes dq:
  /// δ_p = δ_parent + Σ s_u dq_u over the uses of p's joint (the forward pass of a velocity).
  void twists(const Eigen::Ref<const VecX>& dq, std::vector<Vec6>& out) const;

  const System& sys_;
  std::vector<OutputSpec> outputs_;
  Data d_;
  std::unique_ptr<Data> dl_;           // the loops' forward dynamics (Loop outputs only)
  double L_ = 1.0;
  double t_ = 0.0;
  VecX y_, ye_, lambda_;               // the linearisation point; a perturbed one; λ there (nl)
  std::vector<Vec6> dq_, dv_;          // (nbodies) twists of e_q and e_q̇
  std::vector<Vec3> xc_, xc0_;         // (nbodies) centres of mass, global: now and at t0
  double moved_ = 0.0;                 // the farthest a centre of mass has moved from xc0_ so far (m)
  std::vector<Mat3> gyration_;         // (nbodies) R I_C Rᵀ / m, global (m²)
  std::vector<Vec3> element_e_;        // (nelements) unit vectors e of the elements
  std::vector<ExtensionDerivatives> element_dF_;  // (nelements) ∂F/∂(l, l̇, s, ṡ)
  VecX scale_;                          // (outputs) the running max |z_k| (coordinates, elements, loops)
  bool need_loops_ = false, need_elements_ = false;
};

}  // namespace rigidfem
