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
#include "rigidfem/laws.hpp"
#include "rigidfem/profiles.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// An axial force function F(t, l, l̇) (N) of an element's length l (m) and rate l̇ (m/s): a Python law.
using AxialFunction = ScalarFunction;

/// An element's extension: its length l (m) and rate l̇ (m/s) and, for a rope wound on drums or sheaves
/// (ForceElement::windings), the length s = Σ r q they have paid out (m) and its rate ṡ (m/s); 0 for any other element.
struct Extension {
  double l = 0.0, ld = 0.0, s = 0.0, sd = 0.0;
};
/// The derivatives of a function of the extension (an element's force, a drum's pull) by l, l̇, s and ṡ.
struct ExtensionDerivatives {
  double l = 0.0, ld = 0.0, s = 0.0, sd = 0.0;
};

/// What a kind of force element knows, in one class per kind (SpringDamper, Rope below), each describing itself
/// (laws.hpp: its constants, profile and function): its axial force and the force's derivatives, the energy it
/// stores, the power it dissipates and how it is drawn. A new kind is a class here and its row in
/// element_law_kinds(); the bindings, the Python layer (rigidfem.laws, Model.add_force_element, the named
/// parameters, the viewer) and the site's table read the row.
class ElementLaw : public Law {
 public:
  /// SimulationError where the law cannot be evaluated at t and x (element `name`); nothing by default.
  virtual void check(double /*t*/, const Extension& /*x*/, const std::string& /*name*/) const {}
  /// F(t, x) (N, > 0 pushing the points apart), its applied part scaled by the load factor λ (as loads
  /// and applied generalised forces are; springs and dampers are not).
  virtual double force(double t, const Extension& x, double load_factor) const = 0;
  /// ∂F/∂(l, l̇, s, ṡ).
  virtual ExtensionDerivatives derivatives(double t, const Extension& x, double load_factor) const = 0;
  /// Whether it stores energy (energy is then asked) and dissipates power (power is then asked).
  virtual bool elastic() const = 0;
  virtual bool dissipative() const = 0;
  /// The energy (J) it stores at x, and the power (W) it dissipates at x with the force F.
  virtual double energy(double t, const Extension& x) const = 0;
  virtual double power(double t, const Extension& x, double F) const = 0;
  /// Whether it can be wound on a drum (a rope): then the drum's coordinate φ takes the generalised force r P.
  virtual bool winds() const { return false; }
  /// P (N): the pull on the drum, −∂V/∂s − ∂D/∂ṡ of its energy V and dissipation function D; and its derivatives.
  virtual double pull(double /*t*/, const Extension& /*x*/) const { return 0.0; }
  virtual ExtensionDerivatives pull_derivatives(double /*t*/, const Extension& /*x*/) const { return {}; }
  /// The mass of its free span (kg), hanging on its two points (a heavy rope's μ l_u), and that mass's rate per metre
  /// paid out, ∂m/∂s (kg/m): the span's weight m g is shared by its ends, ½ m g on each, and its potential
  /// V = −½ m g·(r_B − r_A) (relative to the rope on the drum) pulls the drum by ½ (∂m/∂s) g·(r_B − r_A). None by default.
  virtual double span_mass(double /*t*/, const Extension& /*x*/) const { return 0.0; }
  virtual double span_mass_rate() const { return 0.0; }
  /// How the viewer draws the element: "spring", "cylinder", "rope".
  virtual const char* drawn_as() const = 0;
  /// A copy with the constant `name` set to `value` (a named parameter: parameters.hpp), unchecked;
  /// std::invalid_argument for a name the law does not have.
  std::shared_ptr<const ElementLaw> with_constant(const std::string& name, double value) const {
    auto law = clone();
    law->set(constant_index(name), value);
    return law;
  }
  /// A copy with its profile (a cylinder's F(t), a winch's l_u(t)) replaced; std::invalid_argument if it has none.
  std::shared_ptr<const ElementLaw> with_profile(ProfilePtr profile) const {
    if (!profile_) bad("profile", std::string("an element with a profile (") + info().kind + " takes one)", "one without");
    auto law = clone();
    law->profile_ = std::move(profile);
    return law;
  }
  const ProfilePtr& profile() const { return profile_; }

