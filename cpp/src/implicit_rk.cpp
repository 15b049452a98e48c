// Implicit Runge–Kutta methods of high order for the second-order system M(q) q̈ = f(q, q̇, t),
// stiffly accurate and L-stable, with embedded error estimates.
//
// Both write the stages for the unknown stage accelerations A_i, the residual of each stage
// r_i = M(Q_i) A_i − f(Q_i, V_i, t_i) by inverse dynamics (O(n)), and Newton's matrix from the
// tangent at the step's start: K = ∂r/∂q, C = ∂r/∂q̇ and M.
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
//
// The Maxwell arms' forces s (arms.hpp) are stages too: S_i = ŝ_i + γh (k V_i − S_i/τ) gives
// S_i = (ŝ_i + γh k V_i)/(1 + γh/τ) in closed form, so the stage residual holds them and Newton's matrix
// their stiffness (γh)² k/(1 + γh/τ); radau5 refuses them (its stages are coupled through them).
//
// Loops (both): each stage holds M A_i − f_i − G_iᵀλ_i = 0 and G_i A_i = γ_i (index 1) by the Schur
// complement of Newton's matrix, and each accepted step is projected onto the loops (project).
//
// Radau IIA (3 stages, order 5): all stages at once, V = q̇_n 1ᵀ + h A aᵀ, Q = q_n 1ᵀ + h V aᵀ
// (columns the stages, a the Butcher matrix), so Newton's matrix is I⊗M + h a⊗C + h² a²⊗K; with
// a = P D P⁻¹ it falls apart into one real block M + h d₁ C + (h d₁)² K and one complex block
// M + h d₂ C + (h d₂)² K (d₃ = d̄₂): the transformed real/complex form of Hairer & Wanner IV.8.
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/constraints.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/error_measure.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/newton_matrix.hpp"
#include "rigidfem/radau.hpp"
#include "rigidfem/sensitivities.hpp"
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

/// q̈(t0 + θh) of the quintic Hermite interpolant of hermite5 (a cubic in θ), into a.
void acceleration_hermite5(double t, double h, const VecX& q0, const VecX& v0, const VecX& a0, const VecX& q1,
                           const VecX& v1, const VecX& a1, Eigen::Ref<VecX> a) {
  const double t2 = t * t, t3 = t2 * t;
  a = ((-60 * t + 180 * t2 - 120 * t3) / (h * h)) * (q0 - q1) + ((-36 * t + 96 * t2 - 60 * t3) / h) * v0 +
      (1 - 9 * t + 18 * t2 - 10 * t3) * a0 + ((-24 * t + 84 * t2 - 60 * t3) / h) * v1 +
      (3 * t - 12 * t2 + 10 * t3) * a1;
}

