/// Compliant contact between shapes fixed on bodies: what a shape is, what a contact pairs, and the law of its
/// force. A contact pushes two bodies apart wherever their shapes overlap, with a normal force of the penetration
/// δ and its rate (no impulse, no jump: the force rises from 0 at first touch) and a regularised Coulomb friction
/// against the slip at the contact point; contact_forces.hpp finds the overlaps at a state and their forces.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "rigidfem/errors.hpp"
#include "rigidfem/laws.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// The kinds of shape. Spheres and capsules are swept spheres (a point or a segment and a radius); a box touches
/// a half-space by its eight corners; a half-space is the solid below a plane (the ground, a deck).
enum class ShapeKind { Sphere, Capsule, Box, HalfSpace };

/// The kind's name in Python ("sphere", "capsule", "box", "half_space").
inline const char* shape_kind_name(ShapeKind kind) {
  static const char* names[] = {"sphere", "capsule", "box", "half_space"};
  return names[static_cast<int>(kind)];
}

/// A shape fixed in the frame of body `body` (−1: the ground), lengths in m:
///   sphere: centre a, radius r;   capsule: the segment a–b swept by a sphere of radius r;
///   box: centre a, half-extents h along the columns of R (its axes in the body frame);
///   half-space: the points x with n·(x − a) ≤ 0, n the unit outward normal of its plane.
struct Shape {
  std::string name;
  int body = -1;
  ShapeKind kind = ShapeKind::Sphere;
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  Vec3 n = Vec3::UnitZ();     ///< half-space: outward unit normal
  Vec3 h = Vec3::Zero();      ///< box: half-extents
  Mat3 R = Mat3::Identity();  ///< box: axes
  double radius = 0.0;        ///< sphere, capsule
};