 protected:
  ElementLaw(std::vector<double> values, ProfilePtr profile) : Law(std::move(values)), profile_(std::move(profile)) {}
  virtual std::shared_ptr<ElementLaw> clone() const = 0;
  ProfilePtr profile_;  ///< its profile (laws.hpp: LawInfo::profile), or null
};

/// A spring-damper (or a cylinder under force control):
///   F = −k (l − l₀) − c l̇ + λ (F₀ + F(t) + F_law(t, l, l̇)),  stores ½ k (l − l₀)², dissipates c l̇².
class SpringDamper final : public ElementLaw {
 public:
  enum { K, C, L0, F0 };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "SpringDamper", "element",
        "F = −k (l − l₀) − c l̇ + F₀ + F(t) + F(t, l, l̇) (N, > 0 pushing the points apart): a spring-damper, or a "
        "hydraulic cylinder under force control; stores ½ k (l − l₀)², dissipates c l̇²",
        {{"stiffness", "N/m", nullptr, 0.0, 0.0, false, "the element's spring k", true},
         {"damping", "N s/m", nullptr, 0.0, 0.0, false, "the element's damper c", true},
         {"length", "m", nullptr, 0.0, 0.0, false, "the spring's rest length l₀", false},
         {"force", "N", nullptr, 0.0, -std::numeric_limits<double>::infinity(), false, "the element's constant push F0",
          true}},
        "a force F(t) (its value, N) added to F₀",
        "profile",
        "the force profile's (N, s, rad/s)",
        "a force F(t, l, ld) (N) of time (s), length (m) and its rate (m/s), added to F₀, its derivatives by central "
        "differences"};
    return info;
  }
  SpringDamper(std::vector<double> values, ProfilePtr profile, AxialFunction law)
      : ElementLaw(std::move(values), std::move(profile)), law_(std::move(law)) {}
  const LawInfo& info() const override { return description(); }
  double force(double t, const Extension& x, double load_factor) const override {
    double applied = c_[F0];
    if (profile_) applied += profile_->at(t).q;
    if (law_) applied += law_(t, x.l, x.ld);
    return -c_[K] * (x.l - c_[L0]) - c_[C] * x.ld + load_factor * applied;
  }
  /// −k and −c, plus λ times the law's by central differences (steps 6e-6 max(1, |x|)).
  ExtensionDerivatives derivatives(double t, const Extension& x, double load_factor) const override {
    ExtensionDerivatives dF{-c_[K], -c_[C]};
    if (law_) {
      const double l = x.l, ld = x.ld;
      const double hl = 6e-6 * std::max(1.0, std::abs(l)), hd = 6e-6 * std::max(1.0, std::abs(ld));
      dF.l += load_factor * (law_(t, l + hl, ld) - law_(t, l - hl, ld)) / (2.0 * hl);
      dF.ld += load_factor * (law_(t, l, ld + hd) - law_(t, l, ld - hd)) / (2.0 * hd);
    }
    return dF;
  }
  bool elastic() const override { return c_[K] != 0.0; }
  bool dissipative() const override { return c_[C] != 0.0; }
  double energy(double, const Extension& x) const override { return 0.5 * c_[K] * std::pow(x.l - c_[L0], 2); }
  double power(double, const Extension& x, double) const override { return c_[C] * std::pow(x.ld, 2); }
  /// A cylinder where it has no spring and pushes (a force, its profile or its function), else a spring.
  const char* drawn_as() const override {
    return c_[K] == 0.0 && (c_[F0] != 0.0 || profile_ || law_) ? "cylinder" : "spring";
  }

 private:
  std::shared_ptr<ElementLaw> clone() const override { return std::make_shared<SpringDamper>(*this); }
  AxialFunction law_;  ///< F_law(t, l, l̇), N (the slow path through Python), or null
};