/// What the implicit Runge–Kutta methods share: the state (q, q̇, q̈) at both ends of the last step
/// (dense output), the stage residual, the tangent at the step's start, Newton's convergence test
/// and the error weights. Every work array is allocated by the constructors.
class ImplicitRk : public Stepper {
 public:
  ImplicitRk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats)
      : sys_(sys), d_(sys), stats_(stats), n_(sys.nq), newton_tol_(o.newton_tol), max_it_(o.newton_max_iterations),
        q_(n_), v_(n_), a_(n_), qp_(n_), vp_(n_), ap_(n_), q1_(n_), v1_(n_), a1_(n_), r_(n_), y_(2 * n_),
        y1_(2 * n_), dy_(2 * n_), sc_(2 * n_), zero_(VecX::Zero(n_)), matrix_(NewtonMatrix::make(sys, o, stats)) {
    if (!o.sensitivities.empty()) sens_ = std::make_unique<SensitivityEquations>(sys, o.sensitivities);
  }

  /// The initial acceleration, q̈_0 = M⁻¹ f at (t0, q0, q̇0, s0).
  void start(double t0, const VecX& y0) override {
    ++stats_.rhs_evaluations;
    q_ = y0.head(n_), v_ = y0.segment(n_, n_), s_ = y0.segment(2 * n_, sys_.nz);
    set_arm_forces(sys_, d_, s_);
    a_ = forward_dynamics(sys_, d_, t0, q_, v_);
    lambda_ = d_.lambda;  // with loops, the multipliers of the initial state too
    y_ << q_, v_;
    ys_ = y0;
    if (sens_) {
      const int P = sens_->count(), k0 = 2 * n_ + sys_.nz;
      Sq_.resize(n_, P), Sv_.resize(n_, P);
      for (int j = 0; j < P; ++j) Sq_.col(j) = y0.segment(k0 + 2 * n_ * j, n_), Sv_.col(j) = y0.segment(k0 + 2 * n_ * j + n_, n_);
      sensitivity_accelerations(t0);
    }
    restarted();
  }

  /// Loops: (q, q̇) onto the constraint manifold at t after each accepted step (closure residual
  /// <= 1e-12), and q̈, λ by the constrained forward dynamics there (the next step's first stage).
  void project(double t) override {
    ++stats_.rhs_evaluations;
    set_arm_forces(sys_, d_, s_);
    a_ = project_and_forward_dynamics(sys_, d_, t, q_, v_, 1e-12, 10);
    lambda_ = d_.lambda;
    y_ << q_, v_;
    if (sens_) {  // onto the tangent of the loops (in sens_'s own workspace), and S̈ of the next step's first stage
      VecX S(2 * n_);  // with d_ still holding the forward dynamics at the projected state
      for (int j = 0; j < sens_->count(); ++j) {
        S << Sq_.col(j), Sv_.col(j);
        sens_->project(j, t, q_, v_, S);
        Sq_.col(j) = S.head(n_), Sv_.col(j) = S.tail(n_);
      }
      sensitivity_accelerations(t);
    }
    ys_ << y_, s_, sensitivity_blocks();
  }

  /// Hairer's first guess 0.01 ‖y‖/‖ẏ‖ in the error weights (1e-6 s when either is negligible).
  double initial_step(double span, const Tolerances& tol, double max_step) override {
    if (n_ == 0) return std::min(span, max_step);  // nothing moves
    dy_ << v_, a_;
    sc_ = tol.atol.array() + tol.rtol.array() * y_.cwiseAbs().array();
    const double d0 = scaled_rms(y_, sc_), d1 = scaled_rms(dy_, sc_);
    // 1e-6 s where either is negligible, or where a component of zero weight moves (d1 infinite)
    const double h0 = (d0 < 1e-5 || d1 < 1e-5 || !std::isfinite(d1)) ? 1e-6 : 0.01 * d0 / d1;
    return std::min({h0, max_step, span});
  }

  /// The stages into (q1_, v1_, a1_), once more with a fresh tangent if Newton failed with an old
  /// one; err from the method's estimate.
  bool attempt(double t, double h, const Tolerances* asked, double& err) override {
    t_ = t, h_ = h, err = 0.0;
    if (n_ == 0) return true;
    const Tolerances* tol = asked ? &controlled(*asked) : nullptr;
    // Newton's weights: the stricter of the tolerances asked and radau5's rtol' (controlled), which for rtol <
    // 1e-3 is looser than the error the step itself is held to on outputs. What Newton leaves adds up over the
    // steps (systematically, one sign) where an order-5 step's own error is far below its estimate: Bricard
    // linkage over 10 s at rtol 1e-8, q error 1.4e-4 on rtol' weights, 7.5e-6 on rtol's (1.7 times the
    // iterations); the whippy strip's tip error is the same either way, at 20-28 % more iterations.
    if (tol) sc_ = asked->atol.cwiseMin(tol->atol).array() +
                   asked->rtol.cwiseMin(tol->rtol).array() * y_.cwiseAbs().array();
    // η from the last step, raised towards 1 (Hairer's max(η, ε)^0.8): a contraction rate measured long
    // ago, perhaps with another tangent, is trusted less and less, so a second iteration measures it anew.
    eta_ = std::pow(std::max(eta_, std::numeric_limits<double>::epsilon()), 0.8);
    sensitivities_failed_ = false;
    if (!solve(t, h, tol)) {
      bool solved = false;
      if (uses_tangent() && !jacobian_fresh_) {
        jacobian_valid_ = false;
        solved = solve(t, h, tol);
      }
      if (!solved) {
        // a fixed step cannot be shortened: say which equations failed (adaptive: the step is retried shorter)
        if (!asked && sensitivities_failed_)
          step_failure(t, h, "the sensitivities' corrections did not converge with the Newton matrix (with a fresh "
                             "tangent too); reduce dt");
        return false;
      }
    }
    if (!q1_.allFinite() || !v1_.allFinite() || !a1_.allFinite()) step_failure(t, h, "the state became NaN or inf");
    y1_ << q1_, v1_;
    if (tol) err = estimate(t, h, *tol);
    return true;
  }

  void accept() override {
    qp_ = q_, vp_ = v_, ap_ = a_, sp_ = s_;
    q_ = q1_, v_ = v1_, a_ = a1_, s_ = s1_;
    y_ = y1_;
    if (sens_) {
      Sqp_ = Sq_, Svp_ = Sv_, Sap_ = Sa_;
      Sq_ = Sq1_, Sv_ = Sv1_, Sa_ = Sa1_;
    }
    ys_ << y_, s_, sensitivity_blocks();
    jacobian_fresh_ = false;
    // a new tangent for the next step where Newton contracted slowly (progress), and after 5 `served_` steps
    // whatever θ: the error estimate is filtered through it ((I − γhJ)⁻¹, filter), and a stale one can hold the
    // step down while Newton converges at once. A block creeping on an incline under regularised friction
    // (v_ε = 1e-5 m/s, radau5 at rtol 1e-9 and 1e-10) took 69,562 and 43,445 steps with its start's tangent,
    // 138 and 143 with one renewed every 100 steps.
    if (slow_ || ++tangent_age_ >= 5 * served_) jacobian_valid_ = false;
    accepted();
  }

  const VecX& state() const override { return ys_; }

  /// [q, q̇] by the quintic Hermite interpolant, s by the cubic one through s and ṡ at both ends.
  VecX dense(double t) const override {
    VecX y, out(2 * n_ + sys_.nz), sdp(sys_.nz), sd(sys_.nz);
    hermite5((t - t_) / h_, h_, qp_, vp_, ap_, q_, v_, a_, y);
    arm_rates(sys_, vp_, sp_, sdp);
    arm_rates(sys_, v_, s_, sd);
    out << y, hermite((t - t_) / h_, h_, sp_, sdp, s_, sd);
    if (sens_) {  // each [S_q, S_q̇] by the same quintic Hermite rule
      out.conservativeResize(2 * n_ + sys_.nz + 2 * n_ * sens_->count());
      for (int j = 0; j < sens_->count(); ++j) {
        hermite5((t - t_) / h_, h_, Sqp_.col(j), Svp_.col(j), Sap_.col(j), Sq_.col(j), Sv_.col(j), Sa_.col(j), y);
        out.segment(2 * n_ + sys_.nz + 2 * n_ * j, 2 * n_) = y;
      }
    }
    return out;
  }

  /// Both estimates are O(h⁴); PI control (Gustafsson): h_new = h · 0.9 err^(−0.7/4) err_prev^(0.4/4),
  /// h kept for gains below 1.2 (the factorisations with it).
  StepControl control() const override { return {4, 5.0, true, 1.2, 0.7, 0.4}; }

 protected:
  /// The step t → t + h from (q_, v_, a_) into (q1_, v1_, a1_); false when Newton fails.
  virtual bool solve(double t, double h, const Tolerances* tol) = 0;
  /// The scaled norm of the step's error estimate.
  virtual double estimate(double t, double h, const Tolerances& tol) = 0;
  virtual bool uses_tangent() const { return true; }
  /// The tolerances the estimate is held to, for the tolerances asked.
  virtual const Tolerances& controlled(const Tolerances& asked) { return asked; }
  virtual void accepted() {}
  /// A new start (the run's, or a step taken again after an event): no last step to predict from.
  virtual void restarted() {}

  /// [S_q, S_q̇] of each parameter in turn (2 nq P; empty without sensitivities).
  VecX sensitivity_blocks() const {
    if (!sens_) return VecX();
    VecX S(2 * n_ * sens_->count());
    for (int j = 0; j < sens_->count(); ++j) S.segment(2 * n_ * j, 2 * n_) << Sq_.col(j), Sv_.col(j);
    return S;
  }

  /// Sa_ = S̈ of each parameter at (t, q_, v_) from the differentiated forward dynamics, d_ holding the forward
  /// dynamics there (the step's first stage: q̈_n).
  void sensitivity_accelerations(double t) {
    const int P = sens_->count();
    VecX S = sensitivity_blocks(), Sd(2 * n_ * P);
    sens_->rates(d_, t, q_, v_, S, Sd);
    Sa_.resize(n_, P);
    for (int j = 0; j < P; ++j) Sa_.col(j) = Sd.segment(2 * n_ * j + n_, n_);
  }

  /// The staggered direct method at one stage: δA solving the stage's differentiated equations
  ///   R(δA) = K δQ + C δV + M δA − ∂(Gᵀλ)/∂q δQ − Gᵀδλ + ∂r/∂p = 0,  δV = δv̂ + γh δA, δQ = δq̂ + γh δV
  /// (loops also G δA = D(γ − G A)[δQ, δV]) by corrections with the stage's Newton matrix (`correct`: −S⁻¹R
  /// with the loops' Schur step), until they move δQ and δV by less than 1e-9 of them or reach the
  /// differences' noise (1e-6 of δA) after a fresh tangent at the stage (`refresh`, once), or fall to `floor`, the
  /// round-off of ∂r/∂p's difference (a sensitivity that is exactly zero converges to it, where no relative test
  /// passes). dA holds the first iterate on entry; dV, dQ, dl are the stage's on return.
  template <class Correct, class Refresh>
  bool sensitivity_stage(int j, double ti, double gh, const VecX& Q, const VecX& V, const VecX& A, const VecX& lambda,
                         const VecX& dqhat, const VecX& dvhat, Eigen::Ref<VecX> dA, VecX& dV, VecX& dQ, VecX& dl,
                         double floor, Correct&& correct, Refresh&& refresh) {
    double previous = 0.0, free = 0.0;  // free: the largest correction before the loops' part
    bool refreshed = false;
    dl = VecX::Zero(sys_.nl);
    for (int it = 0;; ++it) {
      interruption_point();
      dV = dvhat + gh * dA;
      dQ = dqhat + gh * dV;
      if (it == std::max(20, max_it_)) return false;  // the step again with a fresh tangent, or a shorter one
      const VecX R = sens_->residual_derivative(j, ti, Q, V, A, lambda, dQ, dV, dA, dl);
      VecX dx(n_), dlambda;
      free = std::max(free, correct(R, dQ, dV, dA, dx, dlambda));
      if (sys_.nl > 0) dl += dlambda;
      dA += dx;
      if (!dA.allFinite()) step_failure(t_, h_, "the sensitivities became NaN or inf");
      // converged: the change below 1e-9 of δQ and δV, or below 1e-12 of what the loops took out of it (a
      // sensitivity they hold at zero, as a mechanism's the drives move alone by its masses, converges to 0,
      // where no relative test passes)
      const double change = max_abs(dx);
      if ((gh * gh * change <= 1e-9 * max_abs(dQ) && gh * change <= 1e-9 * max_abs(dV)) ||
          (sys_.nl > 0 && change <= 1e-12 * free) || change <= floor)
        break;
      if (it > 0 && change > 0.5 * previous) {
        if (change <= 1e-6 * max_abs(VecX(dA))) break;
        if (!refreshed) refreshed = true, refresh();
      }
      previous = change;
    }
    dV = dvhat + gh * dA;
    dQ = dqhat + gh * dV;
    return true;
  }

  /// r_ = M(Q) A − f(Q, V, t) at a stage: inverse dynamics, O(n) for recursive systems.
  void residual(double t, const Eigen::Ref<const VecX>& Q, const Eigen::Ref<const VecX>& V,
                const Eigen::Ref<const VecX>& A) {
    set_state(sys_, d_, t, Q, V);
    set_accelerations(sys_, d_, A);
    dynamics_kinematics(sys_, d_);
    generalized_forces(sys_, d_);  // f − M A
    ++stats_.rhs_evaluations;
    r_ = -d_.f;
  }

  /// The tangent at the step's start (q_n, q̇_n, q̈_n) unless the kept one is valid: K = ∂r/∂q,
  /// C = ∂r/∂q̇ and M (newton_matrix.hpp). Returns whether it is new (the factorisations must follow).
  bool tangent(double t) {
    if (jacobian_valid_) return false;
    matrix_->linearize(t, q_, v_, a_, s_);
    jacobian_valid_ = jacobian_fresh_ = true;
    tangent_age_ = 0;
    return true;
  }

  /// Size of the increments (Δq, Δq̇) of one stage against what may be left: κ = 0.03 of the state's
  /// error weights atol + rtol |y| (adaptive), newton_tol (1 + max |y|) (fixed steps). κ measured on
  /// Kane's beam: 0.01 costs 10-40 % more iterations for the same error, 0.1 leaves Newton errors the
  /// step control sees (4-5× the steps). On the state's weights even when the error is measured on
  /// outputs: measured in the bodies' displacements instead, the torsion of a thin beam (which moves
  /// little material) was left unconverged, and the stiff 3D cantilever's tip error grew from 3.6 to
  /// 142 times the tolerance at rtol = 1e-7 (and its step size collapsed at rtol >= 3e-3).
  template <class Dq, class Dv>
  double increment_size(const Dq& dq, const Dv& dv, const Tolerances* tol) {
    constexpr double kappa = 0.03;
    if (tol) {
      dy_ << dq, dv;
      return scaled_rms(dy_, sc_) / kappa;
    }
    return std::max(dq.cwiseAbs().maxCoeff() / (newton_tol_ * (1.0 + max_abs(q_))),
                    dv.cwiseAbs().maxCoeff() / (newton_tol_ * (1.0 + max_abs(v_))));
  }

  /// out = (I − gJ)⁻¹ x (2 nq), J = [[0, I], [−M⁻¹K, −M⁻¹C]] the Jacobian of y' = (q̇, q̈) at the tangent:
  /// (M + gC + g²K) out_v = M x_v − g K x_q, out_q = x_q + g out_v, with the real block M + gC + g²K factorised.
  void filter(double g, const VecX& x, VecX& out) {
    xq_ = -g * x.head(n_), xv_ = x.tail(n_);
    matrix_->derivative(xq_, zero_, xv_, rhs_);
    matrix_->solve(rhs_, xv_);
    out.resize(2 * n_);
    out.tail(n_) = xv_;
    out.head(n_) = x.head(n_) + g * out.tail(n_);
  }

  /// The norm on the outputs of a filtered estimate ê = (I − gJ)⁻¹ e, with the oscillations that a step
  /// neither resolves nor removes counted κ times: max(‖ê‖, κ ‖4 gJ (I − gJ)⁻² ê‖). The band-pass
  /// 4 gJ (I − gJ)⁻² = 4 ((I − gJ)⁻¹ − I)(I − gJ)⁻¹ has the gain 4 gω/(1 + (gω)²) on a mode of
  /// frequency ω: 2 at gω = 1, falling like gω below and 1/(gω) above. Such a mode (hω ≈ 1-10) loses a
  /// fraction of its amplitude or phase in every step, so its error adds up over the steps that follow:
  /// κ = (t_end − t0)/(100 h), the run's length in steps of this size over 100, between 1 and 20. A
  /// resolved mode (hω ≪ 1) and one removed in a step (hω ≫ 1) keep their estimate. Measured with
  /// `python -m benchmarks accuracy` (released strips m = 16-64, tapes, cantilevers, the stiff 3D
  /// cantilever, Kane's beam, the whippy strip; the default asked for a largest tip error of 1e-4 and
  /// 1e-6 m): without the band-pass the tip error reached 12 times the tolerance (the estimate, which
  /// sees one step, let modes of 10-20 times the tolerance through); with κ = 10 at every step
  /// 0.05-1.17 times, over-delivering 5-20 fold on short runs (2.0-4.3 times the cheapest run's time);
  /// with κ = run/(200 h) up to 1.26 times; with κ as here 0.07-0.70 times.
  double output_error(double g, const VecX& e_hat, const Tolerances& tol, double h) {
    constexpr double steps_per_count = 100.0, most = 20.0;
    const double kappa = std::clamp(tol.span / (steps_per_count * h), 1.0, most);
    filter(g, e_hat, band_);
    filter(g, band_, band2_);
    band2_ = 4.0 * (band2_ - band_);
    return std::max(tol.norm(e_hat, y_, y1_, h), kappa * tol.norm(band2_, y_, y1_, h));
  }

  enum class Newton { Continue, Converged, Failed };
  /// Newton's test after iteration `it` with the increment's size (increment_size): converged when
  /// η size <= 1, η = θ/(1 − θ) from the contraction rate θ (the sum of the remaining increments of
  /// a contraction; Hairer & Wanner IV.8), the last η on the first iteration; failed when
  /// θ >= 0.99 or the iterations run out. A slow contraction asks for a fresh tangent: θ > 0.2 always, θ > mild_
  /// (0.05; radau9 0.02) once the tangent has served `served_` steps, what it costs in stage residuals. One that
  /// serves long pays for itself in iterations saved: strip m = 16, radau5 rtol 2e-6, 9 tangents instead of 1, 2.02 Newton
  /// iterations a step instead of 2.26, 10 % less time (with renewal by age too: 22 tangents, 1.98). One that
  /// serves a few steps does not: on the crane (tangents kept 2-8 steps) θ > 0.05 alone took 33 tangents
  /// instead of 13, and 33 % more time.
  Newton progress(int it, double size, double& previous) {
    constexpr double slow = 0.2;
    double eta = eta_;
    if (it >= 1) {
      const double theta = size / previous;
      if (!(theta < 0.99)) return Newton::Failed;
      if (theta > slow || (theta > mild_ && tangent_age_ >= served_)) slow_ = true;
      eta = theta / (1.0 - theta);
    }
    previous = size;
    if (eta * size <= 1.0) {
      eta_ = eta;
      return Newton::Converged;
    }
    if (it + 1 >= max_it_) {
      slow_ = true;
      return Newton::Failed;
    }
    return Newton::Continue;
  }

  /// Whether a step h needs Newton's matrix factorised anew, the last one factorised for `factored`: not where
  /// they differ by round-off, as fixed steps to the grid t0 + k·dt do (t1 − t): gauss6 at h = 1 ms on the whippy
  /// strip factorised at every other of its 2,000 steps.
  static bool other_step(double h, double factored) { return std::abs(h - factored) > 1e-10 * h; }

  /// The singular-matrix failure of a factorisation by its reciprocal condition number (not the
  /// determinant, which under- or overflows for large n).
  void check_regular(double rcond, double t, double h, const char* matrix) const {
    if (!(rcond > 1e-15))
      throw SimulationError(t, std::string("the Newton iteration matrix ") + matrix + " is singular (step size h = " +
                                   num(h) + " s)");
  }

  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  int n_;
  double newton_tol_;
  int max_it_;
  VecX q_, v_, a_;     // (nq) the current state and its acceleration
  VecX qp_, vp_, ap_;  // (nq) the same at the start of the last accepted step (dense output)
  VecX q1_, v1_, a1_;  // (nq) the attempted step's end
  VecX r_;             // (nq) the residual of the last stage evaluated
  VecX y_, y1_, dy_, sc_;  // (2 nq) y_n, y_{n+1}, scratch, error weights atol + rtol |y_n|
  VecX s_, sp_, s1_;       // (nz) the Maxwell arms' forces: now, at the last step's start, the attempted step's end
  VecX ys_;                // (2 nq + nz) the state [q, q̇, s]
  VecX lambda_;            // (nl) the loops' multipliers: now (esdirk43: at the stage being solved)
  VecX rhs_, band_, band2_;  // (nq) a filter's right-hand side; (2 nq) the band-pass of output_error
  VecX xq_, xv_, zero_;      // (nq) a filter's directions
  std::unique_ptr<NewtonMatrix> matrix_;  // the tangent's Newton matrix (dense or Krylov)
  std::unique_ptr<SensitivityEquations> sens_;  // forward sensitivities, or null
  MatX Sq_, Sv_, Sa_, Sqp_, Svp_, Sap_, Sq1_, Sv1_, Sa1_;  // (nq, P) their q, q̇, q̈: now, at the last step's start, its end
  bool jacobian_valid_ = false, jacobian_fresh_ = false, slow_ = false;
  int tangent_age_ = 0;  // steps accepted since the tangent was taken
  // Steps a tangent serves before a mild θ renews it: at least 20, 1.5 nq for large nq. Set to the tangent's cost in
  // stage residuals while its columns cost O(n) each (24, 48 and 95 residuals on the whippy strip at nq = 16, 32 and
  // 64, 22 on the crane at nq = 21). With the tangent's inertial part summed over subtrees (derivatives.cpp) it
  // costs 6.0, 7.3, 10 and 9.8 residuals, and served = 3, 5, 10 or 20 gave the same times within 4.5 % on the crane
  // (rtol 1e-4, 3e-4) and the strip (m = 16 at rtol 2e-6 and 1e-6, m = 64 at 2e-4 and 2e-6) but for 3 at m = 64
  // and rtol 2e-6 (8 % slower): the rule stayed.
  const int served_ = std::max(20, 3 * n_ / 2);
  /// progress: the contraction rate above which a tangent that has served `served_` steps is renewed.
  double mild_ = 0.05;
  bool sensitivities_failed_ = false;  // the last solve's sensitivities did not converge (its state did)
  double eta_ = 1.0;          // Newton's η of the last converged stage
  double t_ = 0.0, h_ = 1.0;  // the last attempted step
};

