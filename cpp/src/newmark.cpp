// The Newmark family in the generalised-α form of Arnold & Brüls (2007): the equations
// of motion hold at t_{n+1}, M(q_{n+1}) q̈_{n+1} = f(q_{n+1}, q̇_{n+1}, t_{n+1}), and a
// pseudo-acceleration a carries the method:
//   (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n,
//   q_{n+1} = q_n + h q̇_n + h² [(½ − β) a_n + β a_{n+1}],
//   q̇_{n+1} = q̇_n + h [(1 − γ) a_n + γ a_{n+1}].
// The Maxwell arms' forces s (arms.hpp) advance exactly for q linear over the step (arm_step), so
// f(q_{n+1}, ...) holds s_{n+1}(q_{n+1}) and Newton's K the arms' stiffness k (1 − e^{−h/τ})/(h/τ).
// Newmark: α_m = α_f = 0; HHT-α: α_m = 0, α_f = −α; generalised-α from ρ∞ (Chung & Hulbert).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/constraints.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/newmark.hpp"
#include "rigidfem/newton_matrix.hpp"
#include "rigidfem/sensitivities.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

namespace {

class NewmarkFamily final : public NewmarkStepper {
 public:
  NewmarkFamily(const System& sys, const IntegratorOptions& o, IntegratorStats& stats)
      : sys_(sys),
        d_(sys),
        stats_(stats),
        tol_(o.newton_tol),
        span_(o.span),
        max_it_(o.newton_max_iterations),
        spring_(o.iteration_matrix == IterationMatrix::Spring ||
                (o.iteration_matrix == IterationMatrix::Auto && o.method == Method::ImplicitSpring)),
        armature_(sys.nq),
        arm_stiffness_(VecX::Zero(sys.nq)),
        matrix_(NewtonMatrix::make(sys, o, stats)) {
    if (!o.sensitivities.empty()) sens_ = std::make_unique<SensitivityEquations>(sys, o.sensitivities);
    if (o.method == Method::Newmark) {
      am_ = af_ = 0.0;
      beta_ = o.beta;
      gamma_ = o.gamma;
    } else if (o.method == Method::HHT) {
      am_ = 0.0;
      af_ = -o.alpha;
      gamma_ = 0.5 - o.alpha;
      beta_ = 0.25 * (1.0 - o.alpha) * (1.0 - o.alpha);
    } else {  // generalized_alpha, implicit_spring
      const double r = o.rho_inf;
      am_ = (2.0 * r - 1.0) / (r + 1.0);
      af_ = r / (r + 1.0);
      gamma_ = 0.5 - am_ + af_;
      beta_ = 0.25 * (gamma_ + 0.5) * (gamma_ + 0.5);
    }
  }

  /// M q̈ = f at (t, q, q̇): the initial state's acceleration, a_0 = q̈_0.
  void start(double t0, const VecX& y0) override {
    ++stats_.rhs_evaluations;
    const int n = sys_.nq;
    const VecX q0 = y0.head(n), qd0 = y0.segment(n, n), s0 = y0.segment(2 * n, sys_.nz);
    set_arm_forces(sys_, d_, s0);
    const VecX qdd = forward_dynamics(sys_, d_, t0, q0, qd0);
    s_ = {q0, qd0, qdd, qdd, d_.lambda, s0, {}, {}, {}, {}, {}};
    if (sens_) start_sensitivities(t0, y0);
    y_ = y0;
    t_ = t0, h_step_ = 1.0, lambda_a_ = s_.lambda;  // multipliers(t0): λ_0
  }

  double initial_step(double span, const Tolerances&, double max_step) override {
    return std::min(1e-3 * span, max_step);
  }