/// A rope (book ch. 7.1: the hoisting rope of a crane), tension-only, of axial stiffness EA and damping DA, whose
/// unstretched length l_u(t) a winch pays out:
///   T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u  when positive, else 0 (slack),   F = −T,
/// a spring EA/l_u and a damper DA/l_u acting only while the rope pulls; stores ½ EA/l_u (l − l_u)² while
/// stretched and dissipates DA/l_u (l̇ − l̇_u)² while it pulls. Of mass μ per metre of unstretched rope, its free span
/// of mass μ l_u weighs on its two points (ElementLaw::span_mass), more of it as a drum pays it out.
class Rope final : public ElementLaw {
 public:
  enum { EA, DA, LENGTH, MU };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "Rope", "element",
        "T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u while positive, 0 when slack (N, pulling: F = −T): a "
        "tension-only rope of unstretched length l_u, constant or paid out by a winch l_u(t); stores ½ EA/l_u (l − "
        "l_u)² while stretched, dissipates DA/l_u (l̇ − l̇_u)² while it pulls; its free span's weight μ l_u g hangs "
        "half on each point",
        {{"EA", "N", nullptr, 1.0, 0.0, true, "the rope's axial stiffness EA", true},
         {"DA", "N s", nullptr, 0.0, 0.0, false, "the rope's axial damping DA", true},
         {"length", "m", nullptr, 1.0, 0.0, true, "the rope's unstretched length l_u (without a winch)", false},
         {"mass_per_length", "kg/m", nullptr, 0.0, 0.0, false,
          "the rope's mass μ per metre of unstretched rope (its free span's weight; 0: massless)", true}},
        "the unstretched length l_u(t) (m) a winch pays out, instead of length",
        "length",
        "the winch's (m, s, m/s)",
        nullptr};
    return info;
  }
  Rope(std::vector<double> values, ProfilePtr unstretched, AxialFunction = {})
      : ElementLaw(std::move(values), std::move(unstretched)) {
    if (profile_) c_[LENGTH] = profile_->at(0.0).q;  // l_u(0), for the record: the winch's profile is what counts
  }
  const LawInfo& info() const override { return description(); }
  /// A winch's l_u(0) > 0 first (a profile that starts slack names its profile), then the constants.
  void validate() const override {
    if (profile_ && !(c_[LENGTH] > 0.0 && std::isfinite(c_[LENGTH])))
      bad("length", "a profile l_u(t) with a positive length at t = 0 in m", num(c_[LENGTH], 8));
    ElementLaw::validate();
  }
  void check(double t, const Extension& x, const std::string& name) const override {
    const double lu = unstretched_length(t, x).first;
    if (!(lu > 0.0))
      throw SimulationError(t, "the unstretched length of rope '" + name + "' is l_u = " + num(lu) + " m (a rope needs "
                               "l_u > 0" + (x.s != 0.0 ? ": its drum has wound it all in)" : ")"));
  }
  double force(double t, const Extension& x, double) const override { return -tension(t, x); }
  /// The active branch while taut (T > 0), nothing while slack: with l_u = l_u(t) + s and T = N/l_u,
  /// N = EA (l − l_u) + DA (l̇ − l̇_u): ∂T/∂l = EA/l_u, ∂T/∂l̇ = DA/l_u, ∂T/∂s = −(EA + T)/l_u, ∂T/∂ṡ = −DA/l_u.
  ExtensionDerivatives derivatives(double t, const Extension& x, double) const override {
    const double T = tension(t, x);
    if (!(T > 0.0)) return {};
    const double lu = unstretched_length(t, x).first;
    return {-c_[EA] / lu, -c_[DA] / lu, (c_[EA] + T) / lu, c_[DA] / lu};
  }
  bool elastic() const override { return true; }
  bool dissipative() const override { return true; }
  /// ½ EA/l_u (l − l_u)² while stretched.
  double energy(double t, const Extension& x) const override {
    const double lu = unstretched_length(t, x).first;
    const double stretch = std::max(0.0, x.l - lu);
    return 0.5 * c_[EA] / lu * stretch * stretch;
  }
  /// DA/l_u (l̇ − l̇_u)² while it pulls.
  double power(double t, const Extension& x, double F) const override {
    const auto [lu, lud] = unstretched_length(t, x);
    return F < 0.0 ? c_[DA] / lu * (x.ld - lud) * (x.ld - lud) : 0.0;
  }
  bool winds() const override { return true; }
  /// P = −∂V/∂s − ∂D/∂ṡ = T + ½ EA ε² while taut (ε = (l − l_u)/l_u; D = ½ DA/l_u (l̇ − l̇_u)²), 0 while slack: the
  /// drum's r P turns it by the energy the rope stores and dissipates, to the last term (T r alone would leave
  /// ½ EA ε² ṡ unaccounted).
  double pull(double t, const Extension& x) const override {
    const double T = tension(t, x);
    if (!(T > 0.0)) return 0.0;
    const double lu = unstretched_length(t, x).first, eps = (x.l - lu) / lu;
    return T + 0.5 * c_[EA] * eps * eps;
  }
  /// ∂P/∂l = (EA + EA ε)/l_u, ∂P/∂l̇ = DA/l_u, ∂P/∂s = −(EA + T + EA ε (1 + ε))/l_u, ∂P/∂ṡ = −DA/l_u (taut).
  ExtensionDerivatives pull_derivatives(double t, const Extension& x) const override {
    const double T = tension(t, x);
    if (!(T > 0.0)) return {};
    const double lu = unstretched_length(t, x).first, eps = (x.l - lu) / lu;
    return {c_[EA] * (1.0 + eps) / lu, c_[DA] / lu, -(c_[EA] + T + c_[EA] * eps * (1.0 + eps)) / lu, -c_[DA] / lu};
  }
  /// μ l_u (kg) and μ.
  double span_mass(double t, const Extension& x) const override {
    return c_[MU] == 0.0 ? 0.0 : c_[MU] * unstretched_length(t, x).first;
  }
  double span_mass_rate() const override { return c_[MU]; }
  const char* drawn_as() const override { return "rope"; }
  /// l_u and l̇_u at t (m, m/s): the winch's l_u(t) or the length, plus what a drum has paid out, s and ṡ.
  std::pair<double, double> unstretched_length(double t, const Extension& x) const {
    if (!profile_) return {c_[LENGTH] + x.s, x.sd};
    const MotionState p = profile_->at(t);
    return {p.q + x.s, p.qd + x.sd};
  }
  /// T ≥ 0 (N).
  double tension(double t, const Extension& x) const {
    const auto [lu, lud] = unstretched_length(t, x);
    return std::max(0.0, (c_[EA] * (x.l - lu) + c_[DA] * (x.ld - lud)) / lu);
  }

 private:
  std::shared_ptr<ElementLaw> clone() const override { return std::make_shared<Rope>(*this); }
};