/// ESDIRK4(3)6L[2]SA, stage by stage.
class Esdirk final : public ImplicitRk {
  using T = Esdirk43Tableau;

 public:
  Esdirk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats)
      : ImplicitRk(sys, o, stats), spring_(o.iteration_matrix == IterationMatrix::Spring), Q_(n_), qhat_(n_),
        vhat_(n_), dA_(n_), armature_(n_), V_(n_, T::s), A_(n_, T::s), Sd_(sys.nz, T::s),
        shat_(sys.nz), S_arm_(sys.nz), e_(2 * n_) {}

 private:
  // The estimate is filtered (Shampine), ê = (I − γh J)⁻¹ e with J the Jacobian of y' = (q̇, q̈) (filter):
  // the embedded method is not L-stable, so e carries the stiff modes' components at full size although
  // the step damps them; the filter scales a mode of frequency ω by about 1/(γhω) and leaves the accurate
  // ones. It also hides most of what the step loses of an oscillation it damps (measured on y'' = −ω²y:
  // the filtered estimate 0.03-0.1 of the step's error at hω = 3-10, against radau5's 0.7-3), so on
  // outputs esdirk43 resolves fewer modes than radau5 at the same tolerance.

  bool uses_tangent() const override { return !spring_; }

  bool solve(double t, double h, const Tolerances* tol) override {
    const double gh = T::gamma * h;
    if (!spring_ && (tangent(t) || other_step(gh, gh_))) factor(t, gh);
    slow_ = false;
    V_.col(0) = v_, A_.col(0) = a_;
    if (sys_.nl > 0) Lam_.resize(sys_.nl, T::s), Lam_.col(0) = lambda_;
    arm_rates(sys_, v_, s_, Sd_.col(0));
    for (int i = 1; i < T::s; ++i) {
      // v̂_i = q̇_n + h Σ_{j<i} a_ij A_j, q̂_i = q_n + h Σ_{j<i} a_ij V_j
      vhat_ = v_, qhat_ = q_;
      for (int j = 0; j < i; ++j) {
        if (T::a[i][j] == 0.0) continue;
        vhat_ += (h * T::a[i][j]) * A_.col(j);
        qhat_ += (h * T::a[i][j]) * V_.col(j);
      }
      // ŝ_i = s_n + h Σ_{j<i} a_ij Ṡ_j
      shat_ = s_;
      for (int j = 0; j < i; ++j)
        if (T::a[i][j] != 0.0) shat_ += (h * T::a[i][j]) * Sd_.col(j);
      predict(i);
      if (!newton(t + T::c[i] * h, gh, tol, i)) return false;
    }
    q1_ = Q_, v1_ = V_.col(T::s - 1), a1_ = A_.col(T::s - 1), s1_ = S_arm_;
    sensitivities_failed_ = sens_ && !stage_sensitivities(t, h);  // as Newton's failure: the step retried
    return !sensitivities_failed_;
  }

  /// The sensitivities' stages (the staggered direct method, sensitivity_stage) after the state's have
  /// converged: δv̂_i = δq̇_n + h Σ_{k<i} a_ik δA_k, δq̂_i = δq_n + h Σ_{k<i} a_ik δV_k; the last stage is the
  /// step's end. False when a stage's corrections do not converge (the step is then retried as after
  /// Newton's failure: with a fresh tangent, then shorter).
  bool stage_sensitivities(double t, double h) {
    const double gh = T::gamma * h;
    const int P = sens_->count();
    Sq1_.resize(n_, P), Sv1_.resize(n_, P), Sa1_.resize(n_, P);
    MatX dV(n_, T::s), dA(n_, T::s);
    VecX qhat(n_), dqhat(n_), dvhat(n_), Q(n_), dVi, dQi, dl;
    bool tangent_here = !spring_;  // a refreshed stage tangent replaces the spring matrix
    // the corrections' round-off as radau5's (stage_sensitivities there): 64 ε S⁻¹|f| per unit of 1/h_p, with the
    // tangent's matrix (none with the spring matrix: there only the relative tests stop them)
    double round_off = 0.0;
    if (tangent_here) {
      VecX noise(n_);
      matrix_->solve(sens_->force_sizes(t + h, q1_, v1_), noise);
      round_off = 64.0 * std::numeric_limits<double>::epsilon() * max_abs(noise);
    }
    for (int j = 0; j < P; ++j) {
      const double floor = round_off * sens_->difference_noise(j);
      dV.col(0) = Sv_.col(j), dA.col(0) = Sa_.col(j);
      for (int i = 1; i < T::s; ++i) {
        qhat = q_, dqhat = Sq_.col(j), dvhat = Sv_.col(j);
        for (int k = 0; k < i; ++k) {
          if (T::a[i][k] == 0.0) continue;
          qhat += (h * T::a[i][k]) * V_.col(k);
          dvhat += (h * T::a[i][k]) * dA.col(k);
          dqhat += (h * T::a[i][k]) * dV.col(k);
        }
        Q = qhat + gh * V_.col(i);
        const double ti = t + T::c[i] * h;
        const VecX Vi = V_.col(i), Ai = A_.col(i), li = sys_.nl ? VecX(Lam_.col(i)) : VecX();
        dA.col(i) = dA.col(i - 1);
        // −S⁻¹R and the loops' Schur step into dx; returns |S⁻¹R| before the loops' step
        auto correct = [&](const VecX& R, const VecX& dq, const VecX& dv, const VecX& a, VecX& dx,
                           VecX& dlambda) -> double {
          if (tangent_here) {
            matrix_->solve(R, dx);
          } else {
            set_state(sys_, d_, ti, Q, Vi);  // the spring matrix at the stage
            set_accelerations(sys_, d_, Ai);
            dynamics_kinematics(sys_, d_);
            spring_armature(sys_, d_, gh, gh * gh, armature_);
            factor_armature(sys_, d_, armature_);
            solve_armature(sys_, d_, R, dx);
          }
          dx = -dx;
          const double free = max_abs(dx);
          if (sys_.nl == 0) return free;
          loop_equations(sys_, d_, ti, Q, Vi);
          const MatX G = free_jacobian(sys_, d_);
          const MatX Y = tangent_here ? matrix_->solve(MatX(G.transpose())) : solve_armature(sys_, d_, G.transpose());
          const VecX c = sens_->acceleration_constraint_derivative(j, ti, Q, Vi, Ai, dq, dv);
          dlambda = least_norm(G * Y, c - G * (a + dx));
          dx += Y * dlambda;
          return free;
        };
        auto refresh = [&] {
          matrix_->linearize(ti, Q, Vi, Ai, s_);
          factor(ti, gh);
          jacobian_valid_ = false;  // the next step linearises at its own start again
          tangent_here = true;
        };
        if (!sensitivity_stage(j, ti, gh, Q, Vi, Ai, li, dqhat, dvhat, dA.col(i), dVi, dQi, dl, floor, correct,
                               refresh))
          return false;
        dV.col(i) = dVi;
      }
      Sq1_.col(j) = dQi, Sv1_.col(j) = dV.col(T::s - 1), Sa1_.col(j) = dA.col(T::s - 1);
    }
    return true;
  }

  /// The stage's arm forces S_i = (ŝ_i + γh k V_i)/(1 + γh/τ) into S_arm_ and d_, and (rates) Ṡ_i.
  void stage_arms(double gh, const Eigen::Ref<const VecX>& V, int i, bool rates) {
    if (sys_.nz == 0) return;
    S_arm_.resize(sys_.nz);
    for (int j = 0; j < sys_.nz; ++j) {
      const Arm& a = sys_.arms[j];
      S_arm_(j) = (shat_(j) + gh * a.stiffness * V(a.q)) / (1.0 + gh / a.tau);
    }
    set_arm_forces(sys_, d_, S_arm_);
    if (rates) arm_rates(sys_, V, S_arm_, Sd_.col(i));
  }

  /// (γh)² Σ k/(1 + γh/τ) on each coordinate with arms: their part of ∂r/∂A_i.
  void arm_matrix(double gh) {
    arm_diag_.setZero(n_);
    for (const Arm& a : sys_.arms) arm_diag_(a.q) += gh * gh * a.stiffness / (1.0 + gh / a.tau);
  }

  /// e = h Σ (b_i − b̂_i) [V_i, A_i], filtered with the tangent (ê, above) and on outputs output_error's.
  double estimate(double, double h, const Tolerances& tol) override {
    const Eigen::Map<const VecX> e(T::e, T::s);
    e_.head(n_).noalias() = h * (V_ * e);
    e_.tail(n_).noalias() = h * (A_ * e);
    if (spring_) return tol.norm(e_, y_, y1_, h);  // no tangent to filter with
    filter(T::gamma * h, e_, e_hat_);
    return tol.measure ? output_error(T::gamma * h, e_hat_, tol, h) : tol.norm(e_hat_, y_, y1_, h);
  }

  /// The first iterate of A_i: for the first implicit stage, the last step's interpolant continued
  /// (q̈_n on the first step); then the line through the two stages before it, in c. (Continuing the
  /// last step for every stage measured worse on Kane's beam, +20 % Newton iterations; for the
  /// first stage only, 8-18 % fewer than q̈_n.)
  void predict(int i) {
    if (i == 1 && have_previous_) {
      acceleration_hermite5(1.0 + T::c[i] * h_ / h_previous_, h_previous_, qp_, vp_, ap_, q_, v_, a_, A_.col(i));
      return;
    }
    A_.col(i) = A_.col(i - 1);
    if (i >= 2) A_.col(i) += ((T::c[i] - T::c[i - 1]) / (T::c[i - 1] - T::c[i - 2])) * (A_.col(i - 1) - A_.col(i - 2));
  }

  void accepted() override {
    h_previous_ = h_;
    have_previous_ = true;
  }
  void restarted() override { have_previous_ = false; }

  /// Stage i: A_i solving r(A_i) = M(Q_i) A_i − f(Q_i, V_i, t_i) = 0 by A_i ← A_i − S⁻¹ r, with
  /// V_i = v̂ + γh A_i, Q_i = q̂ + γh V_i (left in V_.col(i), Q_).
  bool newton(double ti, double gh, const Tolerances* tol, int i) {
    auto A = A_.col(i);
    auto V = V_.col(i);
    double previous = 0.0;
    for (int it = 0;; ++it) {
      interruption_point();
      V = vhat_ + gh * A;
      Q_ = qhat_ + gh * V;
      stage_arms(gh, V, i, false);
      residual(ti, Q_, V, A);
      if (sys_.nl > 0) G_ = free_jacobian(sys_, d_), r_.noalias() -= G_.transpose() * lambda_;
      correction(gh);
      if (sys_.nl > 0) close_loops_correction();
      ++stats_.newton_iterations;
      if (!dA_.allFinite()) return false;
      A += dA_;
      const Newton state = progress(it, increment_size((gh * gh) * dA_, gh * dA_, tol), previous);
      if (state == Newton::Failed) return false;
      if (state == Newton::Converged) break;
    }
    V = vhat_ + gh * A;
    Q_ = qhat_ + gh * V;
    stage_arms(gh, V, i, true);
    if (sys_.nl > 0) Lam_.col(i) = lambda_;
    return true;
  }

  /// Loops, index 1 at each stage: r = M A − f − Gᵀλ and G A = γ, whose Newton step
  /// [S −Gᵀ; G 0] [ΔA; Δλ] = −[r; G A − γ] is taken by its Schur complement: dA_ = −S⁻¹ r on entry,
  /// Y = S⁻¹ Gᵀ by nl solves with the iteration matrix, (G Y) Δλ = (γ − G A) − G dA_ (d.gamma holds
  /// γ − G A when d.qdda holds A), then dA_ += Y Δλ and λ += Δλ. The state is projected onto the
  /// loops after each step (project).
  void close_loops_correction() {
    const MatX Y = spring_ ? solve_armature(sys_, d_, G_.transpose()) : matrix_->solve(MatX(G_.transpose()));
    const VecX dl = least_norm(G_ * Y, d_.gamma - G_ * dA_);
    dA_ += Y * dl;
    lambda_ += dl;
  }

  /// dA_ = −S⁻¹ r_: the factorised tangent, or the O(n) spring matrix at the iterate.
  void correction(double gh) {
    if (!spring_) {
      matrix_->solve(r_, dA_);
      dA_ = -dA_;
      return;
    }
    // M + diag(γh b + (γh)² c): the sde springs and dampers as armature of the articulated-body algorithm
    spring_armature(sys_, d_, gh, gh * gh, armature_);
    if (sys_.nz > 0) arm_matrix(gh), armature_ += arm_diag_;
    ++stats_.factorizations;
    factor_armature(sys_, d_, armature_);  // at the state residual() left in d_
    dA_ = -r_;
    solve_armature(sys_, d_, dA_, dA_);
  }

  /// S = M + γh C + (γh)² K (+ the arms' diagonal).
  void factor(double t, double gh) {
    if (sys_.nz > 0) arm_matrix(gh);
    const double rcond = matrix_->factor(gh, gh * gh, sys_.nz > 0 ? arm_diag_ : VecX());
    gh_ = gh;
    check_regular(rcond, t, gh / T::gamma, "M + γh C + (γh)² K");
  }

  bool spring_;
  VecX Q_, qhat_, vhat_, dA_, armature_;  // (nq) the stage being solved
  MatX V_, A_;                            // (nq, s) the stages' velocities and accelerations
  MatX Sd_;                               // (nz, s) the stages' arm rates Ṡ_i
  VecX shat_, S_arm_, arm_diag_;          // (nz) ŝ_i and S_i of the stage being solved; (nq) their matrix part
  VecX e_, e_hat_;                        // (2 nq) the error estimate, filtered
  double gh_ = 0.0;  // γh of the factorised S
  double h_previous_ = 1.0;  // the last accepted step
  bool have_previous_ = false;
  MatX G_;  // (nl, nq) the loops' Jacobian at the iterate
  MatX Lam_;  // (nl, s) the stages' multipliers
};

