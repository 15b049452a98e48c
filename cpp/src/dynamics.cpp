#include "rigidfem/dynamics.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "rigidfem/constraints.hpp"
#include "rigidfem/derivatives.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/lagrange.hpp"
#include "rigidfem/recursive.hpp"

namespace rigidfem {

namespace {

bool recursive(const System& sys) { return sys.algorithm == Algorithm::Recursive; }

// Columns of ∂r/∂(q, q̇) by central differences of r at the state and accelerations of d,
// which is left at that state (the Lagrange formulation, the reference).
std::pair<MatX, MatX> differenced(const System& sys, Data& d) {
  const double t = d.t;
  const VecX qdd = d.qdda(sys.free_coords);
  VecX q = d.qa(sys.free_coords), qd = d.qda(sys.free_coords);
  auto r = [&] {
    set_state(sys, d, t, q, qd);
    set_accelerations(sys, d, qdd);
    kinematics(sys, d);
    return inverse_dynamics(sys, d);
  };
  MatX dq(sys.nq, sys.nq), dqd(sys.nq, sys.nq);
  for (int j = 0; j < sys.nq; ++j) {
    dq.col(j) = central_difference(r, q, j);
    interruption_point();
    dqd.col(j) = central_difference(r, qd, j);
  }
  r();
  return {dq, dqd};
}

// The state (t, q, q̇) with the formulation's kinematics.
void full_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  tree_kinematics(sys, d);
}

// ... and the free accelerations q̈.
void full_state(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd) {
  check_vector(qdd, sys.nq, "qdd", "nq");  // before the drives are evaluated (one at a huge t may fail first)
  set_state(sys, d, t, q, qd);
  set_accelerations(sys, d, qdd);
  tree_kinematics(sys, d);
}

// d.load_factor = λ, which scales gravity, loads and applied generalised forces.
void set_load_factor(Data& d, double load_factor) {
  if (!std::isfinite(load_factor)) bad("load_factor", "a finite factor", num(load_factor));
  d.load_factor = load_factor;
}

}  // namespace

void tree_kinematics(const System& sys, Data& d) {
  if (recursive(sys))
    frames_and_axes(sys, d);
  else
    kinematics(sys, d);
}

void dynamics_kinematics(const System& sys, Data& d) {
  tree_kinematics(sys, d);
  if (sys.nl > 0) constraint_equations(sys, d, recursive(sys));  // g, G and γ from the same kinematics
}

void generalized_forces(const System& sys, Data& d) {
  check_state(sys, d);
  if (recursive(sys))
    rnea_forces(sys, d);
  else
    lagrange_forces(sys, d);
}

void mass_matrix(const System& sys, Data& d) {
  check_state(sys, d);
  if (recursive(sys))
    crba(sys, d);
  else
    lagrange_mass_matrix(sys, d);
}

void accelerations(const System& sys, Data& d) {
  check_state(sys, d);
  if (sys.nq == 0) return;
  check_gimbal_lock(sys, d);
  d.llt.compute(d.A);
  if (d.llt.info() != Eigen::Success)
    throw SimulationError(d.t, "mass matrix is not positive definite (singular configuration or massless chain)");
  d.qdd = d.llt.solve(d.f);
  if (!d.qdd.allFinite()) throw SimulationError(d.t, "accelerations are NaN or inf");
}

void driving_forces(const System& sys, Data& d) {
  check_state(sys, d);
  if (sys.np == 0) return;
  set_accelerations(sys, d, d.qdd);
  if (recursive(sys)) {
    rnea_driving_forces(sys, d);
  } else {
    kinematics(sys, d);  // T̈ now holds the full accelerations
    lagrange_driving_forces(sys, d);
  }
  // The prescribed rows of M q̈ = f + τ + Gᵀλ: the loops carry part of the load.
  if (sys.nl > 0) d.tau -= d.G(Eigen::all, sys.drive_coords).transpose() * d.lambda;
}

VecX inverse_dynamics(const System& sys, Data& d) {
  generalized_forces(sys, d);  // with q̈ in d.qdda both formulations give f − A q̈
  return -d.f;
}

std::pair<MatX, MatX> inverse_dynamics_derivatives(const System& sys, Data& d) {
  return recursive(sys) ? rnea_derivatives(sys, d) : differenced(sys, d);
}

