// The integration loop shared by every method, the method table and the checks of the options.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/error_measure.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/newton_matrix.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

namespace {

// The methods: name, order, error estimate, adaptive by default, stepper.
const MethodInfo methods[] = {
    {Method::Euler, "euler", 1, false, false, make_runge_kutta},
    {Method::SymplecticEuler, "symplectic_euler", 1, false, false, make_runge_kutta},
    {Method::RK4, "rk4", 4, false, false, make_runge_kutta},
    {Method::Dopri5, "dopri5", 5, true, true, make_runge_kutta},
    {Method::RKF45, "rkf45", 4, true, true, make_runge_kutta},
    {Method::Newmark, "newmark", 2, true, false, make_newmark},
    {Method::HHT, "hht", 2, true, false, make_newmark},
    {Method::GeneralizedAlpha, "generalized_alpha", 2, true, false, make_newmark},
    {Method::ImplicitSpring, "implicit_spring", 2, true, false, make_newmark},
    {Method::Esdirk43, "esdirk43", 4, true, true, make_implicit_rk},
    {Method::Radau5, "radau5", 5, true, true, make_implicit_rk},
    {Method::Auto, "auto", 5, true, true, make_runge_kutta},  // dopri5 and its stiff method (AutoChoice)
};

const char* iteration_matrices[] = {"auto", "tangent", "spring", "krylov"};

using Clock = std::chrono::steady_clock;

}  // namespace

const MethodInfo& method_info(Method method) {
  for (const MethodInfo& m : methods)
    if (m.method == method) return m;
  throw std::logic_error("method_info: a method without a row in the table");
}

Method parse_method(const std::string& name) {
  std::string names;
  for (const MethodInfo& m : methods) {
    if (name == m.name) return m.method;
    names += std::string(names.empty() ? "" : ", ") + m.name;
  }
  bad("method", "one of " + names, "'" + name + "'");
}

const char* method_name(Method method) { return method_info(method).name; }

IterationMatrix parse_iteration_matrix(const std::string& name) {
  for (int k = 0; k < 4; ++k)
    if (name == iteration_matrices[k]) return static_cast<IterationMatrix>(k);
  bad("iteration_matrix", "'auto', 'tangent', 'spring' or 'krylov'", "'" + name + "'");
}

const char* iteration_matrix_name(IterationMatrix matrix) { return iteration_matrices[static_cast<int>(matrix)]; }

double scaled_rms(const VecX& v, const VecX& sc) {
  if (v.size() == 0) return 0.0;
  if ((sc.array() > 0.0).all()) return std::sqrt((v.array() / sc.array()).square().mean());
  double sum = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (v(i) != 0.0) sum += (v(i) / sc(i)) * (v(i) / sc(i));
  return std::sqrt(sum / static_cast<double>(v.size()));
}

double error_norm(const VecX& e, const VecX& y0, const VecX& y1, const VecX& atol, const VecX& rtol) {
  return scaled_rms(e, atol.array() + rtol.array() * y0.cwiseAbs().cwiseMax(y1.cwiseAbs()).array());
}

double Tolerances::norm(const VecX& e, const VecX& y0, const VecX& y1, double h) const {
  if (measure) return measure->norm(e, h, output_atol, output_rtol);
  return error_norm(e, y0, y1, atol, rtol);
}

Tolerances Tolerances::scaled(double factor) const {
  Tolerances t = *this;
  t.atol *= factor, t.rtol *= factor, t.output_atol *= factor, t.output_rtol *= factor;
  return t;
}

VecX hermite(double theta, double h, const VecX& y0, const VecX& f0, const VecX& y1, const VecX& f1) {
  const double t2 = theta * theta, t3 = t2 * theta;
  return (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + theta) * h * f0 + (-2 * t3 + 3 * t2) * y1 +
         (t3 - t2) * h * f1;
}

void step_failure(double t, double h, const std::string& cause) {
  throw SimulationError(t, cause + " (step size h = " + num(h) + " s)");
}

