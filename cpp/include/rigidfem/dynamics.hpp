/// The equations of motion A(q) q̈ = f(q, q̇, t) of a System: the only place that chooses a
/// formulation (recursive: RNEA, CRBA, ABA and their analytic derivatives; Lagrange: the book's
/// equations, derivatives by central differences).
///
/// Stages (set_state and dynamics_kinematics first) write into Data; the functions taking a
/// state (t, q, q̇) run the whole pipeline on the workspace d given.
#pragma once

#include <tuple>
#include <utility>

#include "rigidfem/derivatives.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

/// The kinematics the system's formulation reads: T_p and the axes (recursive: read off the frames,
/// no 4x4 twists or rates), or T_p, Ṫ_p, T̈_p and the twists U_u (Lagrange, linear joints too).
void tree_kinematics(const System& sys, Data& d);
/// tree_kinematics, and with loops their constraint equations from the same kinematics: g, ġ and G;
/// γ when the free accelerations in d.qdda are zero.
void dynamics_kinematics(const System& sys, Data& d);
/// Whether ∂r/∂(q, q̇) is analytic (recursive) rather than differenced (4 nq residuals, Lagrange).
inline bool analytic_derivatives(const System& sys) { return sys.algorithm == Algorithm::Recursive; }
/// Whether M + diag δ has the O(n) articulated-body factorisation (recursive systems): the matrix-free
/// Newton matrix's preconditioner (newton_matrix.hpp).
inline bool articulated(const System& sys) { return sys.algorithm == Algorithm::Recursive; }
/// Whether the residual has the RNEA's reverse mode, (Kᵀμ, Cᵀμ, Mμ) in O(n) (recursive systems): the adjoint's
/// (adjoint.hpp).
inline bool reverse_mode(const System& sys) { return sys.algorithm == Algorithm::Recursive; }

// Stages, after set_state and a kinematics pass.
/// => f (nq): loads, velocity terms and passive forces (f − A q̈ if d.qdda holds free accelerations).
void generalized_forces(const System& sys, Data& d);
/// => A (nq, nq).
void mass_matrix(const System& sys, Data& d);
/// => q̈ (nq) solving A q̈ = f by Cholesky; SimulationError if A is singular.
void accelerations(const System& sys, Data& d);
/// => τ (np): driving forces of the prescribed coordinates from the full accelerations (their
/// rows of the equations). Needs q̈ in d.qdd (accelerations or forward_dynamics).
void driving_forces(const System& sys, Data& d);
/// r = A q̈ − f (nq) with the free accelerations of d.qdda: the inverse dynamics.
VecX inverse_dynamics(const System& sys, Data& d);
/// (∂r/∂q, ∂r/∂q̇), each (nq, nq), at the state and accelerations of d: analytic (recursive),
/// central differences of r (Lagrange).
std::pair<MatX, MatX> inverse_dynamics_derivatives(const System& sys, Data& d);

// The pipeline at a state (t in s, q in m and rad, q̇ per s).
/// q̈ (nq): ABA (recursive) or A q̈ = f (Lagrange).
const VecX& forward_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                             const Eigen::Ref<const VecX>& qd);
/// A(q) (nq, nq), the prescribed coordinates at their values at t.
const MatX& mass_matrix(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q);
/// f (nq) with gravity, loads and applied generalised forces scaled by load_factor.
const VecX& generalized_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                               const Eigen::Ref<const VecX>& qd, double load_factor);
/// The static residual f(q) (nq): at rest, the prescribed coordinates held at their values at t.
const VecX& static_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                          double load_factor);
/// τ (np) at the forward-dynamics accelerations.
const VecX& driving_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                           const Eigen::Ref<const VecX>& qd);
/// r = A q̈ − f (nq) at (t, q, q̇, q̈).
VecX inverse_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                      const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd);
/// (∂r/∂q, ∂r/∂q̇) at (t, q, q̇, q̈).
std::pair<MatX, MatX> inverse_dynamics_derivatives(const System& sys, Data& d, double t,
                                                   const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& qd,
                                                   const Eigen::Ref<const VecX>& qdd);
/// (∂r/∂q) δq + (∂r/∂q̇) δq̇ + A δq̈ (nq) at (t, q, q̇, q̈) along one direction: the RNEA's forward-mode
/// derivative (recursive: exact, O(n)); central differences of r (Lagrange).
VecX inverse_dynamics_direction(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd, const VecX& dq,
                                const VecX& dqd, const VecX& dqdd);