/// A buffer (an end stop, a bumper): compression only, with the Hunt–Crossley law of a contact. With the
/// penetration δ = l₀ − l (> 0 once the points come closer than l₀) and its rate δ̇ = −l̇,
///   F = k δⁿ (1 + α δ̇)  while δ > 0 and that is positive, else 0,
/// pushing the points apart: n = 1 a linear buffer, n = 3/2 Hertz's contact of curved bodies; α (s/m) dissipates
/// in proportion to the force, so F rises from 0 at first touch (no jump), and the coefficient of restitution
/// follows from α and the impact speed (v_out − ln(1 + α v_out)/α = v_in − ln(1 + α v_in)/α). Stores
/// k δⁿ⁺¹/(n + 1), dissipates k α δⁿ δ̇² while it pushes.
class Buffer final : public ElementLaw {
 public:
  enum { K, N, L0, ALPHA };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "Buffer", "element",
        "F = k δⁿ (1 + α δ̇) with δ = l₀ − l while δ > 0 and F > 0, else 0 (N, pushing the points apart): a "
        "compression-only buffer or end stop with Hunt–Crossley dissipation (n = 1.5: Hertz); stores k δⁿ⁺¹/(n + 1), "
        "dissipates k α δⁿ δ̇²",
        {{"stiffness", "N/m^n", nullptr, 0.0, 0.0, false, "the buffer's stiffness k (F = k δⁿ)", true},
         {"exponent", "1", nullptr, 1.0, 1.0, false, "the exponent n of the penetration (1 linear, 1.5 Hertz)", false},
         {"length", "m", nullptr, 0.0, 0.0, false, "the length l₀ below which it pushes", false},
         {"dissipation", "s/m", nullptr, 0.0, 0.0, false, "Hunt–Crossley's α: F = k δⁿ (1 + α δ̇)", true}},
        nullptr,
        nullptr,
        nullptr,
        nullptr};
    return info;
  }
  Buffer(std::vector<double> values, ProfilePtr, AxialFunction) : ElementLaw(std::move(values), nullptr) {}
  const LawInfo& info() const override { return description(); }
  double force(double, const Extension& x, double) const override {
    const double d = c_[L0] - x.l;
    return d > 0.0 ? std::max(0.0, c_[K] * std::pow(d, c_[N]) * (1.0 - c_[ALPHA] * x.ld)) : 0.0;
  }
  /// ∂F/∂l = −k n δⁿ⁻¹ (1 + α δ̇), ∂F/∂l̇ = −k α δⁿ while it pushes, else 0.
  ExtensionDerivatives derivatives(double t, const Extension& x, double lambda) const override {
    if (!(force(t, x, lambda) > 0.0)) return {};
    const double d = c_[L0] - x.l;
    return {-c_[K] * c_[N] * std::pow(d, c_[N] - 1.0) * (1.0 - c_[ALPHA] * x.ld), -c_[K] * c_[ALPHA] * std::pow(d, c_[N])};
  }
  bool elastic() const override { return true; }
  bool dissipative() const override { return c_[ALPHA] != 0.0; }
  double energy(double, const Extension& x) const override {
    const double d = c_[L0] - x.l;
    return d > 0.0 ? c_[K] * std::pow(d, c_[N] + 1.0) / (c_[N] + 1.0) : 0.0;
  }
  double power(double, const Extension& x, double F) const override {
    const double d = c_[L0] - x.l;
    return F > 0.0 ? c_[K] * c_[ALPHA] * std::pow(d, c_[N]) * x.ld * x.ld : 0.0;
  }
  const char* drawn_as() const override { return "spring"; }

 private:
  std::shared_ptr<ElementLaw> clone() const override { return std::make_shared<Buffer>(*this); }
};

