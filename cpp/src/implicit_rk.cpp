// Implicit Runge–Kutta methods of high order for the second-order system M(q) q̈ = f(q, q̇, t),
// stiffly accurate and L-stable, with embedded error estimates.
//
// ESDIRK: y = [q, q̇] advanced by a singly diagonally implicit tableau (a_11 = 0, a_ii = γ), each
// implicit stage i an unknown acceleration A_i at t_i = t + c_i h:
//   V_i = v̂_i + γh A_i,        v̂_i = q̇_n + h Σ_{j<i} a_ij A_j,
//   Q_i = q̂_i + γh V_i,        q̂_i = q_n + h Σ_{j<i} a_ij V_j,
//   r(A_i) = M(Q_i) A_i − f(Q_i, V_i, t_i) = 0,
// solved by Newton with the matrix ∂r/∂A_i = M + γh C + (γh)² K (C = ∂r/∂q̇, K = ∂r/∂q): the exact
// tangent, or the O(n) matrix M + diag(γh b + (γh)² c) of implicit_spring. Stiffly accurate: the
// last stage is the step's end, (q, q̇, q̈)_{n+1} = (Q_s, V_s, A_s), and the first stage of the next
// step (A_1 = q̈_n).
#include <algorithm>
#include <cmath>
#include <limits>

#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

namespace {

/// ESDIRK4(3)6L[2]SA of Kennedy & Carpenter (2003, the implicit part of ARK4(3)6L[2]SA): order 4,
/// stage order 2, L-stable, stiffly accurate (b = the last row of a); the embedded b̂ of order 3.
struct Esdirk43Tableau {
  static constexpr int s = 6;
  static constexpr double gamma = 0.25;
  static constexpr double c[s] = {0.0, 0.5, 83.0 / 250, 31.0 / 50, 17.0 / 20, 1.0};
  static constexpr double a[s][s] = {
      {0, 0, 0, 0, 0, 0},
      {0.25, 0.25, 0, 0, 0, 0},
      {8611.0 / 62500, -1743.0 / 31250, 0.25, 0, 0, 0},
      {5012029.0 / 34652500, -654441.0 / 2922500, 174375.0 / 388108, 0.25, 0, 0},
      {15267082809.0 / 155376265600, -71443401.0 / 120774400, 730878875.0 / 902184768, 2285395.0 / 8070912, 0.25,
       0},
      {82889.0 / 524892, 0, 15625.0 / 83664, 69875.0 / 102672, -2260.0 / 8211, 0.25}};
  /// b − b̂: the error estimate e = h Σ (b_i − b̂_i) [V_i, A_i], O(h⁴).
  static constexpr double e[s] = {82889.0 / 524892 - 4586570599.0 / 29645900160,
                                  0,
                                  15625.0 / 83664 - 178811875.0 / 945068544,
                                  69875.0 / 102672 - 814220225.0 / 1159782912,
                                  -2260.0 / 8211 + 3700637.0 / 11593932,
                                  0.25 - 61727.0 / 225920};
};

/// y(t0 + θh) (2 nq) by the quintic Hermite interpolant of q through q, q̇ and q̈ at both ends of
/// the step (q̇ its derivative): O(h⁶) in q and O(h⁵) in q̇ beyond the errors of the end values.
void hermite5(double theta, double h, const VecX& q0, const VecX& v0, const VecX& a0, const VecX& q1,
              const VecX& v1, const VecX& a1, VecX& y) {
  const double t = theta, t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  const int n = static_cast<int>(q0.size());
  y.resize(2 * n);
  y.head(n) = (1 - 10 * t3 + 15 * t4 - 6 * t5) * q0 + (h * (t - 6 * t3 + 8 * t4 - 3 * t5)) * v0 +
              (h * h * (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5)) * a0 + (10 * t3 - 15 * t4 + 6 * t5) * q1 +
              (h * (-4 * t3 + 7 * t4 - 3 * t5)) * v1 + (h * h * (0.5 * t3 - t4 + 0.5 * t5)) * a1;
  y.tail(n) = ((-30 * t2 + 60 * t3 - 30 * t4) / h) * q0 + (1 - 18 * t2 + 32 * t3 - 15 * t4) * v0 +
              (h * (t - 4.5 * t2 + 6 * t3 - 2.5 * t4)) * a0 + ((30 * t2 - 60 * t3 + 30 * t4) / h) * q1 +
              (-12 * t2 + 28 * t3 - 15 * t4) * v1 + (h * (1.5 * t2 - 4 * t3 + 2.5 * t4)) * a1;
}

/// The ESDIRK stepper; every work array is allocated by the constructor.
class Esdirk final : public Stepper {
  using T = Esdirk43Tableau;