  bool attempt(double t, double h, const Tolerances* tol, double& err) override {
    t_ = t, h_step_ = h;
    err = 0.0;
    if (sys_.nq == 0) {  // nothing to solve: the state is empty
      s1_ = s_;
      return true;
    }
    if (!newton(t, h)) return false;
    if (!s1_.q.allFinite() || !s1_.v.allFinite()) step_failure(t, h, "the state became NaN or inf");
    if (sens_ && !step_sensitivities(t, h, tol != nullptr)) return false;  // adaptive: the step retried shorter
    if (!tol) return true;
    // Local error estimate of q over the step, h² (β − 1/6)(a_{n+1} − a_n), per unit step: a second-order
    // method propagates the solution it estimates, so the steps' errors add up (coherently, in the phase
    // of an oscillation); held to tol · h / span each, they add up to the tolerance over the run.
    const int n = sys_.nq;
    const VecX eq = (h * h * (beta_ - 1.0 / 6.0)) * (s1_.a - s_.a);
    if (tol->measure) {
      e_.resize(2 * n);
      e_ << eq, VecX::Zero(n);
      err = tol->norm(e_, e_, e_, h);  // on the outputs: the positions' error only
    } else {
      err = error_norm(eq, s_.q, s1_.q, tol->atol.head(n), tol->rtol.head(n));
    }
    if (tol->span > 0.0) err *= tol->span / h;
    return true;
  }

  void accept() override {
    const int n = sys_.nq;
    ya_.resize(2 * n), fa_.resize(2 * n), yb_.resize(2 * n), fb_.resize(2 * n);
    ya_ << s_.q, s_.v;
    fa_ << s_.v, s_.qdd;
    yb_ << s1_.q, s1_.v;
    fb_ << s1_.v, s1_.qdd;
    y_.resize(2 * n + sys_.nz + 2 * n * sensitivity_count());
    y_ << yb_, s1_.s, sensitivity_blocks(s1_);
    sa_ = s_.s;
    if (sens_) sens_a_ = s_;
    lambda_a_ = s_.lambda;
    s_ = s1_;
  }

  const VecX& state() const override { return y_; }
  /// [q, q̇] by cubic Hermite interpolation, s by arm_step along it.
  VecX dense(double t) const override {
    const int n = sys_.nq;
    VecX y(2 * n + sys_.nz), s;
    y.head(2 * n) = hermite((t - t_) / h_step_, h_step_, ya_, fa_, yb_, fb_);
    arm_step(sys_, t - t_, sa_, ya_.head(n), y.head(n), s);
    y.segment(2 * n, sys_.nz) = s;
    if (sens_) {  // each [S_q, S_q̇] by the same Hermite rule from [S_q, S_q̇] and [S_q̇, S_q̈] at both ends
      VecX Sy;
      y.conservativeResize(2 * n + sys_.nz + 2 * n * sensitivity_count());
      for (int j = 0; j < sensitivity_count(); ++j) {
        Sy = hermite((t - t_) / h_step_, h_step_, pair(sens_a_.Sq.col(j), sens_a_.Sv.col(j)),
                     pair(sens_a_.Sv.col(j), sens_a_.Sqdd.col(j)), pair(s_.Sq.col(j), s_.Sv.col(j)),
                     pair(s_.Sv.col(j), s_.Sqdd.col(j)));
        y.segment(2 * n + sys_.nz + 2 * n * j, 2 * n) = Sy;
      }
    }
    return y;
  }
  /// λ by linear interpolation of λ_n, λ_{n+1} (second order, as the method).
  bool multipliers(double t, VecX& lambda) const override {
    if (sys_.nl == 0) return false;
    const double theta = (t - t_) / h_step_;
    lambda = (1.0 - theta) * lambda_a_ + theta * s_.lambda;
    return true;
  }
  /// The estimate per unit step is O(h²).
  StepControl control() const override { return {2, 5.0, false, 1.25}; }

  const NewmarkState& current() const override { return s_; }
  std::shared_ptr<const DenseLU> dense_factor() const override { return matrix_->dense_factor(); }
  void restore(double t, const NewmarkState& s) override {
    s_ = s;
    y_.resize(2 * sys_.nq + sys_.nz);
    y_ << s.q, s.v, s.s;
    t_ = t, h_step_ = 1.0, lambda_a_ = s.lambda;
  }
  NewmarkCoefficients coefficients() const override { return {am_, af_, beta_, gamma_}; }