/// Radau IIA of order 5 (Ehle; Hairer & Wanner IV.5, IV.8): c = ((4 − √6)/10, (4 + √6)/10, 1),
/// stiffly accurate, L-stable. Its error estimate (Hairer & Wanner IV.8, (8.19)–(8.20)), of order 3,
/// is filtered through (I − h d₁ J)⁻¹. Radau IIA of order 9 (5 stages; Hairer & Wanner 1999) the same with its
/// estimate of order 5.
/// The collocation methods of S stages: Radau IIA (radau5, radau9: adaptive, the step ends at its last stage) and
/// Gauss–Legendre (gauss6: fixed steps, the step ends at y_n + h Σ b_i f(Y_i)).
template <int S>
class Collocation final : public ImplicitRk, public RadauAccess {
  using cplx = std::complex<double>;
  static constexpr int pairs = (S - 1) / 2;  // the complex pairs of a's eigenvalues, one complex block each

 public:
  Collocation(const System& sys, const IntegratorOptions& o, IntegratorStats& stats, const CollocationTableau<S>& tab)
      : ImplicitRk(sys, o, stats), tab_(tab), A_(n_, S), V_(n_, S), Q_(n_, S), R_(n_, S), D_(n_, S), dV_(n_, S),
        dQ_(n_, S), Aprev_(n_, S), extrapolated_(n_, S), x_(n_), xs_(n_), b1_(n_), b2_(n_), qx_(n_), vx_(n_), L_(sys.nl, S),
        Cres_(sys.nl, S), W_(S * sys.nl, S * sys.nl), w_(S * sys.nl), E_(n_, S), Z_(n_, S) {
    for (int k = 0; k < pairs; ++k) z_[k].resize(n_), zs_[k].resize(n_), zr_[k].resize(n_), zi_[k].resize(n_);
    // gauss6: Newton to 1e-4 newton_tol (symmetric_tol), or newton_tol where it stops contracting or runs out of
    // iterations. A symmetric method keeps a conservative system's energy only with its equations solved well
    // below its step's error: Newton's leftovers have one sign and add up over the steps. The double pendulum at
    // h = 10 ms over 500 s: its energy drifted by 2.1e-6 J with the increments held to 1e-10 (1 + |y|), by 2e-8 J
    // at 1e-12; the Bricard linkage at h = 10 ms over 200 s: 8.2e-7 J at 1e-12, 1.2e-8 J at 1e-14.
    if (!tab_.stiffly_accurate) newton_tol_ *= symmetric_tol;
    // radau9's further iteration costs 5 stage residuals where the tangent costs what radau5's does: renewed from
    // θ > 0.02, it took 2.06 Newton iterations a step instead of 2.24 on the whippy strip (m = 16, rtol 1e-5),
    // 10 % fewer residuals for 23 tangents instead of 15 (0.05 measured the same for radau5: 1.98 and 1.97).
    if (S == 5) mild_ = 0.02;
    check_pairs();
    dense_polynomials();
  }

