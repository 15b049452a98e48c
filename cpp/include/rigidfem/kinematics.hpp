/// Kinematics: the state, the poses and coordinate axes of the bodies, the loads applied to
/// them and the passive forces of the coordinates (the layer under both formulations).
///
/// T_p = T_parent B_p T̃_p(q_p): the joint's motion T̃_p comes from joint_motion (jcalc), the
/// forward recursion from here. With ∂T_k/∂q_i = U_i T_k for every body k below coordinate i,
/// U_i is the coordinate's global twist, with the axis s_i = (ω, v_O).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "rigidfem/contact_forces.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

/// (t, q, q̇) => qa, qda, qdda: the free coordinates from q, q̇ (q̈ = 0), the
/// prescribed ones from their drives. Checks sizes and finiteness.
void set_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& qd);
/// (t, q) => qa, with q̇ = q̈ = 0 for every coordinate, the prescribed ones held at
/// their values at t (statics).
void set_static_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q);
/// Writes the free accelerations q̈ (nq) into d.qdda (after set_state).
void set_accelerations(const System& sys, Data& d, const Eigen::Ref<const VecX>& qdd);

/// (qa, qda, qdda) => T_p, and if `rates` Ṫ_p, T̈_p (nbodies), U_u and the axes s_u (nuses):
/// the forward recursion T_p = T_parent B_p T̃_p(q_p) with the joint's factors differentiated in
/// time (every joint, linear ones included: the Lagrange formulation's kinematics).
void kinematics(const System& sys, Data& d, bool rates = true);
/// (qa) => T_p and the axes s_u, read off the frame after each elementary factor, without 4x4
/// twists or rates: all the recursive algorithms need. Exact joints only.
void frames_and_axes(const System& sys, Data& d);

/// (qa) => T_p only, the cheapest pass (positions): the frames after each elementary factor for
/// exact joints, jcalc without rates for linear ones.
void frames(const System& sys, Data& d);

/// A load at the current state, global: point of application x (m), force F (N), torque τ
/// (N·m), with its time scale and load factor applied and follower loads turned with the body.
struct AppliedLoad {
  Vec3 x, F, tau;
};
/// Needs T_p of the load's body.
AppliedLoad applied_load(const Data& d, const Load& L);
/// A force element (force_elements.hpp) at the current state: its points r_A, r_B (global, m),
/// their velocities, the unit vector e = (r_B − r_A)/l, the length l (m), its rate l̇ = e·(v_B − v_A)
/// (m/s) and the axial force F (N, > 0 pushing). A heavy rope's span of mass m (ElementLaw::span_mass, μ l_u) hangs
/// ½ λ m g on each point, and the rope its drums have paid out, μ s, is taken from their mass at A where it leaves
/// them: w_B = ½ λ m g, w_A = λ (½ m − μ s) g, the gradient of V = −½ m g·(r_A + r_B) + μ s g·r_A. Wound on drums or
/// sheaves, it pulls them by P = P_law + ½ λ μ g·(r_B − r_A) (N; ElementLaw::pull, μ = ∂m/∂s, λ the load factor). The velocities come from the spatial velocities v_p of the recursive
/// algorithms (`spatial`) or from Ṫ_p (kinematics with rates). A SimulationError at t if the points coincide
/// (l = 0: no line of action).
struct ElementState {
  Vec3 xa, xb, va, vb, e;
  double l, ld, F;
  double s = 0.0, sd = 0.0;  ///< wound on drums or sheaves: the length paid out, Σ r q (m), and its rate (m/s)
  Vec3 wa = Vec3::Zero(), wb = Vec3::Zero();  ///< the weights on A and B (N)
  double P = 0.0;            ///< the pull on its drums and sheaves (N)
  Extension extension() const { return {l, ld, s, sd}; }
};
ElementState element_state(const System& sys, const Data& d, const ForceElement& element, bool spatial);
/// The element's loads: F e + w_B on body b at r_B and −F e + w_A on body a at r_A (none on the ground).
std::pair<AppliedLoad, AppliedLoad> element_loads(const ElementState& s);

