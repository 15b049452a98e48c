/// Maintainers' timing helper for the benchmarks in benchmarks/ (not part of the public API).
#pragma once

#include <map>
#include <string>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// Seconds per forward-dynamics call at (t, q, q̇), averaged over `calls` calls on one workspace
/// after a warm-up call: the C++ cost without the Python call overhead.
double forward_dynamics_seconds(const System& sys, double t, const Eigen::Ref<const VecX>& q,
                                const Eigen::Ref<const VecX>& qd, int calls);

/// Seconds per call of the parts of an implicit (Newmark-family) step at (t, q, q̇, q̈), each on
/// one workspace: "residual" r = M q̈ − f (state, kinematics, inverse dynamics), "tangent"
/// (∂r/∂q, ∂r/∂q̇ and M), "lu_factor" and "lu_solve" of the dense n × n iteration matrix,
/// "armature_factor" and "armature_solve" of the O(n) matrix M + diag δ (implicit_spring).
std::map<std::string, double> implicit_step_parts_seconds(const System& sys, double t, const VecX& q,
                                                        const VecX& qd, const VecX& qdd, int calls);

}  // namespace rigidfem
