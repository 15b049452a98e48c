/// What a user reads off a state or a trajectory: energies, poses and points, and the batch
/// outputs of a simulation result.
#pragma once

#include <vector>

#include "rigidfem/system.hpp"

namespace rigidfem {

/// Energies after kinematics with rates (J): ½ Σ tr(Ṫ_p H_p Ṫ_pᵀ); −Σ m_p gᵀ r_Cp; ½ Σ c_i (q_i − q_i⁰)²
/// plus ½ Σ k (l − l₀)² of the force elements.
double kinetic_energy(const System& sys, const Data& d);
double gravity_energy(const System& sys, const Data& d);
double elastic_energy(const System& sys, const Data& d);
/// Power dissipated by the dampers, Σ b_i q̇_i² + Σ c l̇² of the force elements (W).
double dissipated_power(const System& sys, const Data& d);

/// The energies (J) and the dissipated power (W) at (t, q, q̇).
struct Energies {
  double kinetic, gravity, elastic, dissipated;
  double potential() const { return gravity + elastic; }
};
Energies energies(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                  const Eigen::Ref<const VecX>& qd);

/// Global pose T_p (4, 4) of a body at (t, q).
const Mat4& body_pose(const System& sys, Data& d, int body, double t, const Eigen::Ref<const VecX>& q);
/// Global position (3) in m of the point r (body frame) of a body at (t, q).
Vec3 point_position(const System& sys, Data& d, const Point& point, double t, const Eigen::Ref<const VecX>& q);
/// Global positions (k, 3) in m of several points at (t, q), from one kinematics pass.
MatX point_positions(const System& sys, Data& d, const std::vector<Point>& points, double t,
                     const Eigen::Ref<const VecX>& q);
/// Global velocity (3) in m/s of the point r of a body at (t, q, q̇).
Vec3 point_velocity(const System& sys, Data& d, const Point& point, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd);

/// Every force element's length l (m), rate l̇ (m/s) and axial force F (N, > 0 pushing the points
/// apart) at (t, q, q̇): rows of (nelements, 3). Applied parts of F at load factor 1.
MatX element_states(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd);

/// Quantities at a batch of states (t_k, q_k, q̇_k, s_k), rows k (S: the Maxwell arms' forces, (N, nz),
/// or (N, 0) without arms): accelerations, driving forces, energies (J; elastic with the arms'
/// Σ s²/(2k)), the dissipated power (W; with the arms' Σ s²/(kτ)), the force elements' axial forces and the
/// loops' reactions from the
/// multipliers of the same forward dynamics (the arm forces included) or, where a row of L (N, nl; or
/// (0, nl): none) is finite, from those (an integrator's own, Trajectory::lambda). Used for simulation
/// results.
struct StateOutputs {
  MatX qdd, tau;                          // (N, nq), (N, np)
  VecX kinetic, gravity, elastic, power;  // (N)
  MatX reactions;                         // (N, 6 nloops): each loop's wrench on its body b (loop_reactions), arms included
  MatX element_forces;                    // (N, nelements): the force elements' axial forces F (N, > 0 pushing)
};
StateOutputs evaluate_outputs(const System& sys, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q,
                              const Eigen::Ref<const RowMatX>& QD, const Eigen::Ref<const RowMatX>& S,
                              const Eigen::Ref<const RowMatX>& L);
/// Global positions (N, 3) of the point r (body frame) of `body` at (t_k, q_k), expressed in
/// the frame of body `frame` (−1: global): one positions-only kinematics pass per sample.
MatX point_positions(const System& sys, int body, const Vec3& r, int frame, const Eigen::Ref<const VecX>& t,
                     const Eigen::Ref<const RowMatX>& Q);
/// Every body's pose at (t_k, q_k): rows k·nbodies + i hold T_i's rotation row by row, then its origin
/// (m); one positions-only kinematics pass per sample (the viewer's frames, O(N n)).
RowMatX body_poses(const System& sys, const Eigen::Ref<const VecX>& t, const Eigen::Ref<const RowMatX>& Q);

}  // namespace rigidfem
