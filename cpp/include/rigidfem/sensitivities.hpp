/// Forward sensitivities: the derivatives S_j = ∂y/∂p_j of the state y = [q, q̇] with respect to a few
/// parameters p_j, integrated with the state (book-keeping in integrate.cpp: y carries [q, q̇, s, S_1 .. S_P]).
///
/// Differentiating A(q; p) q̈ = f(q, q̇, t; p) gives the sensitivity equations
///   A S̈_q + (∂r/∂q) S_q + (∂r/∂q̇) S_q̇ + ∂r/∂p = 0,      r = A q̈ − f,
/// with closed loops M S̈ + … = Gᵀ δλ and G S̈ = δγ (δγ with ∂γ/∂p: a drive's or an actuator's numbers move the
/// loops' g(q, t; p), loop_parameter_derivative). A parameter p_j comes as the system at p_j + h_j
/// (parameters.hpp: only constants the residual is linear in differ, so ∂r/∂p = (r(p + h) − r(p))/h exactly,
/// to round-off, whatever h: h = |p| keeps the round-off at that of r; a profile's coefficient, which the
/// residual is not linear in, by a central difference of the systems at p ± h), an initial value as S_j(t0). The
/// derivatives along (S_q, S_q̇) are K δq + C δq̇ + M δq̈ by the RNEA's forward-mode derivative (recursive systems:
/// exact, O(n) per direction, inverse_dynamics_direction), or else central differences of the residual along
/// the direction, scaled so that the largest relative change of q or q̇ is 6e-6 (near 1e-10 relative, but 1e-7
/// where an axial stiffness dwarfs a transverse one: a taut rope, a beam's axial spring), then
/// S̈ = −A⁻¹(…) with the forward dynamics' factorisation (O(n): the articulated-body algorithm's) and, with
/// loops, the multipliers' change by the Schur complement G A⁻¹ Gᵀ as in close_loops: O(n) per direction.
#pragma once

#include <memory>
#include <vector>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// One direction of differentiation: a parameter (the system at p + h, and at p − h for one the residual is not
/// linear in: a profile's coefficient, differenced centrally) or an initial value (both null).
struct SensitivityParameter {
  std::shared_ptr<const System> plus, minus;  ///< the system at p + h (p − h), or null
  double h = 0.0;                             ///< the parameter's step (its unit)
  VecX S0;                                    ///< (2 nq) [∂q₀/∂p, ∂q̇₀/∂p]
};

/// The sensitivity equations of one run: each parameter's systems and workspaces.
class SensitivityEquations {
 public:
  SensitivityEquations(const System& sys, const std::vector<SensitivityParameter>& parameters);
  int count() const { return static_cast<int>(parameters_.size()); }
  /// The initial sensitivities [S_1(t0) .. S_P(t0)] (2 nq P).
  VecX initial() const;

  /// Explicit methods: Ṡ_j = [S_q̇, S̈_j] of every parameter j into Sd (2 nq P) from S = [S_1 .. S_P]
  /// (S_j = [S_q, S_q̇]), with fd the workspace of the forward dynamics just evaluated at (t, q, q̇) (its q̈,
  /// λ and factorisation): A S̈ = −(D(r − Gᵀλ)[S] + ∂r/∂p) + Gᵀ δλ, G S̈ = D(γ − G q̈)[S].
  void rates(Data& fd, double t, const VecX& q, const VecX& qd, const Eigen::Ref<const VecX>& S,
             Eigen::Ref<VecX> Sd);

  /// Implicit methods: the derivative of the residual R = M q̈ − f − Gᵀλ (nq) along (δq, δq̇, δq̈, δλ) plus its
  /// ∂/∂p_j, at (t, q, q̇, q̈, λ) (λ and δλ empty without loops).
  VecX residual_derivative(int j, double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& lambda,
                           const VecX& dq, const VecX& dqd, const VecX& dqdd, const VecX& dlambda);

  /// The round-off of ∂r/∂p_j's difference per unit of force, 1/h_j (1/(2 h_j) central): the residuals differenced
  /// balance forces of size |f|, so the difference carries about ε |f| / h_j. 0 for an initial value (no difference).
  double difference_noise(int j) const;
  /// |f(q, q̇, t)| (nq), each coordinate's generalised force: the size of the terms a residual balances.
  VecX force_sizes(double t, const VecX& q, const VecX& qd);

  /// Loops: D(γ − G q̈)[δq, δq̇] + ∂(γ − G q̈)/∂p_j (nl) at (t, q, q̇) and fixed free accelerations q̈, by
  /// central differences: the right-hand side of G δq̈ in the index-1 equations' derivative.
  VecX acceleration_constraint_derivative(int j, double t, const VecX& q, const VecX& qd, const VecX& qdd,
                                          const VecX& dq, const VecX& dqd);

  /// Loops: the direct derivatives ∂g/∂p_j, ∂ġ/∂p_j and ∂(γ − G q̈)/∂p_j (nl each) at fixed (t, q, q̇, q̈). Only a
  /// drive's number moves the loops (g(q, t; p) through its prescribed coordinates); by the central difference
  /// of its systems at p ± h, zero for every other parameter.
  struct LoopRates {
    VecX g, gd, c;
  };
  LoopRates loop_parameter_derivative(int j, double t, const VecX& q, const VecX& qd, const VecX& qdd);

  /// Systems with loops: S = [S_q, S_q̇] of parameter j onto the tangent of the constraint manifold at
  /// (t, q, q̇), which is the derivative of the projection onto it (project_onto_loops) there:
  ///   S_q ← S_q − Y (G Y)⁺ (G S_q + ∂g/∂p),   S_q̇ ← S_q̇ − Y (G Y)⁺ (G S_q̇ + ∂ġ/∂q S_q + ∂ġ/∂p),   Y = M⁻¹ Gᵀ.
  void project(int j, double t, const VecX& q, const VecX& qd, Eigen::Ref<VecX> S);

 private:
  const System& sys_;
  std::vector<SensitivityParameter> parameters_;
  Data d_, e_;                                // workspaces on sys
  double base_t_ = 0.0;                       // the state of the last base residual R(p)
  VecX base_q_, base_qd_, base_qdd_, base_lambda_, base_r_;
  std::vector<std::unique_ptr<Data>> plus_, minus_;  // on each parameter's systems at p ± h
};

}  // namespace rigidfem