const VecX& forward_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                             const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  dynamics_kinematics(sys, d);
  if (recursive(sys)) {
    aba(sys, d);
  } else {
    lagrange_forces(sys, d);
    lagrange_mass_matrix(sys, d);
    accelerations(sys, d);
  }
  if (sys.nl > 0) close_loops(sys, d);
  return d.qdd;
}

namespace {

/// The loop with the largest |g| (its name and that residual), for messages.
std::string worst_loop(const System& sys, const Data& d) {
  Eigen::Index r = 0;
  const double worst = d.g.cwiseAbs().maxCoeff(&r);
  std::size_t k = 0;
  while (k + 1 < sys.loops.size() && sys.loop_row[k + 1] <= r) ++k;
  return "loop '" + sys.loops[k].name + "' (" + loop_kind_name(sys.loops[k].kind) + ", residual " + num(worst) + ")";
}

/// d.Y = M⁻¹ Gᵀ of the loops' free columns d.Gfree with the factorisation of M in d: the tree's, a column at a
/// time in place (no allocation), or the Lagrange engine's LLT. A row that is exactly zero (a planar loop's
/// out-of-plane rows: 3 of a revolute loop joint's 5 in the plane) has a zero column without a solve.
void mass_weighted_rows(const System& sys, Data& d) {
  if (!recursive(sys)) {
    d.Y = d.llt.solve(d.Gfree.transpose());
    return;
  }
  for (Eigen::Index j = 0; j < d.Gfree.rows(); ++j) {
    if ((d.Gfree.row(j).array() == 0.0).all()) {
      d.Y.col(j).setZero();
      continue;
    }
    d.loop_col = d.Gfree.row(j).transpose();
    aba_solve(sys, d, d.loop_col, d.loop_col);
    d.Y.col(j) = d.loop_col;
  }
}

}  // namespace

namespace {

/// λ = (G M⁻¹ Gᵀ)⁺ (γ − G q̈), q̈ += M⁻¹ Gᵀ λ with Y = M⁻¹ Gᵀ and G Y in d (no allocation).
void loop_accelerations(const System& sys, Data& d) {
  d.loop_rhs = d.gamma;
  d.loop_rhs.noalias() -= d.Gfree * d.qdd;
  least_norm_symmetric(d.GY, d.loop_rhs, d.loop_eigen, d.loop_c, d.lambda, d.loop_rank);
  d.qdd.noalias() += d.Y * d.lambda;
  set_accelerations(sys, d, d.qdd);
  if (!d.qdd.allFinite()) throw SimulationError(d.t, "accelerations of the closed loops are NaN or inf");
}

}  // namespace

void close_loops(const System& sys, Data& d) {
  d.Gfree = d.G(Eigen::all, sys.free_coords);
  mass_weighted_rows(sys, d);
  d.GY.noalias() = d.Gfree * d.Y;
  loop_accelerations(sys, d);
}

void loop_equations(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                    const Eigen::Ref<const VecX>& qd) {
  set_state(sys, d, t, q, qd);
  dynamics_kinematics(sys, d);
}

void factor_mass(const System& sys, Data& d) {
  if (!recursive(sys)) return factor_armature(sys, d, VecX::Zero(sys.nq));
  spatial_kinematics(sys, d);
  aba_factor(sys, d);
}

