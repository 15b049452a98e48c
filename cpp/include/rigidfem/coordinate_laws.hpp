/// The laws of a joint coordinate q (m or rad): the generalised force Q(t, q, q̇) (N or N·m) each puts on it,
/// its derivatives, the energy it stores and the power it dissipates. Every coordinate has its own linear
/// spring-damping law (SpringDamping: the book's sde, and a joint's spring, damper and constant force); further
/// laws (CoordinateLaw: a Python function, friction) are listed per coordinate. The algorithms reach them through
/// coordinate_force and coordinate_derivatives (kinematics.hpp), coordinate_energy and coordinate_power
/// (outputs.cpp) and the spring matrix (newton_matrix.hpp), never by a law's name.
#pragma once

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rigidfem/laws.hpp"

namespace rigidfem {

/// The linear spring-damping law of a joint coordinate, scaled by s (Data::spring_scale: L₀/L on the sdes of a
/// link of varying length, else 1), with a constant applied force scaled by the load factor λ:
///   Q = −s (k (q − q⁰) + c q̇) + λ Q₀,   stores ½ s k (q − q⁰)²,   dissipates s c q̇².
/// One type, called directly (no virtual call: it is on every coordinate of every evaluation).
struct SpringDamping {
  double stiffness = 0.0;  ///< k, N/m or N·m/rad
  double rest = 0.0;       ///< q⁰, m or rad
  double damping = 0.0;    ///< c, N·s/m or N·m·s/rad
  double force = 0.0;      ///< Q₀, N or N·m (applied: scaled by the load factor)

  static const LawInfo& description() {
    static const LawInfo info{
        "SpringDamping", "coordinate",
        "Q = −k (q − q⁰) − c q̇ + Q₀ (N or N·m): a joint coordinate's spring, damper and constant generalised force "
        "(an sde's springs and dampers); stores ½ k (q − q⁰)², dissipates c q̇²",
        {{"stiffness", "N/m", "N m/rad", 0.0, 0.0, false, "the coordinate's spring", true},
         {"rest", "m", "rad", 0.0, -std::numeric_limits<double>::infinity(), false, "the spring's rest value q⁰", false},
         {"damping", "N s/m", "N m s/rad", 0.0, 0.0, false, "the coordinate's damper", true},
         {"force", "N", "N m", 0.0, -std::numeric_limits<double>::infinity(), false,
          "the constant generalised force on the coordinate", true}},
        nullptr, nullptr, nullptr, nullptr};
    return info;
  }
  /// The constants in the description's order, and one of them set by its index (parameters.hpp).
  std::vector<double> values() const { return {stiffness, rest, damping, force}; }
  void set(int index, double value) { (index == 0 ? stiffness : index == 1 ? rest : index == 2 ? damping : force) = value; }
  bool operator!=(const SpringDamping& o) const {
    return stiffness != o.stiffness || rest != o.rest || damping != o.damping || force != o.force;
  }

  /// −s (k (q − q⁰) + c q̇): the spring and damper alone.
  double elastic_force(double q, double qd, double s) const { return -s * (stiffness * (q - rest) + damping * qd); }
  /// −δQ along (δq, δq̇): s (k δq + c δq̇).
  double variation(double dq, double dqd, double s) const { return s * (stiffness * dq + damping * dqd); }
  /// (∂Q/∂q, ∂Q/∂q̇) = (−s k, −s c).
  std::pair<double, double> derivatives(double s) const { return {-s * stiffness, -s * damping}; }
  /// ½ s k (q − q⁰)² (J); 0 without a spring (not 0 · ∞ at a huge q).
  double energy(double q, double s) const { return stiffness != 0.0 ? 0.5 * s * stiffness * std::pow(q - rest, 2) : 0.0; }
  /// s c q̇² (W).
  double power(double qd, double s) const { return s * damping * qd * qd; }
  /// s (c₁ c + c₂ k): the law's part of the spring matrix M + diag(c₁ C + c₂ K) (newton_matrix.hpp).
  template <class Scalar>
  Scalar armature(Scalar c1, Scalar c2, double s) const {
    return s * (c1 * damping + c2 * stiffness);
  }
};

/// A further law on a joint coordinate, in one class per kind (ForceFunction, Friction below), each describing
/// itself (laws.hpp). A new kind is a class here and its row in coordinate_law_kinds(); Model.add_joint_law, the
/// named parameters and the site's table read the row.
class CoordinateLaw : public Law {
 public:
  /// SimulationError where the law cannot be evaluated at t (on coordinate `name`); nothing by default.
  virtual void check(double /*t*/, const std::string& /*name*/) const {}
  /// Q(t, q, q̇) (N or N·m), its applied part scaled by the load factor λ (passive parts, as friction, are not).
  virtual double force(double t, double q, double qd, double load_factor) const = 0;
  /// (∂Q/∂q, ∂Q/∂q̇) at (t, q, q̇) and λ.
  virtual std::pair<double, double> derivatives(double t, double q, double qd, double load_factor) const = 0;
  /// The energy (J) it stores at q, and the power (W) it dissipates at (q, q̇); none by default.
  virtual double energy(double /*t*/, double /*q*/) const { return 0.0; }
  virtual double power(double /*t*/, double /*q*/, double /*qd*/) const { return 0.0; }
  /// A copy with the constant `name` set to `value` (a named parameter), unchecked.
  std::shared_ptr<const CoordinateLaw> with_constant(const std::string& name, double value) const {
    auto law = clone();
    law->set(constant_index(name), value);
    return law;
  }