namespace {

/// Output at requested times (or every step). With loops, every output is projected onto them
/// (closure residual <= 1e-12 in q and in q̇): dense output between steps, and the steps of the
/// Newmark family, which hold g(q) = 0 only to Newton's tolerance and the rates to O(h²).
class Recorder {
 public:
  Recorder(const System& sys, Trajectory& traj, const Eigen::Ref<const VecX>& t_eval)
      : sys_(sys), traj_(traj), t_eval_(t_eval), nq_(sys.nq) {
    if (sys.nl > 0) d_ = std::make_unique<Data>(sys);
  }
  /// y = [q, q̇, s] at t; the stepper's own multipliers there, if any (Stepper::multipliers).
  void push(double t, const VecX& y, const Stepper* stepper = nullptr) {
    traj_.t.push_back(t);
    traj_.lambda.emplace_back();
    if (stepper && !stepper->multipliers(t, traj_.lambda.back())) traj_.lambda.back().resize(0);
    traj_.q.push_back(y.head(nq_));
    traj_.qd.push_back(y.segment(nq_, nq_));
    traj_.s.push_back(y.tail(sys_.nz));
    if (d_) project_onto_loops(sys_, *d_, t, traj_.q.back(), traj_.qd.back(), 1e-12, 10);
  }
  void start(double t0, const VecX& y0, const Stepper& stepper) {
    if (t_eval_.size() == 0) {
      push(t0, y0, &stepper);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t0) push(t_eval_(next_++), y0, &stepper);
  }
  /// Forgets every output (a run that starts again from t0).
  void clear() {
    traj_.t.clear(), traj_.q.clear(), traj_.qd.clear(), traj_.s.clear(), traj_.lambda.clear();
    next_ = 0;
  }
  /// After an accepted step ending at t1: the requested times in (t0, t1] by dense output.
  void step(double t1, const VecX& y1, const Stepper& stepper) {
    if (t_eval_.size() == 0) {
      push(t1, y1, &stepper);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t1) {
      const double t = t_eval_(next_++);
      push(t, t == t1 ? y1 : stepper.dense(t), &stepper);
    }
  }

