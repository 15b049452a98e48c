/// Force elements between two bodies, acting along the line between a point A on body a and a point B
/// on body b (book ch. 7.1, 7.3). With d = r_B − r_A, l = |d|, e = d / l and l̇ = e·ḋ the element
/// pushes the points apart with its kind's axial force F(t, l, l̇) (N, > 0 pushing): the force F e on B
/// at r_B and −F e on A at r_A. The kinds: SpringDamper (a spring-damper or a hydraulic cylinder under
/// force control) and Rope (tension only, paid out by a winch).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "rigidfem/errors.hpp"
#include "rigidfem/profiles.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// An axial force function F(t, l, l̇) (N) of an element's length l (m) and rate l̇ (m/s): a Python law.
using AxialFunction = std::function<double(double, double, double)>;

/// What a kind of force element knows, in one class per kind (SpringDamper, Rope below): its parameters'
/// checks, its axial force and the force's derivatives, the energy it stores and the power it dissipates.
/// A new kind is a class here, its maker in bind_model.cpp and its builder in force_elements.py.
class ElementLaw {
 public:
  virtual ~ElementLaw() = default;
  /// std::invalid_argument naming the first bad parameter (Model::add_force_element calls it after the
  /// points' checks).
  virtual void validate() const = 0;
  /// SimulationError where the law cannot be evaluated at t (element `name`); nothing by default.
  virtual void check(double /*t*/, const std::string& /*name*/) const {}
  /// F(t, l, l̇) (N, > 0 pushing the points apart), its applied part scaled by the load factor λ (as loads
  /// and applied generalised forces are; springs and dampers are not).
  virtual double force(double t, double l, double ld, double load_factor) const = 0;
  /// (∂F/∂l, ∂F/∂l̇).
  virtual std::pair<double, double> derivatives(double t, double l, double ld, double load_factor) const = 0;
  /// Whether it stores energy (energy is then asked) and dissipates power (power is then asked).
  virtual bool elastic() const = 0;
  virtual bool dissipative() const = 0;
  /// The energy (J) it stores at length l, and the power (W) it dissipates at (l, l̇) with the force F.
  virtual double energy(double t, double l) const = 0;
  virtual double power(double t, double l, double ld, double F) const = 0;
  /// A copy with the constant `name` set to `value` (a named parameter: parameters.hpp), unchecked;
  /// std::invalid_argument for a name the law does not have.
  virtual std::shared_ptr<const ElementLaw> with_constant(const std::string& name, double value) const = 0;
  /// A copy with its profile (a cylinder's F(t), a winch's l_u(t)) replaced; std::invalid_argument if it has none.
  virtual std::shared_ptr<const ElementLaw> with_profile(ProfilePtr profile) const = 0;
};

/// std::invalid_argument for a constant a law does not have.
[[noreturn]] inline void unknown_constant(const std::string& name, const char* constants) {
  bad("name", std::string("a constant of the element's law (") + constants + ")", "'" + name + "'");
}

/// A spring-damper (or a cylinder under force control):
///   F = −k (l − l₀) − c l̇ + λ (F₀ + F(t) + F_law(t, l, l̇)),  stores ½ k (l − l₀)², dissipates c l̇².
class SpringDamper final : public ElementLaw {
 public:
  SpringDamper(double stiffness, double damping, double length, double force, ProfilePtr profile, AxialFunction law)
      : k_(stiffness), c_(damping), l0_(length), F0_(force), profile_(std::move(profile)), law_(std::move(law)) {}
  void validate() const override {
    for (const auto& [value, name, expected] :
         {std::tuple<double, const char*, const char*>{k_, "stiffness", "a finite stiffness >= 0 in N/m"},
          {c_, "damping", "a finite damping coefficient >= 0 in N·s/m"},
          {l0_, "length", "a finite rest length >= 0 in m"}})
      if (!(value >= 0.0 && std::isfinite(value))) bad(name, expected, num(value, 8));
    if (!std::isfinite(F0_)) bad("force", "a finite force in N", num(F0_, 8));
  }
  double force(double t, double l, double ld, double load_factor) const override {
    double applied = F0_;
    if (profile_) applied += profile_->at(t).q;
    if (law_) applied += law_(t, l, ld);
    return -k_ * (l - l0_) - c_ * ld + load_factor * applied;
  }
  /// −k and −c, plus λ times the law's by central differences (steps 6e-6 max(1, |x|)).
  std::pair<double, double> derivatives(double t, double l, double ld, double load_factor) const override {
    std::pair<double, double> dF{-k_, -c_};
    if (law_) {
      const double hl = 6e-6 * std::max(1.0, std::abs(l)), hd = 6e-6 * std::max(1.0, std::abs(ld));
      dF.first += load_factor * (law_(t, l + hl, ld) - law_(t, l - hl, ld)) / (2.0 * hl);
      dF.second += load_factor * (law_(t, l, ld + hd) - law_(t, l, ld - hd)) / (2.0 * hd);
    }
    return dF;
  }
  bool elastic() const override { return k_ != 0.0; }
  bool dissipative() const override { return c_ != 0.0; }
  double energy(double, double l) const override { return 0.5 * k_ * std::pow(l - l0_, 2); }
  double power(double, double, double ld, double) const override { return c_ * std::pow(ld, 2); }
  std::shared_ptr<const ElementLaw> with_constant(const std::string& name, double value) const override {
    auto law = std::make_shared<SpringDamper>(*this);
    if (name == "stiffness") law->k_ = value;
    else if (name == "damping") law->c_ = value;
    else if (name == "force") law->F0_ = value;
    else unknown_constant(name, "stiffness, damping, force");
    return law;
  }
  std::shared_ptr<const ElementLaw> with_profile(ProfilePtr profile) const override {
    if (!profile_) bad("profile", "an element with a force profile F(t)", "one without");
    auto law = std::make_shared<SpringDamper>(*this);
    law->profile_ = std::move(profile);
    return law;
  }