/// Sliding friction along an element (a cylinder's seals, a telescope's guide), against the rate of its length:
///   F = −g(l̇) tanh(l̇/v_ε) − b l̇,   g(v) = F_C + (F_S − F_C) e^{−(v/v_S)²},
/// the breakaway force F_S near rest falling to the Coulomb force F_C beyond the Stribeck velocity v_S, and a viscous
/// b: the joints' Friction law (coordinate_laws.hpp) on an element's length, regularised for the same reason (a
/// creep of ~v_ε where it should stick). Stores nothing; dissipates −F l̇ ≥ 0.
class SlidingFriction final : public ElementLaw {
 public:
  enum { FS, FC, VS, B, VE };  // the constants' indices
  static const LawInfo& description() {
    static const LawInfo info{
        "SlidingFriction", "element",
        "F = −(F_C + (F_S − F_C) exp(−(l̇/v_S)²)) tanh(l̇/v_ε) − b l̇ (N, > 0 pushing the points apart): dry friction "
        "against the rate of the element's length, with a Stribeck fall from the breakaway F_S to the Coulomb F_C, "
        "and viscous friction b, regularised over v_ε",
        {{"breakaway", "N", nullptr, 0.0, 0.0, false, "the breakaway (static) friction F_S", true},
         {"coulomb", "N", nullptr, 0.0, 0.0, false, "the Coulomb (kinetic) friction F_C", true},
         {"stribeck", "m/s", nullptr, 0.01, 0.0, true, "the Stribeck velocity v_S", false},
         {"viscous", "N s/m", nullptr, 0.0, 0.0, false, "the viscous friction b", true},
         {"smoothing", "m/s", nullptr, 1e-4, 0.0, true, "the regularising velocity v_ε of tanh(l̇/v_ε)", false}},
        nullptr,
        nullptr,
        nullptr,
        nullptr};
    return info;
  }
  SlidingFriction(std::vector<double> values, ProfilePtr, AxialFunction) : ElementLaw(std::move(values), nullptr) {}
  const LawInfo& info() const override { return description(); }
  double force(double, const Extension& x, double) const override { return friction().force(x.ld); }
  /// (0, dF/dl̇): laws.hpp's RegularisedFriction.
  ExtensionDerivatives derivatives(double, const Extension& x, double) const override {
    return {0.0, friction().rate_derivative(x.ld)};
  }
  bool elastic() const override { return false; }
  bool dissipative() const override { return true; }
  double energy(double, const Extension&) const override { return 0.0; }
  double power(double, const Extension& x, double F) const override { return -F * x.ld; }
  const char* drawn_as() const override { return "cylinder"; }