 private:
  const System& sys_;
  Trajectory& traj_;
  const Eigen::Ref<const VecX>& t_eval_;
  int nq_;
  std::unique_ptr<Data> d_;
  Eigen::Index next_ = 0;
};

bool is_adaptive(const IntegratorOptions& o) {
  return o.adaptive >= 0 ? o.adaptive == 1 : method_info(o.method).adaptive;
}


/// The spectral radius ρ of the Jacobian J = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]] of y' = (q̇, q̈) at (t, q, q̇, s):
/// power iteration on J² (an undamped oscillation's pair ±iω is one eigenvalue −ω² of J², so the
/// iteration converges where J's own would circle), x ← J²x/‖J²x‖, ρ² = ‖J²x‖ for ‖x‖ = 1, with
/// J x = (x_q̇, (q̈(q + ε x_q, q̇ + ε x_q̇) − q̈)/ε) by forward differences, O(n) each, counted in
/// `evaluations`. The estimate settles on ρ at the ratio (ω₂/ω₁)² of the two highest modes per
/// iteration; it stops when an iteration changes it by less than 0.1 %, after at most 20 iterations
/// (41 evaluations with the one at the state itself). Measured against the highest frequency of
/// rf.modal_analysis: 0.01–1.7 % low on four of the benchmark's scenes, 0.04 % high on the whippy strip
/// (bent under gravity), 0.23 % low on a chain of six equal springs (ω₂/ω₁ = 0.91).
double spectral_radius(const System& sys, double t, const VecX& q, const VecX& v, const VecX& s, long& evaluations) {
  constexpr int iterations = 20;
  const int n = sys.nq;
  if (n == 0) return 0.0;
  Data d(sys);
  set_arm_forces(sys, d, s);
  const VecX a = forward_dynamics(sys, d, t, q, v);
  ++evaluations;
  const double eps = std::sqrt(std::numeric_limits<double>::epsilon()) * (1.0 + std::max(q.norm(), v.norm()));
  VecX x(2 * n), y(2 * n), qe(n), ve(n);
  for (int i = 0; i < 2 * n; ++i) x(i) = 1.0 + 0.1 * (i % 7);  // every mode present, none favoured
  x.normalize();
  auto apply = [&](const VecX& in, VecX& out) {  // out = J in; false at a perturbed state beyond doubles
    qe = q + eps * in.head(n), ve = v + eps * in.tail(n);
    if (!qe.allFinite() || !ve.allFinite()) return false;
    out.head(n) = in.tail(n);
    out.tail(n) = (forward_dynamics(sys, d, t, qe, ve) - a) / eps;
    ++evaluations;
    return true;
  };
  double rho = 0.0;
  for (int k = 0; k < iterations; ++k) {
    interruption_point();
    if (!apply(x, y) || !apply(y, x)) return rho;  // the last estimate
    const double norm = x.norm();
    if (!std::isfinite(norm)) return rho;  // the dynamics failed at a perturbed state: the last estimate
    if (norm == 0.0) return 0.0;           // nothing moves the state: no frequency
    const double previous = rho;
    rho = std::sqrt(norm);
    x /= norm;
    if (std::abs(rho - previous) <= 1e-3 * rho) break;
  }
  return rho;
}

/// method="auto": which of dopri5 and its stiff method runs. Three ways to the stiff method:
///  - from t0 at once, when dopri5 would need `direct_steps` or more for stability alone, span ρ/3.3
///    with ρ the Jacobian's spectral radius at t0 (spectral_radius);
///  - from t0 after a probe: dopri5's first window of `window` accepted steps holds a fifth at the
///    stability boundary (h ρ > 2), within `probe` steps and a fifth of the run. dopri5's state at its
///    stability boundary carries errors ~ the tolerance in the stiff modes, which an undamped beam keeps
///    ringing and the stiff method's error control then resolves (measured on Kane's beam at rtol = 1e-3:
///    597 esdirk43 steps over t = 0.2-5 s from dopri5's state, 15 from the initial one), so the stiff
///    method starts again from the initial state. When it reaches the time the probe reached it must have
///    advanced `margin` times as far per unit of work as the probe did, or dopri5 goes on from there;
///  - from the state reached, when a later window of dopri5 looks stiff (a fifth of its steps near
///    the stability boundary or a sixth as many rejections as steps), after waiting `backoff` windows
///    (doubled by a lost probe trial).
/// A hand-over is final. (Judging it too — over its first 26 steps against dopri5's last window or, from
/// t0, against dopri5's best rate 3.3/ρ per 6 evaluations, and every 100 steps after — was measured on
/// the benchmark's five scenes at rtol = 1e-1, 3e-2, 1e-2, 1e-4, 1e-6: trials were lost and repeated up
/// to 9 times, 8 of the 25 runs took 1.11-1.48 times as long, 4 (the stiff 3D cantilever at rtol <= 3e-2)
/// 0.61-0.81 times.) Work is counted, not timed, so the choice is the same on every run and machine: one unit per right-hand side (or residual) evaluation, nq per tangent (the analytic
/// derivatives cost about nq evaluations) and max(1, (nq/50)²) per dense factorisation (one for the O(n) one;
/// a Krylov tangent's evaluations are residuals, counted as such).
class AutoChoice {
 public:
  static constexpr int window = 20, probe = 100;
  static constexpr double margin = 1.25;  // a near tie goes to dopri5, whose error control is the surer
  static constexpr double loosest_explicit = 1e-3;  // dopri5's rtol at most (run() tightens looser ones)
  /// dopri5 is stable for h ρ up to about 3.3 (its region meets the real axis at −3.3; Hairer's test: 3.25).
  static constexpr double dopri5_stability = 3.3;
  /// The stiff method starts at t0, without a dopri5 probe, when dopri5 would need at least this many
  /// steps for stability alone (500 before the stiff method measured its error on outputs; 200 since,
  /// measured on the whippy strip (395 steps): its probe's first window did not look stiff at tight
  /// tolerances and dopri5 ran on, 1.9 times radau5's own time at a 1e-6 m tip error).
  static constexpr double direct_steps = 200;
  /// krylov: the stiff method's tangent is matrix-free (krylov_tangent).
  AutoChoice(const IntegratorOptions& o, int nq, double rho, double span, bool krylov)
      : o_(o), nq_(nq), direct_(std::isfinite(rho) && span * rho >= direct_steps * dopri5_stability),
        krylov_(krylov) {}