 private:
  /// Newton iterations for q̈_{n+1} into s1_; false when they do not converge.
  bool newton(double t, double h) {
    const NewmarkState& s = s_;
    NewmarkState& s1 = s1_;
    const double bp = beta_ * (1.0 - af_) / (1.0 - am_), gp = gamma_ * (1.0 - af_) / (1.0 - am_);
    arm_step_stiffness(sys_, h, arm_stiffness_);
    // Attempts: the kept iteration matrix; a fresh one (if it was old); Newton proper, the
    // tangent rebuilt at every iterate. Spring: its matrix (always fresh) first, then the exact
    // tangent, fresh and at every iterate: the spring matrix leaves out the geometric and
    // centrifugal stiffness, which a spinning beam's Newton needs (measured: Kane's beam at
    // dt = 0.04-0.05 s, where the spring iterations alone stop converging near t = 12 s).
    for (int attempt = 0; attempt < 3; ++attempt) {
      spring_now_ = spring_ && attempt == 0;
      if (attempt == 1 && fresh_ && !spring_) continue;
      valid_ = valid_ && attempt == 0;
      full_newton_ = attempt == 2;
      // Predictor: no displacement beyond q̇_n h (a_{n+1} = −(½ − β)/β a_n), so a stiff
      // mode's large acceleration does not throw the first iterate far off.
      const VecX a1 = (-(0.5 - beta_) / beta_) * s.a;
      s1.qdd = ((1.0 - am_) * a1 - af_ * s.qdd + am_ * s.a) / (1.0 - af_);
      s1.lambda = s.lambda;
      double previous = std::numeric_limits<double>::infinity();
      for (int it = 0; it < max_it_; ++it) {
        interruption_point();
        update(h, s, s1);
        if (!s1.q.allFinite() || !s1.v.allFinite()) break;  // a step so long that the iterate overflows
        const VecX r = residual(t + h, s1);
        VecX dx = spring_now_ ? spring_correction(h, r, bp, gp) : tangent_correction(t + h, h, r, bp, gp, it == 0);
        if (sys_.nl > 0) close_loops_correction(h * h * bp, s1, dx);
        ++stats_.newton_iterations;
        if (!dx.allFinite()) break;
        s1.qdd += dx;
        // Converged when the position and velocity errors left are negligible: the increments
        // times η = θ/(1 − θ) once a contraction rate θ < 1 is seen (the sum of the remaining
        // increments of a contraction; Hairer & Wanner IV.8), the increments themselves before.
        const double size = max_abs(dx);
        const double theta = it >= 1 ? size / previous : 0.0;  // 0: no rate seen yet
        const double eta = theta > 0.0 && theta < 1.0 ? theta / (1.0 - theta) : 1.0;
        const double dq = eta * bp * h * h * size, dv = eta * gp * h * size;
        if (converged(dq, dv, theta, h, s, s1)) {
          update(h, s, s1);
          if (it > 4) valid_ = false;  // slow convergence: refresh the iteration matrix next step
          fresh_ = false;
          return true;
        }
        if (it >= 2 && size > 2.0 * previous) break;  // diverging
        // A tangent from another state (an earlier step or the predictor) converging slowly:
        // rebuild it at the next iterate (Newton proper).
        if (!spring_now_ && ((it >= 1 && size > 0.5 * previous) || full_newton_)) valid_ = false;
        previous = size;
      }
    }
    return false;
  }

  /// Newton's stopping test on the errors it leaves in q and q̇ (dq, dv): below newton_tol (1 + |q|),
  /// newton_tol (1 + |q̇|), and, over a run of known span T, below κ = 0.03 of the step's own local error
  /// estimate e_q = h² |β − 1/6| |a_{n+1} − a_n| (as adaptive radau5 and esdirk43 hold Newton to a
  /// fraction of their error weights): dq ≤ κ e_q and dv ≤ κ e_q / T, each down to 1e-3 of the first
  /// bounds and not below 500 ε (1 + |q|). An error dv in q̇ moves q by up to dv T by the end, so that
  /// what the T/h steps leave adds up to at most κ of their own errors even where every step's is of one
  /// sign. Held to newton_tol (1 + |q̇|) alone, it grew as h shrank: Bricard linkage over 1 s, 6.4e-8 at
  /// h = 62.5 µs and 2.0e-7 at 15.6 µs, where the method's own error is 3e-9. Held to κ e_q / √(h T)
  /// (errors of either sign adding up as √(T/h)), it grew too, the Bricard's being of one sign: over 4 s
  /// 1.6e-5, 5.7e-6, 1.6e-5 rad at h = 1.56, 0.78, 0.39 ms, against 1.6e-5, 3.9e-6, 9.8e-7 with κ e_q / T
  /// (4.35 and 4.49 Newton iterations a step at 0.39 ms). Newton iterations a step on Kane's beam in 3D
  /// (40 elements, 20 s) at h = 2 / 0.5 ms: 3.00 / 2.92 held to newton_tol alone, 3.47 / 3.38 to
  /// κ e_q / √(h T), 3.86 / 3.38 to κ e_q / T, for the same tip to nine digits. Where the iterations stall
  /// (θ ≥ 1/2: round-off) within the first bounds, they are converged as far as the arithmetic goes.
  bool converged(double dq, double dv, double theta, double h, const NewmarkState& s, const NewmarkState& s1) const {
    constexpr double kappa = 0.03;
    const double q_scale = tol_ * (1.0 + max_abs(s1.q)), v_scale = tol_ * (1.0 + max_abs(s1.v));
    if (!(dq <= q_scale && dv <= v_scale)) return false;
    if (theta >= 0.5 || span_ <= 0.0) return true;
    // the floor: 1e-3 of the first bounds, not below 500 ε (1 + |q|), which round-off reaches
    const double local = kappa * h * h * std::abs(beta_ - 1.0 / 6.0) * (s1.a - s.a).lpNorm<Eigen::Infinity>();
    const double floor = std::max(1e-3, 500.0 * std::numeric_limits<double>::epsilon() / tol_);
    return dq <= std::max(local, floor * q_scale) && dv <= std::max(local / span_, floor * v_scale);
  }

