/// The contacts' forces at a state (contact.hpp: shapes, contacts, the law). Every pair of shapes reduces to
/// features of two kernels:
///   point–plane: a point x_B of radius r_B (a sphere's centre, a capsule's two ends, a box's eight corners with
///     r_B = 0) against the plane (o, n) of a half-space: gap g = n·(x_B − o) − r_B, contact point
///     x_c = x_B − (r_B + g/2) n;
///   point–point: the closest points p_A, p_B of two segments (a sphere's is a point) of radii r_A, r_B:
///     n = (p_B − p_A)/|p_B − p_A|, g = |p_B − p_A| − r_A − r_B, x_c = p_A + (r_A + g/2) n.
/// Where g < 0 the contact pushes body b (the sphere's, capsule's or box's against a half-space) by
/// f = F_n n + f_t at x_c and body a by −f there: F_n of the penetration δ = −g and its rate δ̇ = −n·v_rel, f_t of
/// the slip v_t = (1 − n nᵀ) v_rel, with v_rel = v_b(x_c) − v_a(x_c) the bodies' velocities at the contact point.
/// A half-space against n spheres, capsules or boxes costs O(n) features; two groups of spheres and capsules meet by
/// sweep and prune (their extents along x sorted, only the overlapping ones tested; all pairs below 64).
#pragma once

#include <functional>

#include "rigidfem/contact.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

/// One overlap of two shapes at the current state: the kernel's geometry (global, m) and the bodies' spatial
/// velocities (ω, v_O) it was evaluated from, and its force.
struct ContactForce {
  int contact = -1, body_a = -1, body_b = -1;
  bool plane = false;  ///< point–plane: p[0] = o, p[1] = n, p[2] = x_B; point–point: segments p[0]–p[1], p[2]–p[3]
  Vec3 p[4];
  double ra = 0.0, rb = 0.0;
  Vec6 Va = Vec6::Zero(), Vb = Vec6::Zero();
  Vec3 x, n, f, vt;      ///< contact point, normal (a to b), force on b (N), slip (m/s)
  double gap, gap_rate;  ///< g (m, < 0), ġ (m/s)
  double Fn;             ///< normal force (N)
};

/// visit(c) for every overlap at d's state (needs d.T, and d.v (`spatial`) or d.Td): O(shape pairs declared);
/// no allocation.
void for_each_contact_force(const System& sys, const Data& d, bool spatial,
                            const std::function<void(const ContactForce&)>& visit);

/// The smallest gap (m) between the shapes of contact k at d's frames (d.T), overlapping or not: negative once they
/// overlap (its events' function: onset and separation). Where two groups of many spheres and capsules meet, the
/// pairs whose extents along x lie farther apart than the largest radius are left out and the gap is capped there
/// (the same continuous function near zero).
double contact_gap(const System& sys, const Data& d, int k);

/// J = ∂(x_c × f, f)/∂ε (6×24) of one overlap: the change of the wrench on body b about the global origin when the
/// bodies move by the twists W_a, W_b (a material point x moves by W_v + W_ω × x) and their spatial velocities
/// change by δV_a, δV_b, ε = (W_a, δV_a, W_b, δV_b); by automatic differentiation of the kernels (exact).
Eigen::Matrix<double, 6, 24> contact_jacobian(const System& sys, const ContactForce& c);

/// The energy (J) the contacts store and the power (W) they dissipate at d's state (kinematics with rates).
double contact_energy(const System& sys, const Data& d);
double contact_power(const System& sys, const Data& d);

}  // namespace rigidfem