 protected:
  using Law::Law;
  virtual std::shared_ptr<CoordinateLaw> clone() const = 0;
};

/// A generalised force given as a Python function Q(t, q, q̇) of the coordinate's own value and rate, applied
/// (scaled by λ); its derivatives by central differences (steps 6e-6 max(1, |x|)). The slow path: called under
/// the GIL at every evaluation.
class ForceFunction final : public CoordinateLaw {
 public:
  static const LawInfo& description() {
    static const LawInfo info{"ForceFunction", "coordinate",
                              "Q = Q(t, q, q̇) (N or N·m): a Python function of time (s) and the coordinate's value "
                              "and rate, applied (scaled by the load factor of statics)",
                              {},
                              nullptr,
                              nullptr,
                              nullptr,
                              "Q(t, q, qd) in N or N·m, its derivatives by central differences"};
    return info;
  }
  ForceFunction(std::vector<double> values, ScalarFunction f) : CoordinateLaw(std::move(values)), f_(std::move(f)) {}
  const LawInfo& info() const override { return description(); }
  double force(double t, double q, double qd, double load_factor) const override { return load_factor * f_(t, q, qd); }
  std::pair<double, double> derivatives(double t, double q, double qd, double load_factor) const override {
    const double hq = difference_step(q), hd = difference_step(qd);
    return {load_factor * ((f_(t, q + hq, qd) - f_(t, q - hq, qd)) / (2.0 * hq)),
            load_factor * ((f_(t, q, qd + hd) - f_(t, q, qd - hd)) / (2.0 * hd))};
  }

 private:
  std::shared_ptr<CoordinateLaw> clone() const override { return std::make_shared<ForceFunction>(*this); }
  ScalarFunction f_;
};

/// Dry and viscous friction, regularised (smooth): with v = q̇,
///   Q = −g(v) tanh(v/v_ε) − b v,   g(v) = F_C + (F_S − F_C) e^{−(v/v_S)²},
/// the breakaway force F_S near rest falling to the Coulomb force F_C beyond the Stribeck velocity v_S, and a
/// viscous b. Regularised rather than switched between stick and slip: a smooth Q lets every method, the error
/// control, the sensitivities and the adjoint run unchanged, at the price of a creep |v| ~ v_ε Q_held/F_S where the
/// joint should stick (v_ε, `smoothing`, sets it; ∂Q/∂q̇ ≈ −F_S/v_ε near rest is stiff: an implicit method's).
/// Passive: not scaled by the load factor; stores nothing, dissipates −Q v ≥ 0.
class Friction final : public CoordinateLaw {
 public:
  enum { FS, FC, VS, B, VE };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "Friction", "coordinate",
        "Q = −(F_C + (F_S − F_C) exp(−(q̇/v_S)²)) tanh(q̇/v_ε) − b q̇ (N or N·m): dry friction with a Stribeck "
        "fall from the breakaway F_S to the Coulomb F_C, and viscous friction b, regularised over v_ε",
        {{"breakaway", "N", "N m", 0.0, 0.0, false, "the breakaway (static) friction F_S", true},
         {"coulomb", "N", "N m", 0.0, 0.0, false, "the Coulomb (kinetic) friction F_C", true},
         {"stribeck", "m/s", "rad/s", 0.01, 0.0, true, "the Stribeck velocity v_S", false},
         {"viscous", "N s/m", "N m s/rad", 0.0, 0.0, false, "the viscous friction b", true},
         {"smoothing", "m/s", "rad/s", 1e-4, 0.0, true, "the regularising velocity v_ε of tanh(q̇/v_ε)", false}},
        nullptr,
        nullptr,
        nullptr,
        nullptr};
    return info;
  }
  explicit Friction(std::vector<double> values) : CoordinateLaw(std::move(values)) {}
  const LawInfo& info() const override { return description(); }
  double force(double, double, double v, double) const override { return friction().force(v); }
  /// (0, dQ/dq̇): laws.hpp's RegularisedFriction.
  std::pair<double, double> derivatives(double, double, double v, double) const override {
    return {0.0, friction().rate_derivative(v)};
  }
  double power(double t, double q, double v) const override { return -force(t, q, v, 1.0) * v; }

 private:
  RegularisedFriction friction() const { return {c_[FS], c_[FC], c_[VS], c_[B], c_[VE]}; }
  std::shared_ptr<CoordinateLaw> clone() const override { return std::make_shared<Friction>(*this); }
};

/// A kind of law of a joint coordinate as the bindings make it: its description and its maker (constants in the
/// description's order, a Python function where it takes one).
struct CoordinateLawKind {
  const LawInfo& (*info)();
  std::shared_ptr<const CoordinateLaw> (*make)(std::vector<double> values, ScalarFunction function);
};

/// Every kind of law a joint coordinate takes beyond its own spring-damping law, each once.
inline const std::vector<CoordinateLawKind>& coordinate_law_kinds() {
  static const std::vector<CoordinateLawKind> kinds = {
      {ForceFunction::description,
       [](std::vector<double> v, ScalarFunction f) -> std::shared_ptr<const CoordinateLaw> {
         return std::make_shared<ForceFunction>(std::move(v), std::move(f));
       }},
      {Friction::description,
       [](std::vector<double> v, ScalarFunction) -> std::shared_ptr<const CoordinateLaw> {
         return std::make_shared<Friction>(std::move(v));
       }},
  };
  return kinds;
}

}  // namespace rigidfem