  void update(double h, const NewmarkState& s, NewmarkState& s1) const {
    s1.a = ((1.0 - af_) * s1.qdd + af_ * s.qdd - am_ * s.a) / (1.0 - am_);
    s1.q = s.q + h * s.v + (h * h) * ((0.5 - beta_) * s.a + beta_ * s1.a);
    s1.v = s.v + h * ((1.0 - gamma_) * s.a + gamma_ * s1.a);
    arm_step(sys_, h, s.s, s.q, s1.q, s1.s);
  }

  /// r = M(q) q̈ − f(q, q̇, t) − Gᵀλ at the iterate (inverse dynamics: O(n) for recursive
  /// systems; with loops, g and G are left in d_ for close_loops_correction).
  VecX residual(double t, const NewmarkState& s1) {
    set_arm_forces(sys_, d_, s1.s);
    set_state(sys_, d_, t, s1.q, s1.v);
    set_accelerations(sys_, d_, s1.qdd);
    dynamics_kinematics(sys_, d_);
    ++stats_.rhs_evaluations;
    VecX r = inverse_dynamics(sys_, d_);
    if (sys_.nl > 0) r -= free_jacobian(sys_, d_).transpose() * s1.lambda;
    return r;
  }

  /// Index 3 (Arnold & Brüls): the Newton step of [S −Gᵀ; G 0] [Δq̈; Δλ] = −[r; g/(β'h²)] by
  /// its Schur complement. dx = −S⁻¹ r on entry; Y = S⁻¹ Gᵀ by nl solves with the iteration
  /// matrix, (G Y) Δλ = −g/(β'h²) − G dx, then dx += Y Δλ and λ += Δλ. O(n·nl + nl³).
  void close_loops_correction(double bh2, NewmarkState& s1, VecX& dx) {
    VecX dl;
    close_loops_correction(bh2, d_.g, dx, dl);
    s1.lambda += dl;
  }
  /// The same with the constraints' residual g given, Δλ into dl.
  void close_loops_correction(double bh2, const VecX& g, VecX& dx, VecX& dl) {
    const MatX G = free_jacobian(sys_, d_);
    const MatX Y = spring_now_ ? solve_armature(sys_, d_, G.transpose()) : matrix_->solve(MatX(G.transpose()));
    dl = least_norm(G * Y, -g / bh2 - G * dx);
    dx += Y * dl;
  }