 private:
  RegularisedFriction friction() const { return {c_[FS], c_[FC], c_[VS], c_[B], c_[VE]}; }
  std::shared_ptr<ElementLaw> clone() const override { return std::make_shared<SlidingFriction>(*this); }
};

/// A kind of force element as the bindings make it: its description, and its maker from the constants' values
/// (in the description's order), a profile and a Python function (each null where the kind takes none).
struct ElementLawKind {
  const LawInfo& (*info)();
  std::shared_ptr<const ElementLaw> (*make)(std::vector<double> values, ProfilePtr profile, AxialFunction function);
};

/// Every kind of force element, each once.
inline const std::vector<ElementLawKind>& element_law_kinds() {
  static const std::vector<ElementLawKind> kinds = {
      {SpringDamper::description,
       [](std::vector<double> v, ProfilePtr p, AxialFunction f) -> std::shared_ptr<const ElementLaw> {
         return std::make_shared<SpringDamper>(std::move(v), std::move(p), std::move(f));
       }},
      {Rope::description,
       [](std::vector<double> v, ProfilePtr p, AxialFunction f) -> std::shared_ptr<const ElementLaw> {
         return std::make_shared<Rope>(std::move(v), std::move(p), std::move(f));
       }},
      {Buffer::description,
       [](std::vector<double> v, ProfilePtr p, AxialFunction f) -> std::shared_ptr<const ElementLaw> {
         return std::make_shared<Buffer>(std::move(v), std::move(p), std::move(f));
       }},
      {SlidingFriction::description,
       [](std::vector<double> v, ProfilePtr p, AxialFunction f) -> std::shared_ptr<const ElementLaw> {
         return std::make_shared<SlidingFriction>(std::move(v), std::move(p), std::move(f));
       }},
  };
  return kinds;
}

/// A coordinate a rope is wound on (Model::wind): a drum's rotation φ (radius r, m) or the slip u of a rope over a
/// sheave (radius ±1). It pays out r q of unstretched rope and takes the generalised force r P c(q̇), with the
/// capstan's regularised friction c = exp(−sgn(r) μθ tanh(q̇/v_ε)) (c = 1 without: μθ = 0): in slip the tensions on
/// either side of a sheave stand in Euler's ratio e^{μθ}, and the friction's power −r P (c − 1) q̇ is never negative.
struct Winding {
  int body = -1, slot = 0;  ///< the coordinate: slot `slot` of body `body`'s joint
  int coord = -1;           ///< its index among the System's coordinates (set by compile())
  double radius = 0.0;      ///< r (m per unit of the coordinate)
  double capstan = 0.0;     ///< μθ: the friction coefficient times the wrap angle (rad)
  double smoothing = 0.0;   ///< v_ε: the rate (the coordinate's unit per s) over which the friction is regularised
  /// (c, dc/dq̇) at the coordinate's rate q̇.
  std::pair<double, double> factor(double qd) const {
    if (capstan == 0.0) return {1.0, 0.0};
    const double k = (radius > 0.0 ? -1.0 : 1.0) * capstan, th = std::tanh(qd / smoothing);
    const double c = std::exp(k * th);
    return {c, c * k * (1.0 - th * th) / smoothing};
  }
};

/// One force element as the user describes it: two points, and its kind's law. Body −1 is the ground.
struct ForceElement {
  std::string name;
  int body_a = -1, body_b = -1;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  ///< m, in the frames of bodies a and b
  std::shared_ptr<const ElementLaw> law;
  /// A rope wound on drums and sheaves (Model::wind): they pay out s = Σ r_k q_k of unstretched rope
  /// (l_u = l₀ + s) and each takes r_k P c_k (ElementLaw::pull, Winding::factor).
  std::vector<Winding> windings;
};

}  // namespace rigidfem