  /// radau9: q̇ by its collocation polynomial, q̇(t_n + θh) = q̇_n + h Σ_k A_k L1_k(θ), and q by its integral,
  /// q_n + θh q̇_n + h² Σ_k A_k L2_k(θ) (L1_k = ∫₀^θ l_k, L2_k = ∫₀^θ L1_k, l_k Lagrange's basis on c), which
  /// end at the step's (q, q̇)_n+1 (the Radau quadrature integrates L1_k exactly); with loops plus θ times what the
  /// projection moved the end by, so that they end at the projected state. radau5 and gauss6: the quintic Hermite
  /// interpolant (ImplicitRk::dense).
  VecX dense(double t) const override {
    if (S == 3) return ImplicitRk::dense(t);
    const double theta = (t - t_) / h_;
    Eigen::Matrix<double, S, 1> w1, w2;
    for (int k = 0; k < S; ++k) {  // Horner on the monomial coefficients
      double p1 = 0.0, p2 = 0.0;
      for (int m = S + 1; m >= 0; --m) p1 = p1 * theta + L1_(k, m), p2 = p2 * theta + L2_(k, m);
      w1(k) = p1, w2(k) = p2;
    }
    VecX out(2 * n_);
    out.tail(n_).noalias() = h_ * A_ * w1;
    out.tail(n_) += vp_;
    out.head(n_).noalias() = (h_ * h_) * A_ * w2;
    out.head(n_) += qp_ + (theta * h_) * vp_;
    if (sys_.nl > 0) {  // q_, v_ projected onto the loops (project), the stages not
      out.head(n_) += theta * (q_ - Q_.col(S - 1));
      out.tail(n_) += theta * (v_ - V_.col(S - 1));
    }
    return out;
  }

  /// The estimate is O(h^(S+1)) (order S): PI control as ImplicitRk's with that exponent.
  StepControl control() const override {
    StepControl c = ImplicitRk::control();
    c.k = S + 1;
    return c;
  }

  void stages(MatX& Q, MatX& V, MatX& A) const override { Q = Q_, V = V_, A = A_; }
  void stage_multipliers(MatX& L) const override { L = L_; }
  void current(VecX& q, VecX& v, VecX& a) const override { q = q_, v = v_, a = a_; }
  void restore(double t, const VecX& q, const VecX& v, const VecX& a) override {
    q_ = q, v_ = v, a_ = a;
    y_ << q_, v_;
    ys_.resize(2 * n_ + sys_.nz);
    ys_ << y_, s_;
    t_ = t, have_previous_ = false, rejected_ = false;
  }

 private:
  /// The stages by simplified Newton on the transformed system: R = [r_i] (nq, S), R̃ = R P⁻ᵀ, each
  /// column solved with its block, ΔÃ_k = −S_k⁻¹ R̃_k, then ΔA = Re(ΔÃ Pᵀ).
  bool solve(double t, double h, const Tolerances* tol) override {
    if (tangent(t) || other_step(h, h_factored_)) factor(t, h);
    predict(h);
    predict_multipliers(h);
    basis_valid_ = full_ = lu_valid_ = false;  // the loops' row basis from this step's first stage
    slow_ = false;
    double previous = 0.0;
    for (int it = 0;; ++it) {
      interruption_point();
      stage_values(h);
      for (int i = 0; i < S; ++i) {
        residual(t + tab_.c(i) * h, Q_.col(i), V_.col(i), A_.col(i));
        if (sys_.nl > 0) {  // r_i −= G_iᵀ λ_i; c_i = γ_i − G_i A_i (d_.gamma with d_.qdda = A_i)
          G_[i] = free_jacobian(sys_, d_);
          r_.noalias() -= G_[i].transpose() * L_.col(i);
          Cres_.col(i) = d_.gamma;
        }
        R_.col(i) = r_;
      }
      solve_stages(R_, D_);
      D_ = -D_;  // ΔA = −𝒮⁻¹ R
      if (sys_.nl > 0) close_loops_correction();
      ++stats_.newton_iterations;
      if (!D_.allFinite()) return false;
      A_ += D_;
      // (ΔV, ΔQ) = (h ΔA aᵀ, h ΔV aᵀ), the largest stage increment
      dV_.noalias() = h * D_ * tab_.a.transpose();
      dQ_.noalias() = h * dV_ * tab_.a.transpose();
      double size = 0.0;
      for (int i = 0; i < S; ++i) size = std::max(size, increment_size(dQ_.col(i), dV_.col(i), tol));
      // gauss6 within newton_tol as asked, and at round-off (no longer contracting) or out of iterations
      if (!tab_.stiffly_accurate && it >= 1 && size * symmetric_tol <= 1.0 &&
          (size >= 0.5 * previous || it + 1 >= max_it_))
        break;
      const Newton state = progress(it, size, previous);
      if (state == Newton::Failed) return false;
      if (state == Newton::Converged) break;
    }
    stage_values(h);
    if (tab_.stiffly_accurate) {
      q1_ = Q_.col(S - 1), v1_ = V_.col(S - 1), a1_ = A_.col(S - 1);
    } else {  // (q, q̇)_{n+1} = (q, q̇)_n + h Σ b_i (V_i, A_i), and q̈_{n+1} by the forward dynamics there
      q1_.noalias() = q_ + h * V_ * tab_.b;
      v1_.noalias() = v_ + h * A_ * tab_.b;
      ++stats_.rhs_evaluations;
      a1_ = forward_dynamics(sys_, d_, t + h, q1_, v1_);
    }
    sensitivities_failed_ = sens_ && !stage_sensitivities(t, h);  // as Newton's failure: the step retried
    return !sensitivities_failed_;
  }