  /// Newton: −S⁻¹ r with the tangent S = M + γ' h ∂r/∂q̇ + β' h² ∂r/∂q (newton_matrix.hpp: dense, or
  /// matrix-free by GMRES for a large recursive system), kept while h stays within 30 % of its own (it
  /// only steers the iterations).
  VecX tangent_correction(double t, double h, const VecX& r, double bp, double gp, bool predictor) {
    if (!valid_ || std::abs(h / h_ - 1.0) > 0.3) {
      // At the iterate of residual(); at the predictor with q̈ = 0: there the inertia term
      // ∂(M q̈)/∂q of a stiff mode's far-off q̈ steers worse than leaving it to the iterations
      // (measured on a stiff 3D beam at h = 2e-3 s), while near the solution it makes Newton's
      // convergence quadratic.
      matrix_->linearize(t, s1_.q, s1_.v, predictor ? VecX::Zero(sys_.nq) : s1_.qdd, s1_.s);
      // The reciprocal condition number, not the determinant, which under- or overflows for large n.
      if (!(matrix_->factor(gp * h, bp * h * h, (bp * h * h) * arm_stiffness_) > 1e-15))
        throw SimulationError(t, "the Newton iteration matrix M + γh C + βh² K is singular (step size h = " + num(h) +
                                     " s)");
      valid_ = true;
      fresh_ = true;
      h_ = h;
    }
    VecX dx;
    matrix_->solve(r, dx);
    return -dx;
  }

  /// The O(n) step: −(M + diag(γ' h b + β' h² c))⁻¹ r, the springs c and dampers b of the
  /// coordinates entering like joint armature in the articulated-body recursion (the rest
  /// of the tangent, geometric and gyroscopic, is left to the iterations).
  VecX spring_correction(double h, const VecX& r, double bp, double gp) {
    spring_armature(sys_, d_, gp * h, bp * h * h, armature_);  // d_: the iterate's state (residual())
    armature_ += (bp * h * h) * arm_stiffness_;
    ++stats_.factorizations;
    factor_armature(sys_, d_, armature_);  // residual() left the state of the iterate in d_
    VecX dx = -r;
    solve_armature(sys_, d_, dx, dx);
    return dx;
  }

  int sensitivity_count() const { return sens_ ? sens_->count() : 0; }
  static VecX pair(const VecX& a, const VecX& b) {
    VecX ab(a.size() + b.size());
    ab << a, b;
    return ab;
  }
  /// [S_q, S_q̇] of each parameter in turn (2 nq P).
  VecX sensitivity_blocks(const NewmarkState& s) const {
    const int n = sys_.nq;
    VecX S(2 * n * sensitivity_count());
    for (int j = 0; j < sensitivity_count(); ++j) S.segment(2 * n * j, 2 * n) = pair(s.Sq.col(j), s.Sv.col(j));
    return S;
  }

  /// S(t0) from y0, S̈(t0) from the differentiated forward dynamics (a_0 = q̈_0 as for the state).
  void start_sensitivities(double t0, const VecX& y0) {
    const int n = sys_.nq, P = sensitivity_count(), k0 = 2 * n + sys_.nz;
    forward_dynamics(sys_, d_, t0, s_.q, s_.v);
    VecX Sd(2 * n * P);
    sens_->rates(d_, t0, s_.q, s_.v, y0.tail(2 * n * P), Sd);
    s_.Sq.resize(n, P), s_.Sv.resize(n, P), s_.Sqdd.resize(n, P), s_.Slambda = MatX::Zero(sys_.nl, P);
    for (int j = 0; j < P; ++j) {
      s_.Sq.col(j) = y0.segment(k0 + 2 * n * j, n);
      s_.Sv.col(j) = y0.segment(k0 + 2 * n * j + n, n);
      s_.Sqdd.col(j) = Sd.segment(2 * n * j + n, n);
    }
    s_.Sa = s_.Sqdd;
  }

