/// What every law is: a kind that describes itself once — its constants (name, unit, default, bounds, doc), what a
/// profile or a Python function means to it, what it acts on — and its constants' values, judged against those
/// bounds. The force elements' laws (force_elements.hpp) and the joint coordinates' laws (coordinate_laws.hpp)
/// are laws; the Python layer (rigidfem.laws, named parameters, the builders' checks, the viewer, the site's
/// tables, the stub) reads their descriptions through the bindings, and nothing else names a kind.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "rigidfem/errors.hpp"
#include "rigidfem/profiles.hpp"

namespace rigidfem {

/// One constant of a law.
struct Constant {
  const char* name;           ///< its name, as an argument and as a parameter ("stiffness", "EA", "mu_k")
  const char* unit;           ///< its unit ("N/m"); on a joint coordinate, of a translation
  const char* rotation_unit;  ///< on a joint coordinate, of a rotation ("N m/rad"); null: as unit
  double value;               ///< its default
  double lower;               ///< the smallest value it takes (−inf: none)
  bool positive;              ///< lower excluded: values > lower
  const char* doc;            ///< what it is ("the element's spring k")
  bool parameter;             ///< a named parameter of a compiled system (System.parameters)
  /// The equations are linear in it: its derivatives are one-sided differences of any step, exact to round-off;
  /// otherwise central differences of the systems at p ± h (a contact's restitution).
  bool linear = true;
  double upper = std::numeric_limits<double>::infinity();  ///< the largest value it takes (included)
};

/// What a kind of law is, described once.
struct LawInfo {
  const char* kind;   ///< its name in Python (rigidfem.laws.<kind>): "SpringDamper", "Rope", "Friction"
  const char* acts_on;  ///< "element" (between two points) or "coordinate" (on a joint coordinate)
  const char* doc;    ///< its equations, in a few lines
  std::vector<Constant> constants;
  /// What a profile means to it (a cylinder's force F(t), N; a winch's unstretched length l_u(t), m), and the
  /// name its numbers take as parameters ("profile", "length"); null: it takes none.
  const char* profile;
  const char* profile_name;
  const char* profile_units;  ///< the profile's numbers' units ("N, s, rad/s")
  /// What a Python function means to it (the slow path: called under the GIL); null: it takes none.
  const char* function;
};

/// The step h = 6e-6 max(1, |x|) of a central difference in x (a Python function's derivatives, the Lagrange
/// formulation's Jacobians): its truncation (∝ h²) and round-off (∝ 1/h) both near 1e-10 relative.
inline double difference_step(double x) { return 6e-6 * std::max(1.0, std::abs(x)); }

/// Regularised dry and viscous friction against a velocity v (the joints' Friction, an element's SlidingFriction):
///   Q = −g(v) tanh(v/v_ε) − b v,  g(v) = F_C + (F_S − F_C) e^{−(v/v_S)²},
/// and dQ/dv = −g'(v) tanh(v/v_ε) − g(v) sech²(v/v_ε)/v_ε − b with g'(v) = −2 v/v_S² (F_S − F_C) e^{−(v/v_S)²}.
struct RegularisedFriction {
  double FS, FC, vS, b, ve;  ///< breakaway, Coulomb (N or N·m), Stribeck and smoothing velocities, viscous
  double force(double v) const { return -dry(v) * std::tanh(v / ve) - b * v; }
  double rate_derivative(double v) const {
    const double x = v / vS, th = std::tanh(v / ve);
    const double dg = -2.0 * x / vS * (FS - FC) * std::exp(-x * x);
    return -dg * th - dry(v) * (1.0 - th * th) / ve - b;
  }
  double dry(double v) const {
    const double x = v / vS;
    return FC + (FS - FC) * std::exp(-x * x);
  }
};

/// A scalar function of time and one state's value and rate, given from Python: a force element's F(t, l, l̇) (N),
/// a joint coordinate's Q(t, q, q̇) (N or N·m).
using ScalarFunction = std::function<double(double, double, double)>;

/// The base of every law: its description and its constants' values.
class Law {
 public:
  virtual ~Law() = default;
  virtual const LawInfo& info() const = 0;
  /// The constants' values, in info().constants' order.
  const std::vector<double>& values() const { return c_; }
  /// The value of constant `name` (std::invalid_argument listing the constants if it has none of that name).
  double value(const std::string& name) const { return c_[constant_index(name)]; }
  /// std::invalid_argument naming the first constant out of its bounds: "EA: expected a positive number in N (the
  /// rope's axial stiffness EA), got -1".
  virtual void validate() const {
    const LawInfo& law = info();
    for (std::size_t k = 0; k < law.constants.size(); ++k) {
      const Constant& c = law.constants[k];
      const double x = c_[k];
      const bool bounded = c.lower > -std::numeric_limits<double>::infinity();
      if (std::isfinite(x) && (!bounded || (c.positive ? x > c.lower : x >= c.lower)) && x <= c.upper) continue;
      if (std::isfinite(x) && x > c.upper)
        bad(c.name, "a number <= " + num(c.upper, 8) + " in " + c.unit + " (" + c.doc + ")", num(x, 8));
      const std::string kind = !bounded ? "finite" : c.lower == 0.0 ? (c.positive ? "positive" : "non-negative")
                                                                   : (c.positive ? "> " : ">= ") + num(c.lower, 8);
      bad(c.name, (bounded && c.lower != 0.0 ? "a number " + kind : "a " + kind + " number") + " in " + c.unit +
                      " (" + c.doc + ")",
          num(x, 8));
    }
  }
  /// The index of constant `name` in values(); std::invalid_argument listing the constants otherwise.
  int constant_index(const std::string& name) const;

 protected:
  explicit Law(std::vector<double> values) : c_(std::move(values)) {}
  /// The constant at `index` of a copy set to `value` (a named parameter: unchecked, the central differences of
  /// sensitivities.hpp step a value at zero to both sides).
  void set(int index, double value) { c_[index] = value; }
  std::vector<double> c_;
};

/// The index of constant `name` in a kind's constants; std::invalid_argument listing them otherwise.
inline int constant_index(const LawInfo& info, const std::string& name) {
  std::string names;
  for (std::size_t k = 0; k < info.constants.size(); ++k) {
    if (name == info.constants[k].name) return static_cast<int>(k);
    names += std::string(names.empty() ? "" : ", ") + info.constants[k].name;
  }
  bad("name", std::string("a constant of the law ") + info.kind + " (" + names + ")", "'" + name + "'");
}

inline int Law::constant_index(const std::string& name) const { return rigidfem::constant_index(info(), name); }

/// The defaults of a kind's constants, in order.
inline std::vector<double> defaults(const LawInfo& info) {
  std::vector<double> v;
  for (const Constant& c : info.constants) v.push_back(c.value);
  return v;
}

}  // namespace rigidfem