  /// The sensitivities' stages (the staggered direct method) after the state's have converged: δA (nq, S) with
  /// δV = δq̇_n 1ᵀ + h δA aᵀ, δQ = δq_n 1ᵀ + h δV aᵀ solving each stage's differentiated equations
  ///   R_i = K δQ_i + C δV_i + M δA_i − ∂(G_iᵀλ_i)/∂q δQ_i − G_iᵀ δλ_i + ∂r/∂p = 0   (loops: G_i δA_i = D(γ_i − G_i A_i))
  /// by simplified Newton with the step's matrix (solve_stages and, with loops, close_loops_correction), until
  /// the corrections move δQ and δV by less than 1e-9 of them, stall at the differences' noise (1e-6 of δA), or
  /// fall below the round-off of ∂r/∂p's difference (a sensitivity that is exactly zero, such as a freely falling
  /// body's to its mass, converges to that round-off, where neither relative test passes). False when they do not
  /// converge (the step is then retried as after Newton's failure: with a fresh tangent, then shorter).
  bool stage_sensitivities(double t, double h) {
    const int P = sens_->count(), nl = sys_.nl;
    Sq1_.resize(n_, P), Sv1_.resize(n_, P), Sa1_.resize(n_, P);
    const MatX A = A_, V = V_, Q = Q_, L = L_;  // the converged stages (the loop correction below reuses L_, D_)
    // ∂r/∂p's difference carries about ε |f| / h_p (difference_noise), which S₁⁻¹ carries into δA: 64 ε S₁⁻¹|f|
    // per unit of 1/h_p is as close as the corrections can come
    VecX noise(n_);
    matrix_->solve(sens_->force_sizes(t + h, Q.col(S - 1), V.col(S - 1)), noise);
    const double round_off = 64.0 * std::numeric_limits<double>::epsilon() * max_abs(noise);
    if (nl > 0)
      for (int i = 0; i < S; ++i) loop_equations(sys_, d_, t + tab_.c(i) * h, Q.col(i), V.col(i)), G_[i] = free_jacobian(sys_, d_);
    basis_valid_ = full_ = lu_valid_ = false;
    MatX dA(n_, S), dV(n_, S), dQ(n_, S), R(n_, S), dL = MatX::Zero(nl, S);
    for (int j = 0; j < P; ++j) {
      dA.colwise() = VecX(Sa_.col(j));
      dL.setZero();
      double previous = 0.0, free = 0.0;  // free: the largest correction before the loops' part
      const double floor = round_off * sens_->difference_noise(j);
      for (int it = 0;; ++it) {
        interruption_point();
        dV.noalias() = h * dA * tab_.a.transpose();
        dV.colwise() += VecX(Sv_.col(j));
        dQ.noalias() = h * dV * tab_.a.transpose();
        dQ.colwise() += VecX(Sq_.col(j));
        if (it == std::max(20, max_it_)) {
          L_ = L;
          return false;
        }
        for (int i = 0; i < S; ++i) {
          const double ti = t + tab_.c(i) * h;
          R.col(i) = sens_->residual_derivative(j, ti, Q.col(i), V.col(i), A.col(i), nl ? VecX(L.col(i)) : VecX(),
                                                dQ.col(i), dV.col(i), dA.col(i), nl ? VecX(dL.col(i)) : VecX());
          if (nl > 0)
            Cres_.col(i) = sens_->acceleration_constraint_derivative(j, ti, Q.col(i), V.col(i), A.col(i), dQ.col(i),
                                                                     dV.col(i)) - G_[i] * dA.col(i);
        }
        solve_stages(R, D_);
        D_ = -D_;
        free = std::max(free, D_.cwiseAbs().maxCoeff());
        if (nl > 0) {
          L_ = dL;
          close_loops_correction();
          dL = L_;
        }
        dA += D_;
        if (!dA.allFinite()) step_failure(t, h, "the sensitivities became NaN or inf");
        // the increments (ΔV, ΔQ) = (h ΔA aᵀ, h ΔV aᵀ) against the stages' δV, δQ
        const double change = D_.cwiseAbs().maxCoeff();
        const MatX incV = h * D_ * tab_.a.transpose(), incQ = h * incV * tab_.a.transpose();
        if ((incQ.cwiseAbs().maxCoeff() <= 1e-9 * dQ.cwiseAbs().maxCoeff() &&
             incV.cwiseAbs().maxCoeff() <= 1e-9 * dV.cwiseAbs().maxCoeff()) ||
            (nl > 0 && change <= 1e-12 * free) ||  // a sensitivity the loops hold at zero (sensitivity_stage)
            change <= floor)                        // at the difference's round-off
          break;
        if (it > 0 && change > 0.5 * previous && change <= 1e-6 * dA.cwiseAbs().maxCoeff()) break;
        previous = change;
      }
      dV.noalias() = h * dA * tab_.a.transpose();
      dV.colwise() += VecX(Sv_.col(j));
      dQ.noalias() = h * dV * tab_.a.transpose();
      dQ.colwise() += VecX(Sq_.col(j));
      Sq1_.col(j) = dQ.col(S - 1), Sv1_.col(j) = dV.col(S - 1), Sa1_.col(j) = dA.col(S - 1);
    }
    L_ = L;
    return true;
  }

  /// The multipliers' first iterate, as predict's for A: the last step's stage multipliers continued
  /// (λ_n at every stage on the first step), so that the first Newton increment is not mostly a
  /// correction of the multipliers.
  void predict_multipliers(double h) {
    if (sys_.nl == 0) return;
    if (!have_previous_)
      L_.colwise() = lambda_;
    else
      continue_stages(h, lambda_start_, Lprev_, L_);
  }

  /// Y = 𝒮⁻¹ X (nq, S) for Newton's matrix 𝒮 = I⊗M + h a⊗C + h² a²⊗K on the stages (columns): X̃ = X P⁻ᵀ,
  /// each column solved with its block (S₀ real, then each pair's complex block, its conjugate's the conjugate),
  /// Y = Re(Ỹ Pᵀ). With P's first column and P⁻¹'s first row real and the others conjugate pairs (check_pairs), in
  /// real arithmetic: x = X p̂₀ (p̂ⱼ = P⁻¹'s row j), z_k = X p̂_{2k+1}, and
  /// Y = S₀⁻¹x p₀ᵀ + Σ_k 2 Re(S_k⁻¹z_k p_{2k+1}ᵀ) (pⱼ = P's column j).
  void solve_stages(const MatX& X, MatX& Y) {
    x_.noalias() = X * pinv0_;
    for (int k = 0; k < pairs; ++k) {
      zr_[k].noalias() = X * pinv_[k].real();
      zi_[k].noalias() = X * pinv_[k].imag();
      z_[k].real() = zr_[k], z_[k].imag() = zi_[k];
    }
    matrix_->solve(x_, xs_);
    for (int k = 0; k < pairs; ++k) {
      matrix_->solve(z_[k], zs_[k], k);
      zr_[k] = zs_[k].real(), zi_[k] = zs_[k].imag();
    }
    for (int j = 0; j < S; ++j) {
      Y.col(j) = p0_(j) * xs_ + (2.0 * p_[0](j).real()) * zr_[0] - (2.0 * p_[0](j).imag()) * zi_[0];
      for (int k = 1; k < pairs; ++k)
        Y.col(j) += (2.0 * p_[k](j).real()) * zr_[k] - (2.0 * p_[k](j).imag()) * zi_[k];
    }
  }

  /// L1_ and L2_ (S × (S + 2), monomial coefficients in θ, row k): ∫₀^θ l_k and ∫₀^θ∫₀^σ l_k for Lagrange's basis
  /// l_k(θ) = Π_{j≠k} (θ − c_j)/(c_k − c_j) on the nodes (dense).
  void dense_polynomials() {
    L1_.setZero(S, S + 2), L2_.setZero(S, S + 2);
    for (int k = 0; k < S; ++k) {
      Eigen::VectorXd l = Eigen::VectorXd::Zero(S);  // l_k's coefficients, degree S − 1
      l(0) = 1.0;
      for (int j = 0, degree = 0; j < S; ++j) {
        if (j == k) continue;
        const double scale = 1.0 / (tab_.c(k) - tab_.c(j));
        for (int m = ++degree; m >= 0; --m) l(m) = ((m > 0 ? l(m - 1) : 0.0) - tab_.c(j) * l(m)) * scale;
      }
      for (int m = 0; m < S; ++m) L1_(k, m + 1) = l(m) / (m + 1);
      for (int m = 1; m <= S; ++m) L2_(k, m + 1) = L1_(k, m) / (m + 1);
    }
  }

  /// The tableau's P and P⁻¹ in the form solve_stages takes: P's first column and P⁻¹'s first row real, the
  /// other two conjugate, as the decomposition of a real matrix with one real eigenvalue gives them.
  void check_pairs() {
    bool form = tab_.P.col(0).imag().isZero(0.0) && tab_.Pinv.row(0).imag().isZero(0.0);
    for (int k = 0; k < pairs; ++k)
      form = form && tab_.P.col(2 * k + 2) == tab_.P.col(2 * k + 1).conjugate() &&
             tab_.Pinv.row(2 * k + 2) == tab_.Pinv.row(2 * k + 1).conjugate();
    if (!form) throw std::logic_error("collocation tableau: P and P⁻¹ are not in real-and-pair form");
    p0_ = tab_.P.col(0).real(), pinv0_ = tab_.Pinv.row(0).real().transpose();
    for (int k = 0; k < pairs; ++k) p_[k] = tab_.P.col(2 * k + 1), pinv_[k] = tab_.Pinv.row(2 * k + 1).transpose();
  }