  /// Whether the stiff method takes the run from t0 on ρ (then call switched(t0, 0, stats)).
  bool stiff_from_start() const { return direct_; }

  /// After an accepted step: true when the run should change method (then call switched()).
  bool after_step(double t, double h_rho, const IntegratorStats& stats) {
    if (stiff_running_) {  // final, unless it is the restarted probe trial and has lost to the probe
      if (!restarted_ || t < probe_end_) return false;
      restarted_ = false;
      const bool kept = (t - t_mark_) / std::max(work(stats) - work_mark_, 1.0) >= margin * probe_rate_;
      if (!kept) backoff_ *= 2;
      return !kept;
    }
    if (h_rho > 2.0) ++near_boundary_;
    if (++steps_ < window) return false;
    // The first window: its start-up rejections say nothing, its steps at the stability boundary do.
    const bool near = near_boundary_ * 5 >= window, rejecting = (stats.rejected - rejected_mark_) * 6 >= window;
    const bool trial = (near && first_window_) || ((near || rejecting) && ++windows_since_trial_ >= backoff_);
    first_window_ = false;
    mark(t, stats);
    return trial;
  }
  /// The options of the method the run changes to, at time t; h: dopri5's step, to go on with should
  /// the stiff method lose (explicit_step).
  IntegratorOptions switched(double t, double h, IntegratorStats& stats) {
    stiff_running_ = !stiff_running_;
    IntegratorOptions next = o_;
    next.adaptive = 1;
    next.method = stiff_running_ ? o_.stiff_method : Method::Dopri5;
    if (stiff_running_) {
      ++stats.auto_trials;
      h_explicit_ = h;
    }
    stats.switched_at = stiff_running_ ? t : std::numeric_limits<double>::quiet_NaN();
    windows_since_trial_ = 0;
    spring_ = next.method == Method::ImplicitSpring || next.iteration_matrix == IterationMatrix::Spring || krylov_;
    mark(t, stats);
    return next;
  }
  /// The step to continue dopri5 with after a lost trial.
  double explicit_step() const { return h_explicit_; }
  /// Whether the trial just started should start from the initial state: the first, after at most
  /// `probe` dopri5 steps over at most a fifth of the run (a longer probe is not thrown away; a tenth
  /// until the stiff method started at once from 200 stability-bound steps instead of 500: a window of
  /// 20 steps at the stability limit then spans more than a tenth of any run below that).
  bool restart(const IntegratorStats& stats, double t0, double span) const {
    return stiff_running_ && stats.auto_trials == 1 && stats.steps <= probe && t_mark_ - t0 <= 0.2 * span;
  }
  bool stiff_running() const { return stiff_running_; }
  /// The trial starts at t0 instead (restart): it will be measured when it reaches the time the probe
  /// reached, against the probe's rate over the same interval (all the work so far).
  void switched_at(double t0, IntegratorStats& stats) {
    stats.switched_at = t0;
    restarted_ = true;
    probe_end_ = t_mark_;
    probe_rate_ = (t_mark_ - t0) / std::max(work_mark_, 1.0);
    mark(t0, stats);
  }

