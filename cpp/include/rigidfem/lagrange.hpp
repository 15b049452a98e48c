/// The book's Lagrange formulation (ch. 2.4-2.7) as named stages.
///
/// With T_p the global pose of body p, H_p its pseudo-inertia and
/// ∂T_p/∂q_i = U_i T_p (U_i the 4x4 global twist of coordinate i, equal for every
/// body below coordinate i), Lagrange's equations read A(q) q̈ = f(q, q̇, t):
///   a_ij = Σ_p tr(T_{p,i} H_p T_{p,j}ᵀ) = tr(U_i H̄_b U_jᵀ),
///   f_i  = tr(U_i (Z̄_b − W̄_b)) − c_i (q_i − q_i⁰) − b_i q̇_i + Q_i,
/// where b is the deeper of the two coordinates' bodies and the bars are sums over
/// the subtree of b (the book's link-by-link accumulation):
///   H̄_b = Σ T_k H_k T_kᵀ,  W̄_b = Σ T_k H_k T̈_kᵀ (T̈ with q̈_free = 0: velocity terms),
///   Z̄_b = Σ (T_k H_k e₄) g̃ᵀ + Σ loads (Q_i = tr(U_i Z̄) is their virtual work).
/// Cost: O(n) for everything but the mass matrix, O(n·depth) for A, O(n³) to solve.
#pragma once

#include "rigidfem/system.hpp"

namespace rigidfem {

/// (t, q, q̇) => qa, qda, qdda: the free coordinates from q, q̇ (q̈ = 0), the
/// prescribed ones from their drives. Checks sizes and finiteness.
void set_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& qd);
/// (t, q) => qa, with q̇ = q̈ = 0 for every coordinate, the prescribed ones held at
/// their values at t (statics).
void set_static_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q);
/// (qa, qda, qdda) => T_p, Ṫ_p, T̈_p (nbodies) and U_i (nc): forward recursion
/// T_p = T_parent B_p T̃_p(q_p) with the joint's elementary factors differentiated in time.
/// Also the axes s_u = (ω, v_O) of U_u. rates = false computes only T_p and the axes for
/// recursive systems (all their algorithms need; U_u is then not computed), T_p and U_u otherwise.
void kinematics(const System& sys, Data& d, bool rates = true);
/// (T, T̈) => W̄_p = Σ_{k in subtree(p)} T_k H_k T̈_kᵀ.
void inertia_composites(const System& sys, Data& d);
/// (T) => Z̄_p = Σ_{k in subtree(p)} (T_k H_k e₄) g̃ᵀ + (T_k r) F̃ᵀ + [[−½ S(τ), 0], [0, 0]].
void load_composites(const System& sys, Data& d);
/// A load at the current state, global: point of application x (m), force F (N), torque τ
/// (N·m), with its time scale and load factor applied and follower loads turned with the body.
struct AppliedLoad {
  Vec3 x, F, tau;
};
AppliedLoad applied_load(const Data& d, const Load& L);
/// Q_i of springs, dampers and applied generalised forces on coordinate i (all coordinates).
double passive_force(const System& sys, const Data& d, int i);
/// => f (nq): loads, velocity terms and passive forces. Needs kinematics.
void generalized_forces(const System& sys, Data& d);
/// => A (nq, nq): a_ij = tr(U_i H̄_b U_jᵀ). Needs kinematics.
void mass_matrix(const System& sys, Data& d);
/// SimulationError if a ZYX joint sits at pitch ±π/2, where its mass matrix is singular.
void check_gimbal_lock(const System& sys, const Data& d);
/// => q̈ (nq) solving A q̈ = f; SimulationError if A is singular.
void accelerations(const System& sys, Data& d);
/// => τ (np): driving forces of the prescribed coordinates from the full
/// accelerations (inverse dynamics of their rows). Needs accelerations.
void driving_forces(const System& sys, Data& d);

/// The pipeline: set_state, kinematics, generalized_forces, mass_matrix, accelerations.
const VecX& forward_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                             const Eigen::Ref<const VecX>& qd);
/// dy/dt = [q̇, q̈] for y = [q, q̇] (2 nq).
VecX rhs(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y);
/// ∂(dy/dt)/∂y (2nq, 2nq): analytic for recursive systems (derivatives.hpp), central
/// differences for the Lagrange formulation.
MatX rhs_jacobian(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y);

/// ∂f/∂q and ∂f/∂q̇ (nq, nq) at (t, q, q̇), analytic for recursive systems and by central
/// differences for the Lagrange formulation, with the prescribed
/// coordinates moving (static = false) or held at their values at t (static = true: at rest, q̇ ignored).
/// −∂f/∂q is the tangent stiffness, −∂f/∂q̇ the damping and gyroscopic matrix.
std::pair<MatX, MatX> force_jacobians(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                      const Eigen::Ref<const VecX>& qd, bool static_drives);

/// "" or a sentence naming the ZYX joints whose pitch φ2 (free coordinates q) is within
/// `tol` of ±π/2 in cos φ2, where Euler angles are singular (gimbal lock).
std::string gimbal_lock_hint(const System& sys, const VecX& q, double tol);

/// Quantities at a batch of states (t_k, q_k, q̇_k), rows k: accelerations, driving
/// forces and energies (J). Used for simulation results.
struct StateOutputs {
  MatX qdd, tau;  // (N, nq), (N, np)
  VecX kinetic, gravity, elastic;  // (N)
};
StateOutputs evaluate_outputs(const System& sys, const VecX& t, const MatX& Q, const MatX& QD);
/// Global positions (N, 3) of the point r (body frame) of `body` at (t_k, q_k), expressed in
/// the frame of body `frame` (−1: global).
MatX point_positions(const System& sys, int body, const Vec3& r, int frame, const VecX& t, const MatX& Q);

/// Energies after kinematics (J): ½ Σ tr(Ṫ_p H_p Ṫ_pᵀ); −Σ m_p gᵀ r_Cp; ½ Σ c_i (q_i − q_i⁰)².
double kinetic_energy(const System& sys, const Data& d);
double gravity_energy(const System& sys, const Data& d);
double elastic_energy(const System& sys, const Data& d);
/// Power dissipated by the dampers, Σ b_i q̇_i² (W).
double dissipated_power(const System& sys, const Data& d);

}  // namespace rigidfem