  /// The staggered direct method: the step's equations differentiated by each parameter are linear in
  /// δq̈_{n+1} (and δλ_{n+1}) with the Newton matrix S = M + γ'h C + β'h² K as their matrix,
  ///   R(δq̈) = ∂r/∂q δq_{n+1} + ∂r/∂q̇ δq̇_{n+1} + M δq̈ − ∂(Gᵀλ)/∂q δq_{n+1} − Gᵀ δλ + ∂r/∂p = 0,
  ///   G δq_{n+1} + ∂g/∂p = 0,
  /// with δq_{n+1}, δq̇_{n+1} from the method's update. Solved by corrections with the step's own iteration matrix
  /// (exact tangent: one correction to the differences' accuracy; spring matrix: a few) until they are below
  /// 1e-10 of δq̈. False (adaptive steps) when they do not converge: the step is then retried shorter.
  bool step_sensitivities(double t, double h, bool adaptive) {
    const int P = sensitivity_count();
    const double bp = beta_ * (1.0 - af_) / (1.0 - am_), gp = gamma_ * (1.0 - af_) / (1.0 - am_);
    NewmarkState& s1 = s1_;
    s1.Sq.resize(sys_.nq, P), s1.Sv.resize(sys_.nq, P), s1.Sqdd.resize(sys_.nq, P), s1.Sa.resize(sys_.nq, P);
    s1.Slambda = s_.Slambda;
    const int max_it = std::max(20, max_it_);
    for (int j = 0; j < P; ++j) {
      VecX dqdd = s_.Sqdd.col(j), dl = s_.Slambda.col(j), dq, dv, da;
      // G δq_{n+1} + ∂g/∂p = 0: a drive's number moves the loops' g(q, t; p) at fixed q
      const VecX dg_dp = sys_.nl ? sens_->loop_parameter_derivative(j, t + h, s1.q, s1.v, s1.qdd).g : VecX();
      double previous = 0.0;
      bool spring = spring_now_, refreshed = false;
      double free = 0.0;  // the largest correction before the loops' part
      for (int it = 0;; ++it) {
        interruption_point();
        da = ((1.0 - af_) * dqdd + af_ * s_.Sqdd.col(j) - am_ * s_.Sa.col(j)) / (1.0 - am_);
        dq = s_.Sq.col(j) + h * s_.Sv.col(j) + (h * h) * ((0.5 - beta_) * s_.Sa.col(j) + beta_ * da);
        dv = s_.Sv.col(j) + h * ((1.0 - gamma_) * s_.Sa.col(j) + gamma_ * da);
        if (it == max_it) {
          if (adaptive) return false;  // a shorter step moves the end state off what defeats them (a rope's kink)
          step_failure(t, h, "the sensitivities' corrections did not converge in " + std::to_string(max_it) +
                                 " iterations with the Newton matrix; reduce dt");
        }
        const VecX R = sens_->residual_derivative(j, t + h, s1.q, s1.v, s1.qdd, s1.lambda, dq, dv, dqdd, dl);
        const bool spring_matrix = spring_now_;
        spring_now_ = spring;  // the loops' correction solves with the matrix used here
        VecX dx = spring ? spring_correction(h, R, bp, gp) : tangent_correction(t + h, h, R, bp, gp, false);
        free = std::max(free, max_abs(dx));
        if (sys_.nl > 0) {
          const MatX G = free_jacobian(sys_, d_);
          VecX dlambda;
          close_loops_correction(h * h * bp, G * dq + dg_dp, dx, dlambda);
          dl += dlambda;
        }
        spring_now_ = spring_matrix;
        dqdd += dx;
        if (!dqdd.allFinite()) step_failure(t, h, "the sensitivities became NaN or inf");
        // Converged when the correction moves δq_{n+1} and δq̇_{n+1} by less than 1e-9 of them, or is below 1e-12
        // of what the loops took out of the corrections: a sensitivity they hold at zero (a mechanism the drives
        // move alone, by its masses) converges to 0, against which no relative test passes. A correction that
        // no longer halves has either reached the central differences' noise (below 1e-6 of δq̈: measured 1e-8 to
        // 1e-7 on beams and ropes, whose axial stiffness dwarfs the transverse one) or meets a matrix too far
        // from this step's tangent (an older one, or the spring matrix): then the exact tangent is formed here,
        // once, and the corrections go on with it.
        const double change = max_abs(dx);
        if ((bp * h * h * change <= 1e-9 * max_abs(dq) && gp * h * change <= 1e-9 * max_abs(dv)) ||
            (sys_.nl > 0 && change <= 1e-12 * free))
          break;
        if (it > 0 && change > 0.5 * previous) {
          if (change <= 1e-6 * max_abs(dqdd)) break;
          if (!refreshed) refreshed = true, spring = false, valid_ = false;
        }
        previous = change;
      }
      s1.Sqdd.col(j) = dqdd;
      s1.Sa.col(j) = ((1.0 - af_) * dqdd + af_ * s_.Sqdd.col(j) - am_ * s_.Sa.col(j)) / (1.0 - am_);
      s1.Sq.col(j) = s_.Sq.col(j) + h * s_.Sv.col(j) + (h * h) * ((0.5 - beta_) * s_.Sa.col(j) + beta_ * s1.Sa.col(j));
      s1.Sv.col(j) = s_.Sv.col(j) + h * ((1.0 - gamma_) * s_.Sa.col(j) + gamma_ * s1.Sa.col(j));
      s1.Slambda.col(j) = dl;
    }
    return true;
  }

  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  std::unique_ptr<SensitivityEquations> sens_;
  NewmarkState sens_a_;  // the state before the last accepted step (its sensitivities: dense output)
  double tol_;
  double span_;  // t_end − t0 (s), or 0
  int max_it_;
  bool spring_;
  bool spring_now_ = false;  // this attempt iterates with the spring matrix
  VecX armature_;
  VecX arm_stiffness_;  // (nq) ∂s_{n+1}/∂q_{n+1} of the arms over the step (arm_step_stiffness)
  double am_ = 0, af_ = 0, beta_ = 0.25, gamma_ = 0.5;
  std::unique_ptr<NewtonMatrix> matrix_;  // the tangent's
  bool valid_ = false, fresh_ = false, full_newton_ = false;
  double h_ = 0.0;                   // step of the kept tangent
  NewmarkState s_, s1_;              // the current state and the attempted step
  double t_ = 0.0, h_step_ = 1.0;    // the last attempted step
  VecX y_;                           // [q, q̇, s] after it
  VecX ya_, fa_, yb_, fb_, sa_;      // [q, q̇] and [q̇, q̈] before and after it, s before it
  VecX lambda_a_;                    // (nl) λ before it
  VecX e_;                           // (2 nq) the error estimate [e_q, 0] on outputs
};

}  // namespace

