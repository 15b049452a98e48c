/// Force elements between two bodies: a spring-damper or a hydraulic cylinder under force
/// control, acting along the line between a point A on body a and a point B on body b (book
/// ch. 7.3). With d = r_B − r_A, l = |d|, e = d / l and l̇ = e·ḋ the element pushes the points
/// apart with the axial force
///   F(t, l, l̇) = −k (l − l₀) − c l̇ + F₀ + F(t) + F_law(t, l, l̇)       (N, > 0 pushing),
/// i.e. the force F e on B at r_B and −F e on A at r_A, and stores ½ k (l − l₀)² and
/// dissipates c l̇².
///
/// A rope (book ch. 7.1: the hoisting rope of a crane) is a massless tension-only element of
/// axial stiffness EA and damping DA whose unstretched length l_u(t) a winch pays out:
///   T = (EA (l − l_u) + DA (l̇ − l̇_u)) / l_u  when positive, else 0 (slack),   F = −T,
/// i.e. a spring EA/l_u and a damper DA/l_u acting only while the rope pulls.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>

#include "rigidfem/profiles.hpp"
#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// An axial force law F(t, l, l̇) (N) of an element's length l (m) and rate l̇ (m/s).
using AxialLaw = std::function<double(double, double, double)>;

/// One force element as the user describes it. Body −1 is the ground.
struct ForceElement {
  std::string name;
  int body_a = -1, body_b = -1;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  ///< m, in the frames of bodies a and b
  double stiffness = 0.0;  ///< k, N/m
  double damping = 0.0;    ///< c, N·s/m
  double length = 0.0;     ///< l₀, m: the length at which the spring is relaxed
  double force = 0.0;      ///< F₀, N: a constant push
  ProfilePtr force_profile;  ///< F(t), N (its value), or null
  AxialLaw law;              ///< F_law(t, l, l̇), N (the slow path through Python), or null
  // Ropes (stiffness, damping and force unused):
  bool rope = false;
  double EA = 0.0;           ///< N: axial stiffness times the unstretched length
  double DA = 0.0;           ///< N·s: axial damping times the unstretched length
  ProfilePtr unstretched;    ///< l_u(t), m (a winch), or null: l_u = length
};

/// A rope's unstretched length l_u and its rate at t.
inline std::pair<double, double> unstretched_length(const ForceElement& e, double t) {
  if (!e.unstretched) return {e.length, 0.0};
  const MotionState s = e.unstretched->at(t);
  return {s.q, s.qd};
}

/// A rope's tension T ≥ 0 (N).
inline double rope_tension(const ForceElement& e, double t, double l, double ld) {
  const auto [lu, lud] = unstretched_length(e, t);
  return std::max(0.0, (e.EA * (l - lu) + e.DA * (ld - lud)) / lu);
}

/// F(t, l, l̇) (N, > 0 pushing the points apart) with the applied part F₀ + F(t) + F_law scaled by
/// the load factor λ (as loads and applied generalised forces are; the spring and damper are not).
inline double axial_force(const ForceElement& e, double t, double l, double ld, double load_factor) {
  if (e.rope) return -rope_tension(e, t, l, ld);
  double applied = e.force;
  if (e.force_profile) applied += e.force_profile->at(t).q;
  if (e.law) applied += e.law(t, l, ld);
  return -e.stiffness * (l - e.length) - e.damping * ld + load_factor * applied;
}

/// (∂F/∂l, ∂F/∂l̇): −k and −c, plus λ times the law's by central differences (steps 6e-6 max(1, |x|)).
inline std::pair<double, double> axial_force_derivatives(const ForceElement& e, double t, double l, double ld,
                                                         double load_factor) {
  if (e.rope) {  // the active branch: EA/l_u, DA/l_u while taut, nothing while slack
    const double lu = unstretched_length(e, t).first;
    return rope_tension(e, t, l, ld) > 0.0 ? std::pair<double, double>{-e.EA / lu, -e.DA / lu}
                                           : std::pair<double, double>{0.0, 0.0};
  }
  std::pair<double, double> dF{-e.stiffness, -e.damping};
  if (e.law) {
    const double hl = 6e-6 * std::max(1.0, std::abs(l)), hd = 6e-6 * std::max(1.0, std::abs(ld));
    dF.first += load_factor * (e.law(t, l + hl, ld) - e.law(t, l - hl, ld)) / (2.0 * hl);
    dF.second += load_factor * (e.law(t, l, ld + hd) - e.law(t, l, ld - hd)) / (2.0 * hd);
  }
  return dF;
}

}  // namespace rigidfem