/// Links of varying length (flows.hpp) at d.t: L, v, v̇ into d.flow (the rates zero `at_rest`),
/// the rfes' mass properties at L(t) into d.H, d.mass, d.com, d.inertia, and L₀/L into the spring
/// scales of their sdes. A SimulationError if L(t) <= 0 or is not finite.
void update_flows(const System& sys, Data& d, bool at_rest);
/// One rfe of a link of varying length at the current state: its body and the body `prev` whose
/// axis e_prev the material leaves at the rfe's origin (rfe k − 1; for rfe 0 the guide: the
/// parent, e_prev = x of T_parent B_0), its mass m and mass per length ρA, the flow speed
/// α = v (1 − ξ) and acceleration β = v̇ (1 − ξ) relative to its frame, its axis e, angular
/// velocity ω, centre of mass x_C and origin (global). Velocities as in element_state.
struct FlowTerm {
  int body, prev;
  double m, rhoA, alpha, beta;
  Vec3 e, e_prev, omega, xc, origin;
};
FlowTerm flow_term(const System& sys, const Data& d, int flow, int k, bool spatial);
/// visit(term) for rfe k = 0..m of every link of varying length (no allocation: the per-step path).
template <class Visit>
void for_each_flow_term(const System& sys, const Data& d, bool spatial, Visit&& visit) {
  for (int f = 0; f < static_cast<int>(sys.flows.size()); ++f)
    for (int k = 0; k <= sys.flows[f].elements; ++k) visit(flow_term(sys, d, f, k, spatial));
}
/// The loads of the flowing material (inertia moved to the right-hand side): on rfe k
/// −m (2 α ω × e + β e) at x_C (Coriolis and relative acceleration), and −ρA α² (e − e_prev)
/// at its origin (the turn at the sde).
std::pair<AppliedLoad, AppliedLoad> flow_loads(const FlowTerm& f);

/// visit(body, load, follower) for every load on a body at the current state, the one list both
/// formulations and the tangents read: the model's loads, the force elements' two point forces
/// (none on the ground), the contacts' forces f on body b and −f on body a at their contact points
/// (contact_forces.hpp) and the loads of the flowing material. Velocities as in element_state.
template <class Visit>
void for_each_body_load(const System& sys, const Data& d, bool spatial, Visit&& visit) {
  for (const Load& L : sys.loads) visit(L.body, applied_load(d, L), L.follower);
  for (const ForceElement& E : sys.elements) {
    const auto [on_b, on_a] = element_loads(element_state(sys, d, E, spatial));
    if (E.body_b >= 0) visit(E.body_b, on_b, false);
    if (E.body_a >= 0) visit(E.body_a, on_a, false);
  }
  if (!sys.contacts.empty())
    for_each_contact_force(sys, d, spatial, [&visit](const ContactForce& c) {
      if (c.body_b >= 0) visit(c.body_b, AppliedLoad{c.x, c.f, Vec3::Zero()}, false);
      if (c.body_a >= 0) visit(c.body_a, AppliedLoad{c.x, -c.f, Vec3::Zero()}, false);
    });
  for_each_flow_term(sys, d, spatial, [&](const FlowTerm& f) {
    const auto [coriolis, turn] = flow_loads(f);
    visit(f.body, coriolis, false);
    visit(f.body, turn, false);
  });
}

/// Σ Q_law + Σ r P c of coordinate i: its further laws' Q(t, q, q̇) (coordinate_laws.hpp) and, as a drum or a
/// sheave's slip, r P c of each rope wound on it (force_elements.hpp: Winding; its state from d.v where `spatial`, else
/// d.Td). Out of line: passive_force calls it only for the coordinates that have them.
double further_force(const System& sys, const Data& d, int i, bool spatial);
/// Q_i of the laws on coordinate i (all coordinates): its spring-damping law −s (k (q − q⁰) + c q̇) + λ Q₀, its
/// Maxwell arms' −Σ s (d.arm_force) and further_force.
inline double passive_force(const System& sys, const Data& d, int i, bool spatial) {
  const Coordinate& c = sys.coords[i];
  // −s (k (q − q⁰) + c q̇) − Σ s_arm + λ Q₀ + Σ Q_law + Σ r P c of the ropes wound on it
  const double Q = c.spring.elastic_force(d.qa(i), d.qda(i), d.spring_scale(i)) - d.arm_force(i) +
                   d.load_factor * c.spring.force;
  return c.laws.empty() && c.windings.empty() ? Q : Q + further_force(sys, d, i, spatial);
}
/// (∂Q/∂q_i, ∂Q/∂q̇_i) of coordinate i's further laws (coordinate_laws.hpp) at d's state: the spring-damping
/// law's own are exact constants the callers take from Coordinate::spring, and the arms' are internal variables.
std::pair<double, double> coordinate_derivatives(const System& sys, const Data& d, int i);

/// SimulationError if a ZYX joint sits at pitch ±π/2, where its mass matrix is singular.
void check_gimbal_lock(const System& sys, const Data& d);
/// "" or a sentence naming the ZYX joints whose pitch φ2 (free coordinates q) is within
/// `tol` of ±π/2 in cos φ2, where Euler angles are singular (gimbal lock).
std::string gimbal_lock_hint(const System& sys, const VecX& q, double tol);

}  // namespace rigidfem