namespace {

/// project_onto_loops; with `factor_at_end` the velocity's projection factorises M at the projected q (rather
/// than keep a Gauss-Newton iterate's factorisation), so that d leaves with M factorised, G, Y = M⁻¹ Gᵀ and G Y
/// all at the projected q.
double project(const System& sys, Data& d, double t, VecX& q, VecX& qd, double tol, int max_iterations,
               bool factor_at_end) {
  if (sys.nl == 0) return 0.0;
  constexpr double eps = std::numeric_limits<double>::epsilon();
  double residual = 0.0, previous = 0.0;
  bool factored = false;  // M factorised in this call (at a configuration Gauss-Newton has since moved by Δq)
  MatX& G = d.Gfree;
  MatX& Y = d.Y;
  // Y = M⁻¹ Gᵀ (nq, nl) for the mass-weighted corrections, G at the state of d and M factorised there, or for
  // the velocity's projection at the last Gauss-Newton iterate (the weight need only be positive definite: the
  // projection lands on G q̇ = −∂g/∂t with the current G whatever it is)
  auto weighted = [&](bool refactor) {
    G = d.G(Eigen::all, sys.free_coords);
    if (refactor || !factored) factor_mass(sys, d), factored = true;
    mass_weighted_rows(sys, d);
  };
  int rank = -1;
  auto corrected = [&](const VecX& residuals) -> const VecX& {  // Y (G Y)⁺ residuals, into d.loop_col
    d.GY.noalias() = G * Y;
    rank = least_norm_symmetric(d.GY, residuals, d.loop_eigen, d.loop_c, d.loop_rhs);
    d.loop_col.noalias() = Y * d.loop_rhs;
    return d.loop_col;
  };
  for (int it = 0;; ++it) {
    loop_equations(sys, d, t, q, qd);
    interruption_point();
    residual = d.g.cwiseAbs().maxCoeff();
    double scale = 1.0;  // the model's length scale (m): its farthest body origin
    for (const Mat4& T : d.T) scale = std::max(scale, T.col(3).head<3>().cwiseAbs().maxCoeff());
    if (!std::isfinite(residual) || residual <= 16.0 * eps * scale) break;  // closed to round-off
    // Gauss-Newton runs on past tol while it gains: near a singular G a residual within tol can
    // still hide a position error |g|/σ off the branch, and the velocity projected on there an error
    // |g| q̇/σ². It stops where it no longer gains (round-off, or the residual lies along a row
    // that least_norm counts as dependent) or after max_iterations; linear convergence there is fine.
    if ((it > 0 && residual > 0.9 * previous) || it == max_iterations) break;
    weighted(true);
    q -= corrected(d.g);  // Δq = M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁺ g
    previous = residual;
  }
  if (!(residual <= std::max(tol, 1e-9)) || sys.nq == 0)
    throw SimulationError(t, "the closed loops cannot be assembled: Gauss-Newton from the given coordinates left " +
                                 worst_loop(sys, d) +
                                 " (the loop is out of reach, or its coordinates cannot move it); give coordinates "
                                 "closer to a closed configuration");
  // q̇ ← q̇ − M⁻¹Gᵀ (G M⁻¹ Gᵀ)⁺ ġ, ġ = G q̇ + ∂g/∂t: the correction is M-orthogonal to every motion
  // the loops allow, so it never raises the kinetic energy and takes none from the admissible motion
  // (the Euclidean Gᵀ(GGᵀ)⁺ġ does, where G loses rank).
  weighted(factor_at_end);
  qd -= corrected(d.gd);
  // on the loops the rank decision has its clear gap; the step's stages, off them by its drift, keep to it
  d.loop_rank = rank;
  return residual;
}

}  // namespace

double project_onto_loops(const System& sys, Data& d, double t, VecX& q, VecX& qd, double tol, int max_iterations) {
  const double residual = project(sys, d, t, q, qd, tol, max_iterations, false);
  d.loop_rank = -1;  // a projection by itself leaves later evaluations their own rank decision
  return residual;
}

const VecX& project_and_forward_dynamics(const System& sys, Data& d, double t, VecX& q, VecX& qd, double tol,
                                         int max_iterations) {
  if (sys.nl == 0 || !recursive(sys)) {
    project(sys, d, t, q, qd, tol, max_iterations, false);
    return forward_dynamics(sys, d, t, q, qd);
  }
  project(sys, d, t, q, qd, tol, max_iterations, true);
  // the configuration is the projection's last: its frames, G, the articulated inertias, Y and G Y stand
  set_state(sys, d, t, q, qd);
  constraint_equations(sys, d, true);  // ġ and γ at the projected q̇
  aba_on_factor(sys, d);
  loop_accelerations(sys, d);
  return d.qdd;
}

const MatX& mass_matrix(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q) {
  full_state(sys, d, t, q, VecX::Zero(sys.nq));
  mass_matrix(sys, d);
  return d.A;
}

const VecX& generalized_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                               const Eigen::Ref<const VecX>& qd, double load_factor) {
  set_load_factor(d, load_factor);
  full_state(sys, d, t, q, qd);
  generalized_forces(sys, d);
  return d.f;
}

const VecX& static_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                          double load_factor) {
  set_load_factor(d, load_factor);
  set_static_state(sys, d, t, q);
  tree_kinematics(sys, d);
  generalized_forces(sys, d);
  return d.f;
}

