/// Maintainers' timing helper for the benchmarks in benchmarks/ (not part of the public API).
#pragma once

#include <chrono>
#include <map>
#include <string>

#include "rigidfem/dynamics.hpp"
#include "rigidfem/kinematics.hpp"

namespace rigidfem {

/// Seconds per forward-dynamics call at (t, q, q̇), averaged over `calls` calls on one workspace
/// after a warm-up call: the C++ cost without the Python call overhead.
inline double forward_dynamics_seconds(const System& sys, double t, const Eigen::Ref<const VecX>& q,
                                       const Eigen::Ref<const VecX>& qd, int calls) {
  Data d(sys);
  forward_dynamics(sys, d, t, q, qd);
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < calls; ++k) forward_dynamics(sys, d, t, q, qd);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / calls;
}

/// Seconds per call, averaged over `calls` calls after a warm-up call, of `f`.
template <class F>
double seconds_per_call(F&& f, int calls) {
  f();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < calls; ++k) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / calls;
}

/// Seconds per call of the parts of an implicit (Newmark-family) step at (t, q, q̇, q̈), each on
/// one workspace: "residual" r = M q̈ − f (state, kinematics, inverse dynamics), "tangent"
/// (∂r/∂q, ∂r/∂q̇ and M), "lu_factor" and "lu_solve" of the dense n × n iteration matrix,
/// "armature_factor" and "armature_solve" of the O(n) matrix M + diag δ (implicit_spring).
inline std::map<std::string, double> implicit_step_parts_seconds(const System& sys, double t, const VecX& q,
                                                               const VecX& qd, const VecX& qdd, int calls) {
  Data d(sys);
  std::map<std::string, double> s;
  VecX r(sys.nq), x(sys.nq);
  const auto residual = [&] {
    set_state(sys, d, t, q, qd);
    set_accelerations(sys, d, qdd);
    dynamics_kinematics(sys, d);
    r = inverse_dynamics(sys, d);
  };
  s["residual"] = seconds_per_call(residual, calls);
  MatX S;
  s["tangent"] = seconds_per_call([&] {
    auto [drdq, drdqd] = inverse_dynamics_derivatives(sys, d);
    mass_matrix(sys, d);
    S = d.A + 1e-4 * drdqd + 1e-6 * drdq;
  }, std::max(1, calls / 10));
  Eigen::PartialPivLU<MatX> lu(sys.nq);
  s["lu_factor"] = seconds_per_call([&] { lu.compute(S); }, std::max(1, calls / 10));
  s["lu_solve"] = seconds_per_call([&] { x = lu.solve(r); }, calls);
  const VecX armature = VecX::Constant(sys.nq, 1e-3);
  s["armature_factor"] = seconds_per_call([&] { factor_armature(sys, d, armature); }, calls);
  s["armature_solve"] = seconds_per_call([&] { solve_armature(sys, d, r, x); }, calls);
  return s;
}

}  // namespace rigidfem