 private:
  /// The work done so far, in right-hand-side evaluations (see the class comment).
  double work(const IntegratorStats& s) const {
    const double factorization = spring_ ? 1.0 : std::max(1.0, (nq_ / 50.0) * (nq_ / 50.0));
    const double tangent = krylov_ ? 0.0 : nq_;
    return static_cast<double>(s.rhs_evaluations) + tangent * static_cast<double>(s.jacobians) +
           factorization * static_cast<double>(s.factorizations);
  }
  /// A new window from t: its time, work and rejections measured from here, its steps counted from 0.
  void mark(double t, const IntegratorStats& stats) {
    t_mark_ = t, work_mark_ = work(stats), rejected_mark_ = stats.rejected;
    steps_ = 0, near_boundary_ = 0;
  }
  IntegratorOptions o_;
  int nq_;
  bool direct_;  // the stiff method from t0 on ρ alone
  bool krylov_;  // the stiff method's tangent is matrix-free
  bool stiff_running_ = false, spring_ = false, restarted_ = false, first_window_ = true;
  double probe_end_ = 0.0, probe_rate_ = 0.0;  // the restarted trial's comparison (switched_at)
  // The first window holds dopri5's start from its first step (rejections, a low rate): only its steps at the
  // stability boundary start a trial after it.
  int steps_ = 0, near_boundary_ = 0, windows_since_trial_ = -1, backoff_ = 1;
  long rejected_mark_ = 0;
  double t_mark_ = 0.0, work_mark_ = 0.0, h_explicit_ = 0.0;
};

/// The one loop, into traj: attempt a step, control its size by the error estimate (adaptive runs)
/// or keep to the grid t0 + k·dt (fixed steps), record the outputs it covers, ask the monitor; the
/// last step lands on t_end exactly. last_q: the last accepted coordinates.
void run(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
         const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o, const Monitor& monitor, Trajectory& traj,
         VecX& last_q) {
  auto last_check = Clock::now();
  IntegratorStats& stats = traj.stats;
  Recorder out(sys, traj, t_eval);
  const int n = sys.nq;
  const bool adaptive = is_adaptive(o);
  // The outputs the error is measured on (error_measure.hpp), for adaptive runs; none: the state.
  std::unique_ptr<ErrorMeasure> measure;
  if (adaptive && !o.error_on.empty()) {
    measure = std::make_unique<ErrorMeasure>(sys, o.error_on, t0, q0);
    stats.model_size = measure->length();
  }
  // On outputs, the state's weights (Newton's increments, first steps) take as atol the rotation (rad)
  // that moves a point at the model's far end L by the length tolerance: (atol + rtol L)/L.
  const double state_atol = measure ? (o.atol(0) + o.rtol(0) * measure->length()) / measure->length() : o.atol(0);
  const Tolerances asked{o.atol.size() == 1 ? VecX::Constant(2 * n, state_atol) : o.atol,
                         o.rtol.size() == 1 ? VecX::Constant(2 * n, o.rtol(0)) : o.rtol,
                         t_end - t0,
                         measure.get(),
                         o.atol(0),
                         o.rtol(0)};
  // auto runs dopri5 at rtol <= 1e-3 (atol scaled alike): looser, its error control lets the stiff
  // modes of a beam go unstable (measured: the classical cantilever at rtol = 1e-2 ... 1e-1).
  const double loosest = asked.rtol.size() ? asked.rtol.maxCoeff() : 0.0;  // nq = 0: no tolerance to tighten
  const double tighten = o.method == Method::Auto && loosest > AutoChoice::loosest_explicit
                             ? AutoChoice::loosest_explicit / loosest : 1.0;
  // auto's dopri5 holds the state whatever the outputs, to the tolerances as given: an explicit method's
  // stability rests on its error control, and a mode that no output sees would grow unseen until it does.
  Tolerances explicit_tol = asked.scaled(tighten);
  if (o.method == Method::Auto && measure) {
    explicit_tol.measure = nullptr;
    explicit_tol.atol = tighten * (o.atol.size() == 1 ? VecX::Constant(2 * n, o.atol(0)) : o.atol);
  }
  const double span = t_end - t0, grid = std::min(o.dt, o.max_step), near_end = t_end - 1e-12 * span;

  VecX y0(2 * n + sys.nz);
  y0 << q0, qd0, (o.s0.size() ? o.s0 : VecX::Zero(sys.nz));
  if (o.method == Method::Auto)
    stats.omega_max = spectral_radius(sys, t0, q0, qd0, y0.tail(sys.nz), stats.rhs_evaluations);
  IntegratorOptions stiff = o;
  stiff.method = o.stiff_method;
  AutoChoice choice(o, n, stats.omega_max, span, krylov_tangent(sys, stiff));
  // auto on a stiff problem (choice.stiff_from_start): its stiff method from t0 for the whole run (h = 0:
  // no dopri5 step to go back to).
  const IntegratorOptions first = choice.stiff_from_start() ? choice.switched(t0, 0.0, stats) : o;
  std::unique_ptr<Stepper> stepper = method_info(first.method).make(sys, first, stats);
  StepControl control = stepper->control();
  stepper->start(t0, y0);
  out.start(t0, stepper->state(), *stepper);
  const Tolerances* tol = o.method == Method::Auto && !choice.stiff_running() ? &explicit_tol : &asked;
  double h = o.dt > 0.0 ? std::min(o.dt, span) : stepper->initial_step(span, *tol, o.max_step);

  double t = t0;
  double err_prev = 1.0;  // the error estimate of the last accepted step (PI control)
  bool rejected_last = false;
  int stiff_steps = 0, nonstiff_steps = 0;  // Hairer's stiffness test (h ρ, dopri5)
  bool measured = false;                    // the measure is linearised at the current state
  while (t < t_end) {
    // The step: to the grid point t0 + k·dt (fixed) or by h (adaptive), to t_end for the last one.
    double hs, t1;
    if (adaptive) {
      hs = std::min({h, o.max_step, t_end - t});
      if (t + hs > near_end) hs = t_end - t;
      t1 = t + hs >= near_end ? t_end : t + hs;
    } else {
      t1 = t0 + static_cast<double>(stats.steps + 1) * grid;
      if (t1 > near_end) t1 = t_end;
      hs = t1 - t;
    }
    if (stats.steps + stats.rejected >= o.max_steps)
      step_failure(t, hs, "max_steps = " + std::to_string(o.max_steps) + " reached");
    if (hs < 16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)))
      step_failure(t, hs, "the step size fell below the minimum: the problem is too stiff or singular for this method");
    if (measure && !measured) measure->at(t, stepper->state()), measured = true;  // linearised at the step's start
    double err = 0.0;
    if (!stepper->attempt(t, hs, adaptive ? tol : nullptr, err)) {
      if (!adaptive)
        step_failure(t, hs, "Newton iterations did not converge in newton_max_iterations = " +
                                std::to_string(o.newton_max_iterations) + " (with a fresh tangent too); reduce dt "
                                "or raise newton_max_iterations");
      ++stats.rejected;
      h = 0.25 * hs;
      continue;
    }
    if (adaptive) {
      // h_new = h · min(growth, max(0.2, 0.9 err^(−β₁/k) err_prev^(β₂/k))), the elementary controller
      // after a rejection; no growth right after a rejection where the method asks so, and h kept
      // for small gains where it reuses a matrix.
      const double growth = control.hold_after_reject && rejected_last ? 1.0 : control.growth;
      const double e = std::max(err, 1e-10);
      const double pi = rejected_last || !(err <= 1.0)
                            ? std::pow(e, -1.0 / control.k)
                            : std::pow(e, -control.beta1 / control.k) * std::pow(err_prev, control.beta2 / control.k);
      double factor = std::min(growth, std::max(0.2, 0.9 * pi));
      if (factor >= 1.0 && factor < control.keep_below) factor = 1.0;
      if (!(err <= 1.0)) {
        if (!std::isfinite(err) && hs < 1e-300) step_failure(t, hs, "the error estimate is NaN or inf");
        ++stats.rejected;
        rejected_last = true;
        h = hs * (std::isfinite(err) ? factor : 0.2);
        continue;
      }
      rejected_last = false;
      err_prev = e;
      h = hs * factor;
      if (stepper->h_rho() > control.stiff_limit) {
        nonstiff_steps = 0;
        if (++stiff_steps == 15 && std::isnan(stats.stiff_at)) stats.stiff_at = t1;
      } else if (++nonstiff_steps == 6) {
        stiff_steps = 0;
      }
    }
    stepper->accept();
    measured = false;
    if (sys.nl > 0) stepper->project(t1);
    t = t1;
    ++stats.steps;
    const VecX& y = stepper->state();
    out.step(t, y, *stepper);
    last_q = y.head(n);
    if (o.method == Method::Auto && choice.after_step(t, stepper->h_rho(), stats)) {
      // Change method: the other goes on from the state reached (its own controller grows its step).
      const VecX y1 = y;
      const IntegratorOptions next = choice.switched(t, h, stats);
      stepper = method_info(next.method).make(sys, next, stats);
      control = stepper->control();
      if (choice.restart(stats, t0, span)) {  // the stiff method from the start: dopri5 was a probe (see AutoChoice)
        t = t0;
        stats.probe_steps = stats.steps;
        choice.switched_at(t0, stats);
        stepper->start(t0, y0);
        out.clear();
        out.start(t0, stepper->state(), *stepper);
        last_q = q0;
        h = stepper->initial_step(span, asked, o.max_step);
      } else {
        stepper->start(t, y1);
      }
      if (!choice.stiff_running()) h = choice.explicit_step();
      tol = choice.stiff_running() ? &asked : &explicit_tol;
      measured = false;
      rejected_last = false;
      err_prev = 1.0;
    }
    // Ask the monitor about every 0.05 s; false means stop (e.g. Ctrl-C).
    if (monitor && Clock::now() - last_check >= std::chrono::milliseconds(50)) {
      last_check = Clock::now();
      if (!monitor(t)) {
        traj.interrupted = true;
        return;
      }
    }
  }
}