const VecX& driving_forces(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                           const Eigen::Ref<const VecX>& qd) {
  forward_dynamics(sys, d, t, q, qd);
  driving_forces(sys, d);
  return d.tau;
}

VecX inverse_dynamics(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                      const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd) {
  full_state(sys, d, t, q, qd, qdd);
  return inverse_dynamics(sys, d);
}

std::pair<MatX, MatX> inverse_dynamics_derivatives(const System& sys, Data& d, double t,
                                                   const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& qd,
                                                   const Eigen::Ref<const VecX>& qdd) {
  full_state(sys, d, t, q, qd, qdd);
  return inverse_dynamics_derivatives(sys, d);
}

VecX inverse_dynamics_direction(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd, const VecX& dq,
                                const VecX& dqd, const VecX& dqdd) {
  if (recursive(sys)) {
    full_state(sys, d, t, q, qd, qdd);
    return rnea_directional_derivative(sys, d, dq, dqd, dqdd);
  }
  // r is linear in q̈; along (δq, δq̇) a central difference with the largest relative change 6e-6
  const double size = std::max(dq.size() ? dq.cwiseAbs().maxCoeff() / std::max(1.0, q.cwiseAbs().maxCoeff()) : 0.0,
                               dqd.size() ? dqd.cwiseAbs().maxCoeff() / std::max(1.0, qd.cwiseAbs().maxCoeff()) : 0.0);
  const double eps = size > 0.0 ? 6e-6 / size : 1.0;
  const VecX up = inverse_dynamics(sys, d, t, q + eps * dq, qd + eps * dqd, qdd + eps * dqdd);
  return (up - inverse_dynamics(sys, d, t, q - eps * dq, qd - eps * dqd, qdd - eps * dqdd)) / (2.0 * eps);
}

ResidualVjp inverse_dynamics_vjp(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                 const Eigen::Ref<const VecX>& qd, const Eigen::Ref<const VecX>& qdd, const VecX& mu) {
  if (!recursive(sys))
    throw std::invalid_argument("system: expected a system compiled with algorithm='recursive' (the reverse mode is "
                                "the recursive engine's), got algorithm='lagrange'");
  full_state(sys, d, t, q, qd, qdd);
  return rnea_vector_jacobian_product(sys, d, mu);
}

std::pair<MatX, MatX> acceleration_derivatives(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                               const Eigen::Ref<const VecX>& qd) {
  if (sys.nl > 0) {
    // With loops q̈ = q̈(q, q̇) of the constrained dynamics (its least-norm λ(q, q̇) and G(q) included),
    // whose derivatives the tree's −A⁻¹ ∂r/∂(q, q̇) leaves out: central differences, O(n) per evaluation.
    VecX x = q, v = qd;
    const auto qdd = [&] { return forward_dynamics(sys, d, t, x, v); };
    MatX dq(sys.nq, sys.nq), dqd(sys.nq, sys.nq);
    for (int j = 0; j < sys.nq; ++j) {
      interruption_point();
      dq.col(j) = central_difference(qdd, x, j);
      dqd.col(j) = central_difference(qdd, v, j);
    }
    forward_dynamics(sys, d, t, q, qd);  // d left at the state, as below
    return {dq, dqd};
  }
  const VecX qdd = forward_dynamics(sys, d, t, q, qd);
  set_state(sys, d, t, q, qd);
  set_accelerations(sys, d, qdd);
  dynamics_kinematics(sys, d);
  auto [dq, dqd] = inverse_dynamics_derivatives(sys, d);
  // M⁻¹ by the articulated-body factorisation, column by column (O(n²) in all, Ctrl-C between the
  // columns), or by the Cholesky factor of the Lagrange formulation's A
  factor_armature(sys, d, VecX::Zero(sys.nq));
  return {-solve_armature(sys, d, dq), -solve_armature(sys, d, dqd)};
}

VecX rhs(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y) {
  check_vector(y, 2 * sys.nq, "y", "2 nq");
  VecX ydot(2 * sys.nq);
  ydot.head(sys.nq) = y.tail(sys.nq);
  ydot.tail(sys.nq) = forward_dynamics(sys, d, t, y.head(sys.nq), y.tail(sys.nq));
  return ydot;
}