 public:
  Esdirk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats)
      : sys_(sys),
        d_(sys),
        stats_(stats),
        n_(sys.nq),
        newton_tol_(o.newton_tol),
        max_it_(o.newton_max_iterations),
        spring_(o.iteration_matrix == IterationMatrix::Spring),
        q_(n_), v_(n_), a_(n_), qp_(n_), vp_(n_), ap_(n_), Q_(n_), qhat_(n_), vhat_(n_), r_(n_), dA_(n_),
        armature_(n_), V_(n_, T::s), A_(n_, T::s), y_(2 * n_), y1_(2 * n_), e_(2 * n_), dy_(2 * n_), sc_(2 * n_),
        K_(n_, n_), C_(n_, n_), M_(n_, n_), S_(n_, n_), lu_(n_) {}

  /// The initial acceleration, q̈_0 = M⁻¹ f at (t0, q0, q̇0).
  void start(double t0, const VecX& q0, const VecX& qd0) override {
    ++stats_.rhs_evaluations;
    q_ = q0, v_ = qd0, a_ = forward_dynamics(sys_, d_, t0, q0, qd0);
    y_ << q_, v_;
  }

  /// Hairer's first guess 0.01 ‖y‖/‖ẏ‖ in the error weights (1e-6 s when either is negligible).
  double initial_step(double span, const Tolerances& tol, double max_step) override {
    dy_ << v_, a_;
    sc_ = tol.atol.array() + tol.rtol.array() * y_.cwiseAbs().array();
    const double d0 = scaled_rms(y_, sc_), d1 = scaled_rms(dy_, sc_);
    const double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    return std::min({h0, max_step, span});
  }

  bool attempt(double t, double h, const Tolerances* tol, double& err) override {
    t_ = t, h_ = h, err = 0.0;
    if (n_ == 0) return true;
    if (tol) sc_ = tol->atol.array() + tol->rtol.array() * y_.cwiseAbs().array();
    if (!stages(t, h, tol)) {
      if (spring_ || jacobian_fresh_) return false;
      jacobian_valid_ = false;  // a tangent from an earlier step: once more with a fresh one
      if (!stages(t, h, tol)) return false;
    }
    if (!Q_.allFinite() || !V_.allFinite()) step_failure(t, h, "the state became NaN or inf");
    y1_ << Q_, V_.col(T::s - 1);
    if (!tol) return true;
    // e = h Σ (b_i − b̂_i) [V_i, A_i]
    e_.head(n_) = h * (V_ * Eigen::Map<const VecX>(T::e, T::s));
    e_.tail(n_) = h * (A_ * Eigen::Map<const VecX>(T::e, T::s));
    if (!spring_) filter_error(T::gamma * h);
    err = error_norm(e_, y_, y1_, tol->atol, tol->rtol);
    return true;
  }

  void accept() override {
    qp_ = q_, vp_ = v_, ap_ = a_;
    q_ = Q_, v_ = V_.col(T::s - 1), a_ = A_.col(T::s - 1);
    y_ = y1_;
    jacobian_fresh_ = false;
    if (slow_) jacobian_valid_ = false;  // Newton contracted slowly: a new tangent for the next step
  }

  const VecX& state() const override { return y_; }

  VecX dense(double t) const override {
    VecX y;
    hermite5((t - t_) / h_, h_, qp_, vp_, ap_, q_, v_, a_, y);
    return y;
  }

  /// The embedded estimate is O(h⁴); PI control (Gustafsson): h_new = h · 0.9 err^(−0.7/4) err_prev^(0.4/4).
  StepControl control() const override { return {4, 5.0, true, 1.2, 0.7, 0.4}; }