/// ((∂r/∂q)ᵀ μ, (∂r/∂q̇)ᵀ μ, A μ) and the same by the prescribed coordinates' motion at (t, q, q̇, q̈): the RNEA's
/// reverse mode (derivatives.hpp; recursive systems without links of varying length: std::invalid_argument
/// otherwise), O(n).
ResidualVjp inverse_dynamics_vjp(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                 const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd, const VecX& mu);
/// ∂q̈/∂q and ∂q̈/∂q̇ (nq, nq) at (t, q, q̇): −A⁻¹ (∂r/∂q, ∂r/∂q̇) at the forward-dynamics q̈; with loops, of
/// the constrained q̈ (λ(q, q̇) and G(q) varying too) by central differences.
std::pair<MatX, MatX> acceleration_derivatives(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                               const Eigen::Ref<const VecX>& qd);
/// dy/dt = [q̇, q̈] for y = [q, q̇] (2 nq).
VecX rhs(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y);
/// ∂(dy/dt)/∂y (2nq, 2nq): from acceleration_derivatives (recursive; with loops its differences), central
/// differences of rhs (Lagrange).
MatX rhs_jacobian(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y);
/// ∂f/∂q and ∂f/∂q̇ (nq, nq) at (t, q, q̇) with the loads scaled by load_factor, the prescribed
/// coordinates moving (static_drives = false) or held at their values at t (true: at rest, q̇
/// ignored). −∂f/∂q is the tangent stiffness, −∂f/∂q̇ the damping and gyroscopic matrix.
std::pair<MatX, MatX> force_jacobians(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                      const Eigen::Ref<const VecX>& qd, double load_factor, bool static_drives);

// Loop closures (sys.nl > 0): M q̈ = f + Gᵀλ with g(q, t) = 0 (constraints.hpp).
/// After the tree's forward dynamics at the state of d (d.qdd, and its factorisation: ABA's
/// articulated inertias or A's Cholesky factor) and constraint_equations: Y = M⁻¹ Gᵀ by nl
/// solves with that factorisation, (G Y) λ = γ − G q̈_tree by a rank-revealing factorisation
/// (redundant loops: the least-norm λ), q̈ = q̈_tree + Y λ into d.qdd, λ into d.lambda.
/// O(n·nl + nl³): no n×n factorisation with the recursive engine.
void close_loops(const System& sys, Data& d);
/// Moves (q, q̇) onto the constraint manifold at t: Gauss–Newton on g(q, t) = 0 with the
/// mass-weighted least-norm corrections Δq = −M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁺ g (least_norm: the rank decision
/// of close_loops) while they gain (to round-off of the model's size, at most max_iterations),
/// then q̇ ← q̇ − M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁺ ġ, which never raises the kinetic energy. Returns max |g|
/// reached (m, and for direction rows the cosine); SimulationError naming the loop with the
/// largest residual when it ends above max(tol, 1e-9).
/// g, ġ, G and γ (γ for q̈_free = 0) into d at (t, q, q̇).
void loop_equations(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd);
double project_onto_loops(const System& sys, Data& d, double t, VecX& q, VecX& qd, double tol, int max_iterations);
/// project_onto_loops, then forward_dynamics at the projected state: the velocity's projection factorises M at
/// the projected q, and the accelerations keep that factorisation, the frames, G, Y = M⁻¹Gᵀ and G Y (all of q
/// alone), so that both cost about one constrained forward dynamics (recursive engine; the Lagrange engine
/// evaluates anew). q̈ (nq) as d.qdd. It also records in d.loop_rank the rank of G M⁻¹ Gᵀ on the loops, which the
/// forward dynamics with d keep to until the next projection (a step's stages, off the loops by the step's
/// drift: least_norm_symmetric).
const VecX& project_and_forward_dynamics(const System& sys, Data& d, double t, VecX& q, VecX& qd, double tol,
                                         int max_iterations);

// The operator of the implicit methods.
/// Factorises M + diag(δ) (δ (nq) ≥ 0) at the state of the last inverse_dynamics: O(n) by the
/// articulated-body algorithm with δ as armature (recursive), dense Cholesky (Lagrange).
void factor_armature(const System& sys, Data& d, const VecX& armature);
/// The factorisation of M at the state of d for solve_armature (after dynamics_kinematics).
void factor_mass(const System& sys, Data& d);
/// After factor_armature: x = (M + diag δ)⁻¹ b (x may be b).
void solve_armature(const System& sys, Data& d, const VecX& b, VecX& x);
/// After factor_armature (or a forward dynamics, which leaves δ = 0 factorised): X = (M + diag δ)⁻¹ B,
/// column by column (nq, k): the Y = M⁻¹Gᵀ of the loop closures.
MatX solve_armature(const System& sys, Data& d, const MatX& B);

}  // namespace rigidfem