  /// Loops, index 1 at each stage: M A_i − f_i − G_iᵀλ_i = 0 and G_i A_i = γ_i. With ΔA = −𝒮⁻¹R on entry
  /// (D_), Newton's step [𝒮, −𝒢ᵀ; 𝒢, 0] [ΔA; ΔΛ] = −[R; −c] (𝒢 = diag(G_i), c_i = γ_i − G_i A_i) by its
  /// Schur complement W = 𝒢 𝒮⁻¹ 𝒢ᵀ: W ΔΛ = c − 𝒢 ΔA, then ΔA += 𝒮⁻¹ 𝒢ᵀ ΔΛ. Each stage its own G_i: G frozen
  /// at one stage's left the iterations too slow to pass the contraction test (measured on the four-bar).
  ///
  /// Redundant rows (a planar loop closed in 3D, the Bricard's sixth joint) make W singular. The rows'
  /// independent combinations come first: Ĝ_i = Bᵀ G_i with B (nl, r) an orthonormal basis of the range of
  /// the first stage's G (row_basis, once per solve), and the multipliers λ_i = B μ_i, least-norm where the
  /// stages' G share that range. Ŵ = 𝒢̂ 𝒮⁻¹ 𝒢̂ᵀ (3r × 3r, by 3r stage solves) is then regular, built and factorised
  /// by LU once per solve (as 𝒮 itself: the iterations' G_i enter the right-hand side and the correction); where
  /// it is not (the stages cross a singular position, where G's rank changes), the full W (3 nl) at every
  /// iteration, solved for its least-norm multipliers (SVD). The Newton iterations are the same as with the full
  /// W at every iteration (149 on the slider-crank m = 4 at rtol = 1e-4, 54,211 on the Bricard linkage over
  /// 200 s at h = 10 ms), and radau5's run costs 2.79 ms instead of 4.40 ms on the first (5 rows of rank 2),
  /// 0.79 s instead of 3.8 s on the second (5 rows of rank 4).
  void close_loops_correction() {
    if (full_) return close_loops_full();
    if (!basis_valid_) {
      row_basis(G_[0], basis_);
      basis_valid_ = true;
    }
    const int r = static_cast<int>(basis_.cols());
    if (r == 0) {  // no constraint left (every row zero here): no multiplier
      L_.setZero();
      return;
    }
    for (int i = 0; i < S; ++i) Gr_[i].noalias() = basis_.transpose() * G_[i];
    if (!lu_valid_) schur(Gr_, r);
    for (int i = 0; i < S; ++i) w_.segment(i * r, r).noalias() = basis_.transpose() * (Cres_.col(i) - G_[i] * D_.col(i));
    // the multipliers themselves, Ŵ μ⁺ = ĉ − 𝒢̂ ΔA + Ŵ μ, as below
    mu_.resize(S * r);
    for (int i = 0; i < S; ++i) mu_.segment(i * r, r).noalias() = basis_.transpose() * L_.col(i);
    auto Wr = W_.topLeftCorner(S * r, S * r);
    w_.head(S * r).noalias() += Wr * mu_;
    if (!lu_valid_) {  // Ŵ factorised once per solve, and its condition estimated then (a few solves)
      lu_.compute(Wr);
      lu_valid_ = true;
      full_ = !(lu_.rcond() > 1e-10);  // singular: the full W for the rest of this solve
    }
    if (full_) return close_loops_full();
    mu1_ = lu_.solve(w_.head(S * r));  // μ⁺
    for (int i = 0; i < S; ++i) E_.col(i).noalias() = Gr_[i].transpose() * (mu1_ - mu_).segment(i * r, r);
    solve_stages(E_, Z_);
    D_ += Z_;
    for (int i = 0; i < S; ++i) L_.col(i).noalias() = basis_ * mu1_.segment(i * r, r);
  }

  /// W (its leading Sk × Sk) = 𝒢 𝒮⁻¹ 𝒢ᵀ for the stages' rows G[i] (k, nq): one stage solve per row and stage.
  void schur(const MatX* G, int k) {
    for (int j = 0; j < S; ++j)
      for (int r = 0; r < k; ++r) {
        E_.setZero();
        E_.col(j) = G[j].row(r).transpose();
        solve_stages(E_, Z_);
        for (int i = 0; i < S; ++i) W_.block(i * k, j * k + r, k, 1).noalias() = G[i] * Z_.col(i);
      }
  }

  /// The same step with every row of G: W (S nl × S nl) solved for its least-norm multipliers.
  void close_loops_full() {
    const int nl = sys_.nl;
    schur(G_, nl);
    for (int i = 0; i < S; ++i) {
      w_.segment(i * nl, nl) = Cres_.col(i);
      w_.segment(i * nl, nl).noalias() -= G_[i] * D_.col(i);
    }
    // The least-norm multipliers themselves, W Λ⁺ = c − 𝒢 ΔA + W Λ, not the least-norm increment: in a
    // direction where G lost rank W is blind to Λ, which must then be zero, not its prediction.
    VecX L = Eigen::Map<const VecX>(L_.data(), S * nl);
    w_.noalias() += W_ * L;
    const VecX dl = least_norm(W_, w_) - L;
    for (int i = 0; i < S; ++i) E_.col(i).noalias() = G_[i].transpose() * dl.segment(i * nl, nl);
    solve_stages(E_, Z_);
    D_ += Z_;
    for (int i = 0; i < S; ++i) L_.col(i) += dl.segment(i * nl, nl);
  }

  /// V = q̇_n 1ᵀ + h A aᵀ, Q = q_n 1ᵀ + h V aᵀ.
  void stage_values(double h) {
    V_.noalias() = h * A_ * tab_.a.transpose();
    V_.colwise() += v_;
    Q_.noalias() = h * V_ * tab_.a.transpose();
    Q_.colwise() += q_;
  }

  /// The first iterate: the accelerations' collocation polynomial of the last step (through q̈_n−1 and its stages)
  /// continued to the new stage times, or q̈_n at every stage, whichever came the closer to the last step's converged
  /// stages (accepted); q̈_n at every stage on the first step. The polynomial wins where the steps resolve the motion;
  /// where they step over modes that ring (hω of 3 to 10 on the whippy strip at radau9's steps), continuing a
  /// polynomial of degree S beyond its interval multiplies what the last step left of them: there the first
  /// increment of radau9 was 5-10 times the constant's, and Newton took 2.47 iterations a step instead of 2.27.
  void predict(double h) {
    if (!have_previous_) {
      A_.colwise() = a_;
      extrapolated_ = A_;
      return;
    }
    continue_stages(h, ap_, Aprev_, extrapolated_);
    if (extrapolate_)
      A_ = extrapolated_;
    else
      A_.colwise() = a_;
  }

  /// The polynomial through x(t_{n−1}) = start and the last step's stages prev (nq or nl, S), at this
  /// step's stage times (step h): Lagrange's polynomial of degree S in θ = (t − t_{n−1})/h_{n−1}, into out.
  void continue_stages(double h, const VecX& start, const MatX& prev, MatX& out) const {
    double x[S + 1] = {0.0};
    for (int k = 0; k < S; ++k) x[k + 1] = tab_.c(k);
    for (int i = 0; i < S; ++i) {
      const double theta = 1.0 + tab_.c(i) * h / h_previous_;
      double w[S + 1];
      for (int k = 0; k <= S; ++k) {
        w[k] = 1.0;
        for (int j = 0; j <= S; ++j)
          if (j != k) w[k] *= (theta - x[j]) / (x[k] - x[j]);
      }
      out.col(i) = w[0] * start + w[1] * prev.col(0) + w[2] * prev.col(1) + w[3] * prev.col(2);
      for (int k = 4; k <= S; ++k) out.col(i) += w[k] * prev.col(k - 1);
    }
  }

  /// Hairer's radau5: the estimate, of order 3, bounds an order-5 solution far below it, so on the state it
  /// is held to rtol' = 0.1 rtol^(2/3), atol' = atol rtol'/rtol (radau9, its estimate of order 5: rtol^(3/5), the
  /// exponent (S + 1)/2S of both) (on Kane's beam the error is then still
  /// 10-100× below rtol times the tip's deflection, against 100-2500× with the tolerances as asked). On
  /// outputs the tolerances stay as asked: there the estimate also stands for what a step loses of an
  /// oscillation it damps (about the mode's amplitude at hω ≫ 1: 0.7-1 times the step's error on
  /// y'' = −ω²y), which the looser rtol' would let through (measured: the tip error of a released strip
  /// 25 times the tolerance at 1e-7 with rtol', 13 times as asked before output_error's band-pass).
  const Tolerances& controlled(const Tolerances& asked) override {
    if (tol_.rtol.size() == asked.rtol.size()) return tol_;  // the same tolerances all run long
    tol_ = asked;
    for (Eigen::Index i = 0; i < asked.rtol.size(); ++i) {
      if (!(asked.rtol(i) > 0.0)) continue;
      tol_.rtol(i) = 0.1 * std::pow(asked.rtol(i), (S + 1.0) / (2.0 * S));
      tol_.atol(i) = asked.atol(i) * tol_.rtol(i) / asked.rtol(i);
    }
    return tol_;
  }

  void accepted() override {
    // the predictor for the next step (predict): the one nearer this step's stages (ap_ is q̈_n, a_ already q̈_n+1)
    extrapolate_ = (A_ - extrapolated_).squaredNorm() <= (A_.colwise() - ap_).squaredNorm();
    Aprev_ = A_;
    Lprev_ = L_, lambda_start_ = lambda_;  // lambda_: still the step's start (project follows)
    h_previous_ = h_;
    have_previous_ = true;
    rejected_ = false;
  }
  void restarted() override { have_previous_ = false, rejected_ = false; }