 private:
  /// Shampine's filter of the error estimate, ê = (I − γh J)⁻¹ e with J the Jacobian of y' = (q̇, q̈):
  /// the embedded method is not L-stable, so e carries the stiff modes' components at full size
  /// although the step damps them; the filter scales a mode of frequency ω by about 1/(γhω)² and
  /// leaves the accurate ones. With J = [[0, 1], [−M⁻¹K, −M⁻¹C]]:
  /// (M + γhC + (γh)²K) ê_v = M e_v − γh K e_q, ê_q = e_q + γh ê_v (S is factorised already).
  void filter_error(double gh) {
    rhs_ = M_ * e_.tail(n_) - gh * (K_ * e_.head(n_));
    e_.tail(n_) = lu_.solve(rhs_);
    e_.head(n_) += gh * e_.tail(n_);
  }

  /// The stages of the step t → t + h from (q_, v_, a_); false when a Newton iteration fails.
  bool stages(double t, double h, const Tolerances* tol) {
    const double gh = T::gamma * h;
    if (!spring_) tangent(t, gh);
    slow_ = false;
    V_.col(0) = v_, A_.col(0) = a_;
    for (int i = 1; i < T::s; ++i) {
      // v̂_i = q̇_n + h Σ_{j<i} a_ij A_j, q̂_i = q_n + h Σ_{j<i} a_ij V_j
      vhat_ = v_, qhat_ = q_;
      for (int j = 0; j < i; ++j) {
        if (T::a[i][j] == 0.0) continue;
        vhat_ += (h * T::a[i][j]) * A_.col(j);
        qhat_ += (h * T::a[i][j]) * V_.col(j);
      }
      predict(i);
      if (!newton(t + T::c[i] * h, gh, tol, i)) return false;
    }
    return true;
  }

  /// The first iterate of A_i: the line through the two stages before it, in c (the previous
  /// stage's acceleration for the first implicit stage).
  void predict(int i) {
    A_.col(i) = A_.col(i - 1);
    if (i >= 2) A_.col(i) += ((T::c[i] - T::c[i - 1]) / (T::c[i - 1] - T::c[i - 2])) * (A_.col(i - 1) - A_.col(i - 2));
  }

  /// Stage i: A_i solving r(A_i) = M(Q_i) A_i − f(Q_i, V_i, t_i) = 0 by A_i ← A_i − S⁻¹ r, with
  /// V_i = v̂ + γh A_i, Q_i = q̂ + γh V_i (left in V_.col(i), Q_). Converged when the increments of
  /// (Q_i, V_i) times η = θ/(1 − θ) (θ the contraction rate; Hairer & Wanner IV.8) fall below κ = 0.03
  /// of the error weights (adaptive), or below newton_tol (1 + |y|) (fixed steps).
  bool newton(double ti, double gh, const Tolerances* tol, int i) {
    auto A = A_.col(i);
    auto V = V_.col(i);
    double previous = 0.0;
    for (int it = 0; it < max_it_; ++it) {
      V = vhat_ + gh * A;
      Q_ = qhat_ + gh * V;
      residual(ti, i);
      correction(gh);
      ++stats_.newton_iterations;
      if (!dA_.allFinite()) return false;
      A += dA_;
      const double size = increment_size(gh, tol);
      double eta = eta_;
      if (it >= 1) {
        const double theta = size / previous;
        if (theta >= 0.99) return false;  // diverging, or too slow to finish
        if (theta > 0.2) slow_ = true;
        eta = theta / (1.0 - theta);
      }
      if (eta * size <= 1.0) {
        V = vhat_ + gh * A;
        Q_ = qhat_ + gh * V;
        eta_ = std::max(eta, 1e-3);
        return true;
      }
      previous = size;
    }
    slow_ = true;
    return false;
  }

  /// ‖(γh)² ΔA, γh ΔA‖ relative to what may be left: κ of the error weights (adaptive), or
  /// newton_tol (1 + max |y|) (fixed steps); converged when η times it is at most 1.
  /// κ = 0.03 measured on Kane's beam: 0.01 costs 10-40 % more iterations for the same error,
  /// 0.1 leaves Newton errors the step control sees (4-5× the steps).
  double increment_size(double gh, const Tolerances* tol) {
    constexpr double kappa = 0.03;
    if (tol) {
      dy_ << (gh * gh) * dA_, gh * dA_;
      return scaled_rms(dy_, sc_) / kappa;
    }
    const double size = max_abs(dA_);
    return std::max(gh * gh * size / (newton_tol_ * (1.0 + max_abs(Q_))),
                    gh * size / (newton_tol_ * (1.0 + max_abs(v_))));
  }

