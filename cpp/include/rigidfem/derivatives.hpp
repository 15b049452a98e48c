/// Analytic derivatives of the recursive equations of motion (systems compiled with
/// algorithm=recursive), and the central differences used where no analytic form exists.
///
/// The residual of the equations of motion, r(q, q̇, q̈) = A(q) q̈ − f(q, q̇, t) = Sᵀ f̄ − Q^passive
/// (inverse dynamics of the free coordinates), is differentiated through the RNEA in ground
/// coordinates. Moving q_j by δ turns everything carried by it (the later axes of its joint
/// and its subtree) by the twist s_j δ, so, in Featherstone's notation,
///   ∂s_u/∂q_j = s_j ×m s_u,   ∂I_p/∂q_j = s_j ×* I_p − I_p s_j ×m,   ∂f_ext/∂q_j = s_j ×* f (follower)
/// for every use u and body p below q_j; the tangents of v, c, a and f follow by the product
/// rule: along one direction through the three RNEA passes (O(n)), and as the matrices ∂r/∂q, ∂r/∂q̇
/// in closed form over subtrees (derivatives.cpp: a few dot products per entry, O(n²) in all).
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "rigidfem/recursive.hpp"

namespace rigidfem {

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

/// Needs set_state, the free accelerations in d.qdda and the axes (frames_and_axes): (∂r/∂q,
/// ∂r/∂q̇), each (nq, nq), analytic for the rigid-body terms, springs and dampers; force laws by
/// central differences of their scalar functions.
std::pair<MatX, MatX> rnea_derivatives(const System& sys, Data& d);

/// Needs what rnea_derivatives needs: (∂r/∂q) δq + (∂r/∂q̇) δq̇ + A δq̈ (nq) along one direction, exact, in O(n)
/// (forward mode: each body's frame carried by the twist W_p = Σ_{uses u on its path} s_u δq_u, so
/// δs_u = W_before ×m s_u and δI_p = W_p ×* I_p − I_p W_p ×m; the RNEA's passes differentiated along it).
VecX rnea_directional_derivative(const System& sys, Data& d, const VecX& dq, const VecX& dqd, const VecX& dqdd);

/// (∂r/∂q)ᵀ μ, (∂r/∂q̇)ᵀ μ and A μ (each nq) for one μ (nq), and the same by the prescribed coordinates'
/// values, rates and accelerations (each np): the reverse mode, rnea_directional_derivative's sweeps transposed
/// (leaves to root), O(n) — what an adjoint needs of the residual. Needs what rnea_derivatives needs; links of
/// varying length are not covered (std::invalid_argument).
struct ResidualVjp {
  VecX q, qd, qdd;
  VecX pq, pqd, pqdd;  ///< (np) ∂(μᵀr)/∂ of the prescribed coordinates' q, q̇, q̈
};
ResidualVjp rnea_vector_jacobian_product(const System& sys, Data& d, const VecX& mu);

/// The reverse mode at one state for many μ (an adjoint's transposed solves): prepare(d) computes once what does
/// not depend on μ (the spatial kinematics, the RNEA pass, the loads' and elements' states and their laws'
/// derivatives, the velocities before each use, I v and I a), apply(d, μ) runs only the sweeps, into a buffer it
/// keeps (valid until the next apply). Needs what rnea_derivatives needs; d must not change in between.
class ResidualTranspose {
 public:
  explicit ResidualTranspose(const System& sys);
  ~ResidualTranspose();
  void prepare(Data& d);
  const ResidualVjp& apply(const Data& d, const VecX& mu);

 private:
  struct Prepared;
  const System& sys_;
  std::unique_ptr<Prepared> p_;
  ResidualVjp out_;
};

}  // namespace rigidfem
