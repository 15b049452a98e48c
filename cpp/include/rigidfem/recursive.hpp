/// Recursive O(n) algorithms (Featherstone) over the same System, in ground coordinates:
/// spatial vectors are expressed in the global frame at its origin — motion m = (ω, v_O),
/// force f = (n_O, F) — so composite and articulated inertias add without transforms.
/// Coordinate axes s_i = (w_i, v_i) come from the kinematics (frames_and_axes).
///
///   RNEA  (inverse dynamics):  v_p = v_λ + S q̇, a_p = a_λ + S q̈ + Ṡ q̇ (a_0 = −g),
///                              f_p = I_p a_p + v_p ×* I_p v_p − f_ext,p, τ = Sᵀ f̄_p (subtree sums)
///   CRBA  (mass matrix):       I^c_p = Σ_subtree I_k, a_ij = s_iᵀ I^c_b s_j
///   ABA   (forward dynamics):  three passes with articulated inertias I^A and biases p^A.
/// Prescribed coordinates enter as known accelerations (no constraint equations). Systems
/// with linear joints (the linear beam model) are not trees of rigid joints: they use the
/// Lagrange formulation.
#pragma once

#include "rigidfem/kinematics.hpp"

namespace rigidfem {

/// Spatial inertia at the global origin of mass m with centre c and inertia I_c about it (global axes):
/// [[I_c + m S(c) S(c)ᵀ, m S(c)], [m S(c)ᵀ, m 1]].
Mat6 spatial_inertia(double m, const Vec3& c, const Mat3& Ic);
void spatial_inertia(double m, const Vec3& c, const Mat3& Ic, Mat6& I);  ///< the same, into I
/// a_0 = (0, −g): gravity as an upward acceleration of the base.
Vec6 gravity_acceleration(const System& sys, const Data& d);
/// (T, axes, q̇) => velocities v_p, joint bias accelerations c_p = Σ ṡ_k q̇_k, spatial
/// inertias I_p and external loads f_ext,p, all in ground coordinates. Needs the axes.
void spatial_kinematics(const System& sys, Data& d);
/// RNEA with the accelerations in d.qdda: a_p = a_λ + c_p + Σ s q̈, f_p = I a + v ×* I v − f_ext,
/// summed over subtrees into d.sf. Needs spatial_kinematics.
void rnea_pass(const System& sys, Data& d);

/// Needs set_state and the axes: the generalised forces f (nq) of A q̈ = f by RNEA with the
/// free accelerations of d.qdda, f = −τ_RNEA + passive (= f − A q̈ when q̈ ≠ 0).
void rnea_forces(const System& sys, Data& d);
/// Needs the axes: the mass matrix A (nq, nq) by the composite-rigid-body algorithm.
void crba(const System& sys, Data& d);
/// Needs set_state and the axes: q̈ (nq) by the articulated-body algorithm.
void aba(const System& sys, Data& d);
/// Needs spatial_kinematics: the articulated-body factorisation of M + diag(δ), δ (nq) ≥ 0 added
/// to the free coordinates the way joint armature is (D = Sᵀ I^A S + diag δ). O(n).
void aba_factor(const System& sys, Data& d, const VecX& armature);
/// The same without armature (δ = 0): the factorisation aba itself makes.
void aba_factor(const System& sys, Data& d);
/// Needs set_state, the axes and an aba_factor without armature at the same q and t (q̇ may differ): aba
/// without its factorisation, q̈ from the articulated inertias in d.
void aba_on_factor(const System& sys, Data& d);
/// After aba_factor: x = (M + diag δ)⁻¹ b (nq) by the bias passes of ABA for a system at rest
/// with no gravity or loads under the forces b (x may be b). O(n). Overwrites the ABA workspace (p^A, u, a).
void aba_solve(const System& sys, Data& d, const VecX& b, VecX& x);
/// After aba: the driving forces τ (np) of the prescribed coordinates by RNEA with the full accelerations.
void rnea_driving_forces(const System& sys, Data& d);

}  // namespace rigidfem