  /// Hairer's estimate: x = (I − g J)⁻¹ g [f(y_n) + Σ dd_i (Y_i − y_n)/h], g = h d₁, J the Jacobian
  /// of [q̇, q̈]: with b = [b₁, b₂] the bracket, (M + g C + g² K) x_q = M (g² b₂ + g b₁) + g² C b₁ and
  /// x_q̇ = x_q/g − b₁. On the first step and after a rejection an estimate above 1 is refined once
  /// with f(y_n + x) in place of f(y_n) (it damps the stiff components the first one leaves) — on the
  /// state only: on outputs those components are what the step loses of a mode the outputs see (the
  /// refined estimate of a mode at hω = 100 is 0.04 of its amplitude, the unrefined one 1.0).
  double estimate(double t, double h, const Tolerances& tol) override {
    const bool refine = (!have_previous_ || rejected_) && !tol.measure;
    rejected_ = true;  // until accepted
    b1_ = v_, b2_ = a_;
    for (int i = 0; i < S; ++i) {
      b1_ += (tab_.dd(i) / h) * (Q_.col(i) - q_);
      b2_ += (tab_.dd(i) / h) * (V_.col(i) - v_);
    }
    double err = filtered_error(h, tol);
    if (refine && err > 1.0) {
      // b with f(y_n + x) = [q̇_n + x_q̇, q̈(t, q_n + x_q, q̇_n + x_q̇)]
      qx_ = q_ + dy_.head(n_), vx_ = v_ + dy_.tail(n_);
      ++stats_.rhs_evaluations;
      b2_ += forward_dynamics(sys_, d_, t, qx_, vx_) - a_;
      b1_ += dy_.tail(n_);
      err = filtered_error(h, tol);
    }
    return err;
  }

  /// x = (I − g J)⁻¹ g b into dy_, and its scaled norm.
  double filtered_error(double h, const Tolerances& tol) {
    const double g = h * tab_.d(0).real();
    x_ = (g * g) * b2_ + g * b1_;
    xv_ = (g * g) * b1_;
    matrix_->derivative(zero_, xv_, x_, xs_);  // M x + g² C b₁
    matrix_->solve(xs_, x_);
    dy_ << x_, x_ / g - b1_;
    return tol.measure ? output_error(g, dy_, tol, h) : tol.norm(dy_, y_, y1_, h);
  }

  /// The blocks M + h d_k C + (h d_k)² K: d₁ real, then one complex block per pair (d₂, and radau9's d₄; their
  /// conjugates' blocks the conjugates).
  void factor(double t, double h) {
    const double g = h * tab_.d(0).real();
    const double real = matrix_->factor(g, g * g, VecX());
    double complex[pairs];
    for (int k = 0; k < pairs; ++k) {
      const cplx gc = h * tab_.d(2 * k + 1);
      complex[k] = matrix_->factor(gc, gc * gc, k);
    }
    h_factored_ = h;
    check_regular(real, t, h, "M + h d₁ C + (h d₁)² K");
    static const char* const blocks[] = {"M + h d₂ C + (h d₂)² K", "M + h d₄ C + (h d₄)² K"};  // one per pair
    for (int k = 0; k < pairs; ++k) check_regular(complex[k], t, h, blocks[k]);
  }

  static constexpr double symmetric_tol = 1e-4;  // gauss6's Newton increments: 1e-4 newton_tol (1 + |y|)
  const CollocationTableau<S> tab_;
  Tolerances tol_;  // the tolerances the estimate is held to (controlled)
  MatX A_, V_, Q_, R_, D_, dV_, dQ_, Aprev_;  // (nq, S) stages, residuals, increments, last step's A
  MatX extrapolated_;                         // (nq, S) the last step's polynomial continued to this step (predict)
  MatX L1_, L2_;                              // (S, S + 2) the dense output's polynomials (dense_polynomials)
  bool extrapolate_ = true;                   // predict: the polynomial (or q̈_n at every stage)
  VecX x_, xs_;                               // (nq) the real block's (and the error estimate's)
  Eigen::VectorXcd z_[pairs], zs_[pairs];     // (nq) each complex block's right-hand side and solution
  VecX zr_[pairs], zi_[pairs];                // (nq) z's and S_k⁻¹z's real and imaginary parts
  VecX b1_, b2_, qx_, vx_;                    // (nq) the error estimate's
  typename CollocationTableau<S>::Real p0_, pinv0_;                 // P's first column, P⁻¹'s first row (real)
  typename CollocationTableau<S>::Complex p_[pairs], pinv_[pairs];  // P's columns 2k + 1, P⁻¹'s rows 2k + 1
  double h_factored_ = 0.0, h_previous_ = 1.0;
  bool have_previous_ = false, rejected_ = false;
  MatX G_[S];         // (nl, nq) the loops' Jacobian at each stage of the iterate
  MatX L_, Cres_;     // (nl, S) the stages' multipliers and constraint residuals γ_i − G_i A_i
  MatX Lprev_;        // (nl, S) the last step's stage multipliers
  MatX W_;            // (S nl, S nl) the Schur complement 𝒢 𝒮⁻¹ 𝒢ᵀ over the stages (or its Sr × Sr: 𝒢̂ 𝒮⁻¹ 𝒢̂ᵀ)
  MatX basis_;        // (nl, r) orthonormal basis of the range of G at this solve's first stage (row_basis)
  MatX Gr_[S];        // (r, nq) the stages' independent rows Bᵀ G_i
  Eigen::PartialPivLU<MatX> lu_;      // of 𝒢̂ 𝒮⁻¹ 𝒢̂ᵀ
  VecX mu_, mu1_;                     // (Sr) the stages' multipliers in the basis: the iterate's and the next
  bool basis_valid_ = false, full_ = false, lu_valid_ = false;  // basis_ is this solve's; the full W is needed in this solve
  VecX w_;            // (S nl) its right-hand side
  MatX E_, Z_;        // (nq, S) stage right-hand sides and their 𝒮⁻¹
  VecX lambda_start_;  // (nl) the multipliers at the last step's start
};

}  // namespace

std::unique_ptr<Stepper> make_implicit_rk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) {
  if (o.method == Method::Radau5) return std::make_unique<Collocation<3>>(sys, o, stats, RadauTableau());
  if (o.method == Method::Radau9) return std::make_unique<Collocation<5>>(sys, o, stats, Radau9Tableau());
  if (o.method == Method::Gauss6) return std::make_unique<Collocation<3>>(sys, o, stats, GaussTableau());
  return std::make_unique<Esdirk>(sys, o, stats);
}

namespace {

// The collocation methods' own (radau5, radau9, gauss6): the exact tangent only, and no Maxwell arms, since their stages
// are coupled (esdirk43 takes both); gauss6 also no sensitivities (its step does not end at a stage, where the
// staggered direct method takes them), radau9 none either (radau5's are the ones checked against differences).
void check_collocation(const System& sys, const IntegratorOptions& o) {
  const std::string name = method_name(o.method);
  if (sys.nz > 0)
    throw std::invalid_argument("method: '" + name + "' does not integrate Maxwell arms (the system has " +
                                std::to_string(sys.nz) + " arm forces as internal variables); use esdirk43, "
                                "generalized_alpha or dopri5");
  if (o.iteration_matrix == IterationMatrix::Spring)
    throw std::invalid_argument("iteration_matrix: " + name + " takes the exact tangent ('auto', 'tangent' or "
                                "'krylov'), got 'spring' ('krylov' is its O(n) form); use esdirk43 for the spring "
                                "matrix");
  if ((o.method == Method::Gauss6 || o.method == Method::Radau9) && !o.sensitivities.empty())
    throw std::invalid_argument("sensitivities: " + name + " has no sensitivities; use radau5, esdirk43 or an "
                                "explicit method");
}

}  // namespace

const std::vector<MethodInfo>& implicit_rk_methods() {
  static const std::vector<MethodInfo> rows = {
      {Method::Esdirk43, "esdirk43", "implicit Runge-Kutta", 4, true, true, false, false, method_options(true, true),
       "ESDIRK4(3)6L[2]SA (Kennedy & Carpenter 2003): order 4, L-stable, stiffly accurate, embedded order 3, PI "
       "control; 5 implicit stages, each a Newton solve for its q̈ with M + γh C + (γh)² K (γ = ¼), dense output "
       "quintic Hermite",
       make_implicit_rk, nullptr},
      {Method::Radau5, "radau5", "implicit Runge-Kutta", 5, true, true, true, true, method_options(true, true),
       "Radau IIA, 3 stages, order 5, L-stable, stiffly accurate; simplified Newton on all stages in the transformed "
       "real/complex form (exact tangent only), Hairer's filtered estimate, PI control, dense output quintic Hermite",
       make_implicit_rk, check_collocation},
      {Method::Radau9, "radau9", "implicit Runge-Kutta", 9, true, true, true, false, method_options(true, true),
       "Radau IIA, 5 stages, order 9, L-stable, stiffly accurate; as radau5 with one real and two complex blocks "
       "(exact tangent only), Hairer's filtered estimate of order 5, PI control; dense output q̇'s collocation "
       "polynomial and its integral for q; no sensitivities or adjoint",
       make_implicit_rk, check_collocation},
      {Method::Gauss6, "gauss6", "implicit Runge-Kutta", 6, false, false, false, false, method_options(false, true),
       "Gauss-Legendre, 3 stages, order 6, fixed step: symmetric (time-reversible) and A-stable without damping "
       "(undamped modes keep their amplitude; a linear system's energy is kept exactly), so a regular conservative "
       "mechanism's energy error stays bounded over long runs; simplified Newton as radau5's, to 1e-4 newton_tol; "
       "dense output quintic Hermite",
       make_implicit_rk, check_collocation},
  };
  return rows;
}

}  // namespace rigidfem
