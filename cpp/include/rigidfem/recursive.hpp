/// Recursive O(n) algorithms (Featherstone) over the same System, in ground coordinates:
/// spatial vectors are expressed in the global frame at its origin — motion m = (ω, v_O),
/// force f = (n_O, F) — so composite and articulated inertias add without transforms.
/// Coordinate axes s_i = (w_i, v_i) are the global twists U_i of the kinematics stage.
///
///   RNEA  (inverse dynamics):  v_p = v_λ + S q̇, a_p = a_λ + S q̈ + Ṡ q̇ (a_0 = −g),
///                              f_p = I_p a_p + v_p ×* I_p v_p − f_ext,p, τ = Sᵀ f̄_p (subtree sums)
///   CRBA  (mass matrix):       I^c_p = Σ_subtree I_k, a_ij = s_iᵀ I^c_b s_j
///   ABA   (forward dynamics):  three passes with articulated inertias I^A and biases p^A.
/// Prescribed coordinates enter as known accelerations (no constraint equations). Systems
/// with linear joints (the linear beam model) are not trees of rigid joints: they use the
/// Lagrange formulation.
#pragma once

#include "rigidfem/system.hpp"

namespace rigidfem {

/// Needs set_state and kinematics: the generalised forces f (nq) of A q̈ = f by RNEA with the
/// free accelerations zero, f = −τ_RNEA + passive.
void rnea_forces(const System& sys, Data& d);
/// Needs kinematics: the mass matrix A (nq, nq) by the composite-rigid-body algorithm.
void crba(const System& sys, Data& d);
/// Needs set_state and kinematics: q̈ (nq) by the articulated-body algorithm; with the
/// driving forces τ (np) of the prescribed coordinates from a final RNEA pass.
void aba(const System& sys, Data& d);
/// After aba: the driving forces τ (np) of the prescribed coordinates by RNEA with the full accelerations.
void rnea_driving_forces(const System& sys, Data& d);

}  // namespace rigidfem
