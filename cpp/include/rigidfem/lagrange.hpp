/// The book's Lagrange formulation (ch. 2.4-2.7).
///
/// With T_p the global pose of body p, H_p its pseudo-inertia and
/// ∂T_p/∂q_i = U_i T_p (U_i the 4x4 global twist of coordinate i, equal for every
/// body below coordinate i), Lagrange's equations read A(q) q̈ = f(q, q̇, t):
///   a_ij = Σ_p tr(T_{p,i} H_p T_{p,j}ᵀ) = tr(U_i H̄_b U_jᵀ),
///   f_i  = tr(U_i (Z̄_b − W̄_b)) − c_i (q_i − q_i⁰) − b_i q̇_i + Q_i,
/// where b is the deeper of the two coordinates' bodies and the bars are sums over the
/// subtree of b (the book's link-by-link accumulation):
///   H̄_b = Σ T_k H_k T_kᵀ,  W̄_b = Σ T_k H_k T̈_kᵀ (T̈ with q̈_free = 0: velocity terms),
///   Z̄_b = Σ (T_k H_k e₄) g̃ᵀ + Σ loads (Q_i = tr(U_i Z̄) is their virtual work).
/// Cost: O(n) for everything but the mass matrix, O(n·depth) for A, O(n³) to solve.
/// Every function needs set_state and kinematics (with rates).
#pragma once

#include "rigidfem/kinematics.hpp"

namespace rigidfem {

/// (T, T̈) => W̄_p = Σ_{k in subtree(p)} T_k H_k T̈_kᵀ.
void inertia_composites(const System& sys, Data& d);
/// (T) => Z̄_p = Σ_{k in subtree(p)} (T_k H_k e₄) g̃ᵀ + (T_k r) F̃ᵀ + [[−½ S(τ), 0], [0, 0]].
void load_composites(const System& sys, Data& d);
/// => f (nq): f_i = tr(U_i (Z̄_b − W̄_b)) + Q_i^passive, loads minus the velocity (and drive) terms.
void lagrange_forces(const System& sys, Data& d);
/// => A (nq, nq): a_ij = tr(U_i H̄_b U_jᵀ).
void lagrange_mass_matrix(const System& sys, Data& d);
/// => τ (np), after lagrange_forces (its Z̄) and a kinematics pass with the full accelerations in
/// qdda: row i of the full equations, Σ tr(T_{p,i} H T̈ᵀ) = Q_i^loads + Q_i^passive + τ_i.
void lagrange_driving_forces(const System& sys, Data& d);

}  // namespace rigidfem