/// The compliant contact law, with the penetration δ > 0 of two shapes, its rate δ̇ and the slip v_t (the tangential
/// velocity of body b relative to body a at the contact point):
///   F_n = k δᵖ (1 + α δ̇)  (N, pushing the bodies apart; 0 where that is negative),
///   f_t = −μ(|v_t|) F_n tanh(|v_t|/v_ε) v_t/|v_t|,   μ(v) = μ_k + (μ_s − μ_k) e^{−(v/v_S)²}.
/// p = 1 is a linear contact, p = 3/2 Hertz's contact of curved bodies. The dissipation α (Hunt–Crossley) is set by
/// the coefficient of restitution e at the impact speed v_e: an impact at v_e leaves at e v_e, whatever k and p (a
/// free impact conserves v − ln(1 + α v)/α, so u = α v_e solves u (1 + e) = ln((1 + u)/(1 − e u))); slower impacts
/// rebound a little more, faster ones less, as Hunt and Crossley's law does. The friction is regularised rather
/// than switched between stick and slip, as the joints' Friction law is (coordinate_laws.hpp): the force is smooth,
/// so every method, the error control and the Jacobians run unchanged, at the price of a creep |v_t| ~ v_ε where
/// the bodies should stick. Stores k δᵖ⁺¹/(p + 1); dissipates k α δᵖ δ̇² and −f_t·v_t.
class ContactLaw final : public Law {
 public:
  enum { K, P, E, VE_IMPACT, MU_S, MU_K, VS, VEPS };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "Contact", "contact",
        "F_n = k δᵖ (1 + α δ̇) (N, pushing the bodies apart while positive), α set by the restitution e at the impact "
        "speed v_e; friction f_t = −(μ_k + (μ_s − μ_k) exp(−(v_t/v_S)²)) F_n tanh(|v_t|/v_ε) v_t/|v_t| against the "
        "slip v_t",
        {{"stiffness", "N/m^p", nullptr, 1e6, 0.0, true, "the contact stiffness k (F_n = k δᵖ)", true},
         {"exponent", "1", nullptr, 1.5, 1.0, false, "the exponent p of the penetration (1 linear, 1.5 Hertz)", false},
         {"restitution", "1", nullptr, 1.0, 0.0, true, "the coefficient of restitution e at the impact speed", true,
          false, 1.0},
         {"impact_speed", "m/s", nullptr, 1.0, 0.0, true, "the impact speed v_e at which the restitution is e",
          false},
         {"mu_s", "1", nullptr, 0.0, 0.0, false, "the static friction coefficient μ_s", true},
         {"mu_k", "1", nullptr, 0.0, 0.0, false, "the kinetic friction coefficient μ_k", true},
         {"stribeck", "m/s", nullptr, 0.01, 0.0, true, "the Stribeck velocity v_S", false},
         {"smoothing", "m/s", nullptr, 1e-4, 0.0, true, "the regularising slip velocity v_ε of tanh(|v_t|/v_ε)",
          false}},
        nullptr,
        nullptr,
        nullptr,
        nullptr};
    return info;
  }
  explicit ContactLaw(std::vector<double> values) : Law(std::move(values)) { set_alpha(); }
  /// A copy with the constant `name` set to `value` (a named parameter: parameters.hpp; the force is linear in those
  /// marked so, k, μ_s and μ_k), unchecked; std::invalid_argument for a name the law does not have.
  std::shared_ptr<const ContactLaw> with_constant(const std::string& name, double value) const {
    auto law = std::make_shared<ContactLaw>(*this);
    law->set(constant_index(name), value);
    law->set_alpha();
    return law;
  }
  const LawInfo& info() const override { return description(); }
  /// Hunt–Crossley's α (s/m).
  double alpha() const { return alpha_; }
  /// F_n(δ, δ̇) (N): k δᵖ (1 + α δ̇) where δ > 0 and that is positive, else 0 (S: double or an automatic derivative).
  template <class S>
  S normal(const S& delta, const S& delta_rate) const {
    using std::pow;
    if (!(delta > 0.0)) return S(0.0);
    const S F = c_[K] * pow(delta, c_[P]) * (1.0 + alpha_ * delta_rate);
    return F > 0.0 ? F : S(0.0);
  }
  /// The friction force f_t (N) on body b against its slip v_t (⊥ the normal), of the normal force F_n.
  template <class S>
  Eigen::Matrix<S, 3, 1> friction(const S& Fn, const Eigen::Matrix<S, 3, 1>& vt) const {
    using std::exp, std::sqrt, std::tanh;
    if (c_[MU_S] == 0.0 && c_[MU_K] == 0.0) return Eigen::Matrix<S, 3, 1>::Zero();
    const S s2 = vt.dot(vt);
    const S mu = c_[MU_K] + (c_[MU_S] - c_[MU_K]) * exp(-s2 / (c_[VS] * c_[VS]));
    // tanh(s/v_ε)/s, smooth at s = 0 (1/v_ε (1 − s²/(3 v_ε²)) below 1e-4 v_ε, where the series is exact to 1e-16)
    const double ve = c_[VEPS];
    S phi;
    if (s2 < 1e-8 * ve * ve) {
      phi = (1.0 - s2 / (3.0 * ve * ve)) / ve;
    } else {
      const S s = sqrt(s2);
      phi = tanh(s / ve) / s;
    }
    return -(mu * Fn * phi) * vt;
  }
  /// The energy (J) stored at the penetration δ: k δᵖ⁺¹/(p + 1).
  double energy(double delta) const { return delta > 0.0 ? c_[K] * std::pow(delta, c_[P] + 1.0) / (c_[P] + 1.0) : 0.0; }
  /// The power (W) dissipated: k α δᵖ δ̇² by the normal force while it pushes, −f_t·v_t by friction.
  double power(double delta, double delta_rate, double Fn, const Vec3& ft, const Vec3& vt) const {
    const double normal = Fn > 0.0 ? c_[K] * alpha_ * std::pow(delta, c_[P]) * delta_rate * delta_rate : 0.0;
    return normal - ft.dot(vt);
  }

  /// u = α v_e of the restitution e ∈ (0, 1): the root in (0, 1/e) of f(u) = ln(1 + u) − ln(1 − e u) − u (1 + e).
  /// f(0) = f'(0) = 0, f'' increases from e² − 1 < 0 and f → ∞ at 1/e: f is negative, then positive, with one root,
  /// bisected. Below 1 − e = 1e-6 its series root 3 (1 − e²)/(2 (1 + e³)) (Hunt–Crossley's 3(1 − e)/2 as e → 1).
  static double hunt_crossley_rate(double e) {  // (see set_alpha)
    if (1.0 - e < 1e-6) return 1.5 * (1.0 - e * e) / (1.0 + e * e * e);
    const auto f = [e](double u) { return std::log1p(u) - std::log1p(-e * u) - u * (1.0 + e); };
    double lo = 0.5 / e, hi = 1.0 / e;
    while (!(f(lo) < 0.0)) hi = lo, lo *= 0.5;  // f(lo) < 0 < f(hi)
    for (int k = 0; k < 100 && lo < hi; ++k) {
      const double m = 0.5 * (lo + hi);
      if (m <= lo || m >= hi) break;
      (f(m) < 0.0 ? lo : hi) = m;
    }
    return 0.5 * (lo + hi);
  }

 private:
  void set_alpha() {
    alpha_ = c_.size() == description().constants.size() && c_[E] > 0.0 && c_[E] < 1.0 && c_[VE_IMPACT] > 0.0
                 ? hunt_crossley_rate(c_[E]) / c_[VE_IMPACT]
                 : 0.0;
  }
  double alpha_ = 0.0;
};

/// A kind of contact law as the bindings make it (contact_law_kinds() lists them).
struct ContactLawKind {
  const LawInfo& (*info)();
  std::shared_ptr<const ContactLaw> (*make)(std::vector<double> values);
};

/// Every kind of contact law, each once.
inline const std::vector<ContactLawKind>& contact_law_kinds() {
  static const std::vector<ContactLawKind> kinds = {
      {ContactLaw::description,
       [](std::vector<double> v) -> std::shared_ptr<const ContactLaw> { return std::make_shared<ContactLaw>(std::move(v)); }},
  };
  return kinds;
}

/// A contact as the user declares it: every shape of `shapes_a` against every shape of `shapes_b` (indices into
/// the model's shapes; pairs on one body never touch), with its law.
struct Contact {
  std::string name;
  std::vector<int> shapes_a, shapes_b;
  std::shared_ptr<const ContactLaw> law;
};

}  // namespace rigidfem
