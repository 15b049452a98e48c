/// Analytic derivatives of the recursive equations of motion (systems compiled with
/// algorithm=recursive).
///
/// The residual of the equations of motion, r(q, q̇, q̈) = A(q) q̈ − f(q, q̇, t) = Sᵀ f̄ − Q^passive
/// (inverse dynamics of the free coordinates), is differentiated through the RNEA in ground
/// coordinates. Moving q_j by δ turns everything carried by it (the later axes of its joint
/// and its subtree) by the twist s_j δ, so, in Featherstone's notation,
///   ∂s_u/∂q_j = s_j ×m s_u,   ∂I_p/∂q_j = s_j ×* I_p − I_p s_j ×m,   ∂f_ext/∂q_j = s_j ×* f (follower)
/// for every use u and body p below q_j; the tangents of v, c, a and f follow by the product
/// rule through the three RNEA passes, one pass per direction: O(n) per column, O(n²) in all.
/// The accelerations follow from  ∂q̈/∂x = −A⁻¹ ∂r/∂x  (x = q, q̇) at the actual q̈.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// Step of the central differences at x: ∝ ε^(1/3) for an error O(ε^(2/3)).
inline double difference_step(double x) { return 6e-6 * std::max(1.0, std::abs(x)); }

/// Column j of ∂g/∂x by central differences, g() reading x by reference; x is restored.
template <class G>
VecX central_difference(G&& g, VecX& x, int j) {
  const double xj = x(j), h = difference_step(xj);
  x(j) = xj + h;
  const VecX gp = g();
  x(j) = xj - h;
  const VecX gm = g();
  x(j) = xj;
  return (gp - gm) / (2.0 * h);
}

/// Needs set_state, the free accelerations in d.qdda and kinematics: r = A q̈ − f (nq).
VecX inverse_dynamics(const System& sys, Data& d);
/// Needs set_state, the free accelerations in d.qdda and kinematics: (∂r/∂q, ∂r/∂q̇), each
/// (nq, nq), analytic for the rigid-body terms, springs and dampers; force laws by central
/// differences of their scalar functions.
std::pair<MatX, MatX> inverse_dynamics_derivatives(const System& sys, Data& d);
/// ∂q̈/∂q and ∂q̈/∂q̇ (nq, nq) at (t, q, q̇): −A⁻¹ (∂r/∂q, ∂r/∂q̇) at the forward-dynamics q̈.
std::pair<MatX, MatX> acceleration_derivatives(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                               const Eigen::Ref<const VecX>& qd);
/// Writes the free accelerations q̈ (nq) into d.qdda (after set_state).
void set_accelerations(const System& sys, Data& d, const Eigen::Ref<const VecX>& qdd);

}  // namespace rigidfem