MatX rhs_jacobian(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& y) {
  const int n = 2 * sys.nq;
  check_vector(y, n, "y", "2 nq");
  if (!std::isfinite(t)) bad("t", "a finite time in s", num(t));
  MatX J(n, n);
  if (analytic_derivatives(sys)) {
    check_vector(y, n, "y", "2 nq");
    auto [dq, dqd] = acceleration_derivatives(sys, d, t, y.head(sys.nq), y.tail(sys.nq));
    J << MatX::Zero(sys.nq, sys.nq), MatX::Identity(sys.nq, sys.nq), dq, dqd;
    return J;
  }
  VecX yp = y;
  for (int j = 0; j < n; ++j) {
    interruption_point();
    J.col(j) = central_difference([&] { return rhs(sys, d, t, yp); }, yp, j);
  }
  return J;
}

std::pair<MatX, MatX> force_jacobians(const System& sys, Data& d, double t, const Eigen::Ref<const VecX>& q,
                                      const Eigen::Ref<const VecX>& qd, double load_factor, bool static_drives) {
  set_load_factor(d, load_factor);
  // The state's checks first: the Lagrange branch copies q and q̇ before any stage sees them.
  set_state(sys, d, t, q, static_drives ? VecX::Zero(sys.nq) : VecX(qd));
  if (analytic_derivatives(sys)) {
    // f = −r(q, q̇, q̈ = 0): the analytic derivatives of the recursive inverse dynamics.
    if (static_drives)
      set_static_state(sys, d, t, q);
    else
      set_state(sys, d, t, q, qd);
    dynamics_kinematics(sys, d);
    auto [dq, dqd] = rnea_derivatives(sys, d);
    return {-dq, -dqd};
  }
  // The springs and dampers, −c_i (q_i − q_i⁰) − b_i q̇_i, are differentiated exactly; only the
  // rest (loads, inertia, force laws) by central differences, so stiff sdes (EA/Δ ~ 1e10)
  // add no round-off to the soft terms.
  VecX x = q, xd = static_drives ? VecX::Zero(sys.nq) : VecX(qd);
  auto f = [&]() -> VecX {
    if (static_drives)
      set_static_state(sys, d, t, x);
    else
      set_state(sys, d, t, x, xd);
    kinematics(sys, d);
    lagrange_forces(sys, d);
    VecX g = d.f;
    for (int k = 0; k < sys.nq; ++k) {
      const int i = sys.free_coords[k];
      g(k) -= sys.coords[i].spring.elastic_force(x(k), xd(k), d.spring_scale(i));
    }
    return g;
  };
  MatX dq(sys.nq, sys.nq), dqd = MatX::Zero(sys.nq, sys.nq);
  for (int j = 0; j < sys.nq; ++j) {
    dq.col(j) = central_difference(f, x, j);
    interruption_point();
    if (!static_drives) dqd.col(j) = central_difference(f, xd, j);
  }
  for (int k = 0; k < sys.nq; ++k) {  // the scales at t (the state of the last evaluation)
    const int i = sys.free_coords[k];
    const auto [k_own, c_own] = sys.coords[i].spring.derivatives(d.spring_scale(i));
    dq(k, k) += k_own;
    dqd(k, k) += c_own;
  }
  return {dq, dqd};
}

void factor_armature(const System& sys, Data& d, const VecX& armature) {
  if (recursive(sys)) return aba_factor(sys, d, armature);  // needs the spatial kinematics of the residual
  mass_matrix(sys, d);
  d.A.diagonal() += armature;
  d.llt.compute(d.A);
  if (d.llt.info() != Eigen::Success) throw SimulationError(d.t, "the mass matrix is not positive definite");
}

void solve_armature(const System& sys, Data& d, const VecX& b, VecX& x) {
  if (recursive(sys)) return aba_solve(sys, d, b, x);
  x = d.llt.solve(b);
}

MatX solve_armature(const System& sys, Data& d, const MatX& B) {
  if (!recursive(sys)) return d.llt.solve(B);
  MatX X(B.rows(), B.cols());
  VecX x;
  for (Eigen::Index j = 0; j < B.cols(); ++j) {
    interruption_point();
    x = B.col(j);
    aba_solve(sys, d, x, x);
    X.col(j) = x;
  }
  return X;
}

}  // namespace rigidfem
