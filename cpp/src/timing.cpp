/// The benchmarks' timing helpers (timing.hpp): C++ costs without the Python call overhead.
#include "rigidfem/timing.hpp"

#include <algorithm>
#include <chrono>

#include "rigidfem/dense_lu.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/kinematics.hpp"

namespace rigidfem {

namespace {

/// Seconds per call, averaged over `calls` calls after a warm-up call, of `f`.
template <class F>
double seconds_per_call(F&& f, int calls) {
  f();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < calls; ++k) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / calls;
}

}  // namespace

double forward_dynamics_seconds(const System& sys, double t, const Eigen::Ref<const VecX>& q,
                                const Eigen::Ref<const VecX>& qd, int calls) {
  Data d(sys);
  return seconds_per_call([&] { forward_dynamics(sys, d, t, q, qd); }, calls);
}

std::map<std::string, double> implicit_step_parts_seconds(const System& sys, double t, const VecX& q,
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
  DenseLU lu;  // the dense Newton matrix's
  s["lu_factor"] = seconds_per_call([&] { lu.compute(S); }, std::max(1, calls / 10));
  s["lu_solve"] = seconds_per_call([&] { lu.solve(r, x); }, calls);
  const VecX armature = VecX::Constant(sys.nq, 1e-3);
  s["armature_factor"] = seconds_per_call([&] { factor_armature(sys, d, armature); }, calls);
  s["armature_solve"] = seconds_per_call([&] { solve_armature(sys, d, r, x); }, calls);
  return s;
}

}  // namespace rigidfem
