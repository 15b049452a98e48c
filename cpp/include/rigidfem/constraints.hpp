/// The constraint equations of the loop closures, g(q, t) = 0 (m rows), at the state of a Data:
/// their values g, rates ġ = G q̇ + g_t, Jacobian G = ∂g/∂q (all coordinates: free columns for
/// the equations of motion, prescribed ones for the driving forces) and the acceleration right-hand
/// side γ with G q̈ = γ (every term of g̈ but G q̈ of the free coordinates).
///
/// Rows, with d = r_B − r_A and a_i, b_j the axes of frames A and B (global):
///   position   d·a_i = 0  (i = x, y, z; prismatic and cylindrical: x, y)   λ: force on B along a_i
///   direction  b_j·a_i = 0 (revolute, cylindrical: z·x, z·y; prismatic and fixed: also x·y;
///                           universal: y·x)                                λ: torque λ b_j × a_i on B
///   distance   |d| − l(t) = 0                                              λ: force along d/|d| on B
/// Each quantity is tracked with its rate, its second rate at q̈_free = 0 and its Jacobian row(s):
/// for a vector e fixed in body p, ∂e/∂q_i = U_u e over the uses u of coordinate i on p's path.
#pragma once

#include "rigidfem/system.hpp"

namespace rigidfem {

/// => d.g, d.gd, d.G (nl, nc), d.gamma at the state of d (the accelerations in d.qdda). `spatial`:
/// from T and the axes (frames_and_axes, exact joints: the recursive algorithms' kinematics), the
/// rates from the spatial velocities and accelerations walked along each loop body's path; else from
/// T, Ṫ, T̈ and the twists U (kinematics with rates: the Lagrange formulation's, linear joints too).
/// The dynamics layer chooses (dynamics_kinematics).
void constraint_equations(const System& sys, Data& d, bool spatial);

/// The free columns of d.G (nl, nq).
MatX free_jacobian(const System& sys, const Data& d);

/// x = A⁺ b by the SVD of A with singular values below 1e-10 of the largest dropped (A = G S⁻¹ Gᵀ:
/// G's rows below 1e-5 of its largest singular value count as dependent): the multipliers of
/// redundant rows (a planar loop closed in 3D) share the load with least norm, and on a singular
/// position (a four-bar flat) the row G loses carries no multiplier.
VecX least_norm(const MatX& A, const VecX& b);

/// An orthonormal basis B (nl, r) of the range of G (nl, nq): the left singular vectors of the singular values
/// above 1e-5 of the largest (least_norm's rank decision on G S⁻¹ Gᵀ). The multipliers Bμ are least-norm for
/// this G: they leave out the rows' dependent combinations.
void row_basis(const MatX& G, MatX& B);

/// The same for a symmetric positive semi-definite A (G M⁻¹ Gᵀ, M symmetric): by its eigenvalues,
/// which are its singular values (the same rank decision), without the Jacobi SVD's sweeps.
VecX least_norm_symmetric(const MatX& A, const VecX& b, int rank = -1);
/// The same into x, with the caller's eigensolver and scratch c (no allocation once they are sized); returns
/// the rank it kept. With `rank` >= 0 (the rank found on the loops, project_and_forward_dynamics) it keeps at
/// most that many of A's directions where the others sum to at most 1e-6 tr A. That is a step's stage, off the
/// loops by a drift δ: there a redundant row's direction, of eigenvalue 0 on the loops, has one of order δ² and
/// a right-hand side of order δ, so that counting it would move q̈ by O(1) however small δ is. Otherwise it
/// decides as above.
int least_norm_symmetric(const MatX& A, const VecX& b, Eigen::SelfAdjointEigenSolver<MatX>& eigen, VecX& c,
                         VecX& x, int rank = -1);

/// The wrench each loop joint applies to its body B, in frame A's axes: (force N, torque N·m about
/// B's frame origin) per loop, from the multipliers λ (nl); for a Distance loop the force along the
/// line (positive pushing B away from A) in the first component, the rest zero. (nloops, 6).
RowMatX loop_reactions(const System& sys, const Data& d, const VecX& lambda);

}  // namespace rigidfem