  /// r_ = M(Q_i) A_i − f(Q_i, V_i, t_i) at stage i's iterate: inverse dynamics, O(n) for recursive systems.
  void residual(double ti, int i) {
    set_state(sys_, d_, ti, Q_, V_.col(i));
    set_accelerations(sys_, d_, A_.col(i));
    dynamics_kinematics(sys_, d_);
    generalized_forces(sys_, d_);  // f − M A_i
    ++stats_.rhs_evaluations;
    r_ = -d_.f;
  }

  /// dA_ = −S⁻¹ r_: the factorised tangent, or the O(n) spring matrix at the iterate.
  void correction(double gh) {
    if (!spring_) {
      dA_ = -lu_.solve(r_);
      return;
    }
    // M + diag(γh b + (γh)² c): the sde springs and dampers as armature of the articulated-body algorithm
    for (int k = 0; k < n_; ++k) {
      const int i = sys_.free_coords[k];
      const Coordinate& c = sys_.coords[i];
      armature_(k) = d_.spring_scale(i) * (gh * c.damping + gh * gh * c.stiffness);
    }
    ++stats_.factorizations;
    factor_armature(sys_, d_, armature_);  // at the state residual() left in d_
    dA_ = -r_;
    solve_armature(sys_, d_, dA_, dA_);
  }

  /// The tangent at the step's start (q_n, q̇_n, q̈_n): K = ∂r/∂q, C = ∂r/∂q̇ and M, kept while
  /// Newton converges fast; S = M + γh C + (γh)² K factorised whenever γh changes.
  void tangent(double t, double gh) {
    if (!jacobian_valid_) {
      set_state(sys_, d_, t, q_, v_);
      set_accelerations(sys_, d_, a_);
      dynamics_kinematics(sys_, d_);
      auto [drdq, drdqd] = inverse_dynamics_derivatives(sys_, d_);
      K_ = drdq, C_ = drdqd;
      mass_matrix(sys_, d_);
      M_ = d_.A;
      ++stats_.jacobians;
      if (!analytic_derivatives(sys_)) stats_.rhs_evaluations += 4 * n_;  // the central differences
      jacobian_valid_ = jacobian_fresh_ = true;
      gh_ = 0.0;
    }
    if (gh == gh_) return;
    S_ = M_ + gh * C_ + (gh * gh) * K_;
    lu_.compute(S_);
    ++stats_.factorizations;
    gh_ = gh;
    // The reciprocal condition number, not the determinant, which under- or overflows for large n.
    if (!(lu_.rcond() > 1e-15))
      throw SimulationError(t, "the Newton iteration matrix M + γh C + (γh)² K is singular (step size h = " +
                                   num(gh / T::gamma) + " s)");
  }

  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  int n_;
  double newton_tol_;
  int max_it_;
  bool spring_;
  VecX q_, v_, a_;     // (nq) the current state and its acceleration
  VecX qp_, vp_, ap_;  // (nq) the same at the start of the last accepted step (dense output)
  VecX Q_, qhat_, vhat_, r_, dA_, armature_, rhs_;  // (nq) the stage being solved; the filter's right side
  MatX V_, A_;                                // (nq, s) the stages' velocities and accelerations
  VecX y_, y1_, e_, dy_, sc_;                 // (2 nq) y_n, y_{n+1}, error, increments, error weights
  MatX K_, C_, M_, S_;                        // (nq, nq) the tangent's parts and S
  Eigen::PartialPivLU<MatX> lu_;
  bool jacobian_valid_ = false, jacobian_fresh_ = false, slow_ = false;
  double gh_ = 0.0;    // γh of the factorised S
  double eta_ = 1.0;   // Newton's η of the last converged stage
  double t_ = 0.0, h_ = 1.0;  // the last attempted step
};

}  // namespace

std::unique_ptr<Stepper> make_implicit_rk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) {
  return std::make_unique<Esdirk>(sys, o, stats);
}

}  // namespace rigidfem