/// What the last accepted state says about a failure: a fixed step beyond an explicit method's
/// stability limit (the state grew by orders of magnitude beyond max(|q0|, 1e-6): m, rad; the implicit
/// ones are unconditionally stable and say why Newton failed), or Euler angles near gimbal lock.
SimulationError explained(const SimulationError& e, const System& sys, const VecX& q0, const VecX& last_q,
                          const IntegratorOptions& o) {
  const double growth = max_abs(last_q) / std::max(max_abs(q0), 1e-6);
  const bool explicit_method = method_info(o.method).make == make_runge_kutta;
  if (!is_adaptive(o) && explicit_method && (growth > 1e3 || !last_q.allFinite()))
    return SimulationError(e.time, "the fixed step dt = " + num(o.dt) + " s is probably beyond the stability limit of " +
                                       std::string(method_name(o.method)) + " for this problem: the state grew " +
                                       num(growth) + " times, then " + e.cause);
  return SimulationError(e.time, e.cause + gimbal_lock_hint(sys, last_q, 1e-3));
}

}  // namespace

void check_options(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
                   const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o) {
  const MethodInfo& m = method_info(o.method);
  if (!std::isfinite(t0) || !std::isfinite(t_end) || !(t_end > t0))
    throw std::invalid_argument("t_end: expected a finite end time after t0 = " + num(t0) + " s, got " + num(t_end));
  check_vector(q0, sys.nq, "q0", "nq");
  check_vector(qd0, sys.nq, "qd0", "nq");
  if (!m.error_estimate && o.adaptive == 1)
    throw std::invalid_argument(std::string("adaptive: the method '") + m.name +
                                "' has no error estimate; use dopri5, rkf45, esdirk43, radau5 or the Newmark family");
  if ((o.method == Method::Radau5 || (o.method == Method::Auto && o.stiff_method == Method::Radau5)) && sys.nz > 0)
    throw std::invalid_argument("method: 'radau5' does not integrate Maxwell arms (the system has " +
                                std::to_string(sys.nz) + " arm forces as internal variables); use esdirk43, "
                                "generalized_alpha or dopri5");
  if (o.s0.size() != 0) check_vector(o.s0, sys.nz, "s0", "nz (the Maxwell arms' forces, N or N·m)");
  if (o.method == Method::Radau5 && o.iteration_matrix == IterationMatrix::Spring)
    throw std::invalid_argument("iteration_matrix: radau5 takes the exact tangent ('auto', 'tangent' or 'krylov'), got "
                                "'spring' ('krylov' is its O(n) form); use esdirk43 for the spring matrix");
  if (o.iteration_matrix == IterationMatrix::Krylov && !articulated(sys))
    throw std::invalid_argument("iteration_matrix: 'krylov' needs a system compiled with algorithm='recursive' (its "
                                "products are the recursive inverse dynamics'); use 'tangent' or 'auto'");
  if (!is_adaptive(o) && !(o.dt > 0.0 && std::isfinite(o.dt)))
    throw std::invalid_argument(std::string("dt: expected a positive step in s for the fixed-step method '") + m.name +
                                "', got " + num(o.dt));
  for (const auto& [tol, name] : {std::pair<const VecX*, const char*>{&o.rtol, "rtol"}, {&o.atol, "atol"}})
    if (tol->size() == 0 || (tol->size() != 1 && tol->size() != 2 * sys.nq) || !(tol->minCoeff() >= 0.0) ||
        !tol->allFinite())
      throw std::invalid_argument(std::string(name) + ": expected non-negative tolerances, one or 2 nq = " +
                                  std::to_string(2 * sys.nq) + " of them");
  if (!o.error_on.empty() && (o.rtol.size() != 1 || o.atol.size() != 1))
    throw std::invalid_argument("rtol, atol: expected one value each with error_on (the tolerances of its outputs), "
                                "got " + std::to_string(o.rtol.size()) + " and " + std::to_string(o.atol.size()));
  if (o.rtol.maxCoeff() == 0.0 && o.atol.minCoeff() == 0.0)
    throw std::invalid_argument("atol: expected positive values when rtol is zero");
  if (!(o.max_step > 0.0)) throw std::invalid_argument("max_step: expected a positive step in s");
  if (o.max_steps < 1) throw std::invalid_argument("max_steps: expected a positive number of steps");
  if (o.method == Method::Newmark && !(o.gamma >= 0.5 && o.beta >= 0.25 * (0.5 + o.gamma) * (0.5 + o.gamma) - 1e-15))
    throw std::invalid_argument("beta, gamma: expected the unconditionally stable range gamma >= 1/2, "
                                "beta >= (gamma + 1/2)^2 / 4, got beta = " + num(o.beta) + ", gamma = " + num(o.gamma));
  if (o.method == Method::HHT && !(o.alpha >= -1.0 / 3.0 && o.alpha <= 0.0))
    throw std::invalid_argument("alpha: expected a value in [-1/3, 0], got " + num(o.alpha));
  if ((o.method == Method::GeneralizedAlpha || o.method == Method::ImplicitSpring) &&
      !(o.rho_inf >= 0.0 && o.rho_inf <= 1.0))
    throw std::invalid_argument("rho_inf: expected a value in [0, 1], got " + num(o.rho_inf));
  const Method stiff = o.stiff_method;
  if (o.method == Method::Auto && (!method_info(stiff).error_estimate || stiff == Method::Dopri5 ||
                                   stiff == Method::RKF45 || stiff == Method::Auto))
    throw std::invalid_argument(std::string("stiff_method: expected an implicit method with an error estimate, got '") +
                                method_name(stiff) + "'");
  for (Eigen::Index k = 0; k < t_eval.size(); ++k)
    if (!(t_eval(k) >= t0 && t_eval(k) <= t_end) || (k > 0 && !(t_eval(k) > t_eval(k - 1))))
      throw std::invalid_argument("t_eval: expected increasing times within [t0, t_end]");
}

Trajectory integrate(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
                     const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o, const Monitor& monitor) {
  check_options(sys, t0, t_end, q0, qd0, t_eval, o);
  const auto start = Clock::now();
  Trajectory traj;
  VecX last_q = q0;
  // The long phases within a step (ω_max, tangents, Newton, GMRES) ask the monitor too.
  InterruptScope interrupt([&] {
    if (monitor && !monitor(traj.t.empty() ? t0 : traj.t.back())) throw Interrupted();
  });
  try {
    run(sys, t0, t_end, q0, qd0, t_eval, o, monitor, traj, last_q);
  } catch (const Interrupted&) {
    traj.interrupted = true;
  } catch (const SimulationError& e) {
    traj.error = std::make_exception_ptr(explained(e, sys, q0, last_q, o));
  } catch (...) {
    traj.error = std::current_exception();  // from a callback: the caller decides (Ctrl-C: partial result)
  }
  traj.stats.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
  return traj;
}

}  // namespace rigidfem