 private:
  double k_;   ///< N/m
  double c_;   ///< N·s/m
  double l0_;  ///< m: the length at which the spring is relaxed
  double F0_;  ///< N: a constant push
  ProfilePtr profile_;  ///< F(t), N (its value), or null
  AxialFunction law_;   ///< F_law(t, l, l̇), N (the slow path through Python), or null
};

/// A rope (book ch. 7.1: the hoisting rope of a crane), massless and tension-only, of axial stiffness EA
/// and damping DA, whose unstretched length l_u(t) a winch pays out:
///   T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u  when positive, else 0 (slack),   F = −T,
/// a spring EA/l_u and a damper DA/l_u acting only while the rope pulls; stores ½ EA/l_u (l − l_u)² while
/// stretched and dissipates DA/l_u (l̇ − l̇_u)² while it pulls.
class Rope final : public ElementLaw {
 public:
  Rope(double EA, double DA, double length, ProfilePtr unstretched)
      : EA_(EA), DA_(DA), length_(length), unstretched_(std::move(unstretched)) {}
  void validate() const override {
    if (!(length_ >= 0.0 && std::isfinite(length_))) bad("length", "a finite rest length >= 0 in m", num(length_, 8));
    if (!(EA_ > 0.0 && std::isfinite(EA_))) bad("EA", "a positive axial stiffness EA in N", num(EA_, 8));
    if (!(DA_ >= 0.0 && std::isfinite(DA_))) bad("DA", "a finite axial damping DA >= 0 in N·s", num(DA_, 8));
    if (!unstretched_ && !(length_ > 0.0)) bad("length", "a positive unstretched length in m", num(length_, 8));
  }
  void check(double t, const std::string& name) const override {
    const double lu = unstretched_length(t).first;
    if (!(lu > 0.0))
      throw SimulationError(t, "the unstretched length of rope '" + name + "' is l_u = " + num(lu) +
                                   " m (a rope needs l_u > 0)");
  }
  double force(double t, double l, double ld, double) const override { return -tension(t, l, ld); }
  /// The active branch: EA/l_u, DA/l_u while taut, nothing while slack.
  std::pair<double, double> derivatives(double t, double l, double ld, double) const override {
    const double lu = unstretched_length(t).first;
    return tension(t, l, ld) > 0.0 ? std::pair<double, double>{-EA_ / lu, -DA_ / lu}
                                   : std::pair<double, double>{0.0, 0.0};
  }
  bool elastic() const override { return true; }
  bool dissipative() const override { return true; }
  double energy(double t, double l) const override {
    const double lu = unstretched_length(t).first;
    const double stretch = std::max(0.0, l - lu);
    return 0.5 * EA_ / lu * stretch * stretch;
  }
  double power(double t, double, double ld, double F) const override {
    const auto [lu, lud] = unstretched_length(t);
    return F < 0.0 ? DA_ / lu * (ld - lud) * (ld - lud) : 0.0;
  }
  std::shared_ptr<const ElementLaw> with_constant(const std::string& name, double value) const override {
    auto law = std::make_shared<Rope>(*this);
    if (name == "EA") law->EA_ = value;
    else if (name == "damping") law->DA_ = value;
    else unknown_constant(name, "EA, damping");
    return law;
  }
  std::shared_ptr<const ElementLaw> with_profile(ProfilePtr profile) const override {
    if (!unstretched_) bad("profile", "a rope paid out by a winch (a profile l_u(t))", "one of constant length");
    auto law = std::make_shared<Rope>(*this);
    law->unstretched_ = std::move(profile);
    return law;
  }
  /// l_u and l̇_u at t (m, m/s).
  std::pair<double, double> unstretched_length(double t) const {
    if (!unstretched_) return {length_, 0.0};
    const MotionState s = unstretched_->at(t);
    return {s.q, s.qd};
  }
  /// T ≥ 0 (N).
  double tension(double t, double l, double ld) const {
    const auto [lu, lud] = unstretched_length(t);
    return std::max(0.0, (EA_ * (l - lu) + DA_ * (ld - lud)) / lu);
  }

 private:
  double EA_;            ///< N: axial stiffness times the unstretched length
  double DA_;            ///< N·s: axial damping times the unstretched length
  double length_;        ///< m: l_u without a winch
  ProfilePtr unstretched_;  ///< l_u(t), m (a winch), or null: l_u = length
};

/// One force element as the user describes it: two points, and its kind's law. Body −1 is the ground.
struct ForceElement {
  std::string name;
  int body_a = -1, body_b = -1;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  ///< m, in the frames of bodies a and b
  std::shared_ptr<const ElementLaw> law;
};

}  // namespace rigidfem
