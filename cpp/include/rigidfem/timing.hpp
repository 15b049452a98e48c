/// Maintainers' timing helper for the benchmarks in benchmarks/ (not part of the public API).
#pragma once

#include <chrono>

#include "rigidfem/dynamics.hpp"

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

}  // namespace rigidfem