std::unique_ptr<Stepper> make_newmark(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) {
  return std::make_unique<NewmarkFamily>(sys, o, stats);
}

std::unique_ptr<NewmarkStepper> make_newmark_stepper(const System& sys, const IntegratorOptions& o,
                                                     IntegratorStats& stats) {
  return std::make_unique<NewmarkFamily>(sys, o, stats);
}

namespace {

// The family's own options: Newmark's β, γ in the unconditionally stable range, HHT's α in [−1/3, 0],
// generalised-α's ρ∞ in [0, 1].
void check_newmark(const System&, const IntegratorOptions& o) {
  if (o.method == Method::Newmark && !(o.gamma >= 0.5 && o.beta >= 0.25 * (0.5 + o.gamma) * (0.5 + o.gamma) - 1e-15))
    throw std::invalid_argument("beta, gamma: expected the unconditionally stable range gamma >= 1/2, "
                                "beta >= (gamma + 1/2)^2 / 4, got beta = " + num(o.beta) + ", gamma = " + num(o.gamma));
  if (o.method == Method::HHT && !(o.alpha >= -1.0 / 3.0 && o.alpha <= 0.0))
    throw std::invalid_argument("alpha: expected a value in [-1/3, 0], got " + num(o.alpha));
  if ((o.method == Method::GeneralizedAlpha || o.method == Method::ImplicitSpring) &&
      !(o.rho_inf >= 0.0 && o.rho_inf <= 1.0))
    throw std::invalid_argument("rho_inf: expected a value in [0, 1], got " + num(o.rho_inf));
}

}  // namespace

const std::vector<MethodInfo>& newmark_methods() {
  static const std::vector<MethodInfo> rows = {
      {Method::Newmark, "newmark", "Newmark", 2, true, false, true, true, method_options(true, true, {"beta", "gamma"}),
       "Newmark β, γ (average acceleration ¼, ½), Newton", make_newmark, check_newmark},
      {Method::HHT, "hht", "Newmark", 2, true, false, true, true, method_options(true, true, {"alpha"}),
       "Hilber–Hughes–Taylor α ∈ [−⅓, 0], Newton", make_newmark, check_newmark},
      {Method::GeneralizedAlpha, "generalized_alpha", "Newmark", 2, true, false, true,
       true, method_options(true, true, {"rho_inf"}), "Chung–Hulbert generalised-α with ρ∞, Newton", make_newmark,
       check_newmark},
      {Method::ImplicitSpring, "implicit_spring", "Newmark", 2, true, false, true,
       true, method_options(true, true, {"rho_inf"}),
       "generalised-α whose Newton matrix is M + diag(γ′h b + β′h² c), O(n) per iteration (ABA)", make_newmark,
       check_newmark},
  };
  return rows;
}

}  // namespace rigidfem
