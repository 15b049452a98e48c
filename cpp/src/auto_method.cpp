// method="auto": its stiff method, ω_max at t0, when to hand over, dopri5's tolerances, the hand-over and
// the sentence that says what ran (auto_method.hpp).
#include "rigidfem/auto_method.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rigidfem/arms.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/newton_matrix.hpp"

namespace rigidfem {

Method auto_stiff_method(const System& sys, const IntegratorOptions& o) {
  if (o.stiff_method != Method::Auto) return o.stiff_method;
  return sys.nz == 0 && o.iteration_matrix != IterationMatrix::Spring ? Method::Radau5 : Method::Esdirk43;
}

Method auto_explicit_method(const IntegratorOptions& o) {
  return o.rtol.size() && o.rtol.minCoeff() <= 1e-6 ? Method::Dop853 : Method::Dopri5;
}

std::string auto_description(Method stiff_method, Method explicit_method, const IntegratorStats& st, double t0) {
  const std::string stiff = method_name(stiff_method), dopri5 = method_name(explicit_method);
  const bool switched = std::isfinite(st.switched_at);
  const long lost = st.auto_trials - (switched ? 1 : 0);
  const std::string tried =
      lost ? "; " + std::to_string(lost) + " trial" + (lost != 1 ? "s" : "") + " of " + stiff + " lost" : "";
  if (!switched) return dopri5 + tried;
  if (st.switched_at == t0 && st.probe_steps > 0)
    return stiff + " from the start (a " + dopri5 + " probe of " + std::to_string(st.probe_steps) +
           " steps found the problem stiff)" + tried;
  if (st.switched_at == t0)
    return stiff + " from the start (omega_max = " + num(st.omega_max, 3) + " rad/s: stiff for " + dopri5 + ")" + tried;
  return dopri5 + ", then " + stiff + " from t = " + num(st.switched_at, 6) + " s" + tried;
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

// method="auto": which of its explicit method and its stiff method runs. The explicit method is dopri5, or dop853 at
// rtol <= 1e-6 (auto_explicit_method; below, "dopri5" stands for either: dop853's work per unit of time at its
// stability boundary, 6/12 evaluations, is dopri5's 3.3/6, so the rules are the same, its steps counted near the
// boundary from h ρ > 3.6 instead of 2). Three ways to the stiff method:
//  - from t0 at once, when dopri5 would need `direct_steps` or more for stability alone, span ρ/3.3
//    with ρ the Jacobian's spectral radius at t0 (spectral_radius);
//  - from t0 after a probe: dopri5's first window of `window` accepted steps holds a fifth at the
//    stability boundary (h ρ > 2), within `probe` steps and a fifth of the run. dopri5's state at its
//    stability boundary carries errors ~ the tolerance in the stiff modes, which an undamped beam keeps
//    ringing and the stiff method's error control then resolves (measured on Kane's beam at rtol = 1e-3:
//    597 esdirk43 steps over t = 0.2-5 s from dopri5's state, 15 from the initial one), so the stiff
//    method starts again from the initial state. When it reaches the time the probe reached it must have
//    advanced `margin` times as far per unit of work as the probe did, or dopri5 goes on from there;
//  - from the state reached, when a later window of dopri5 looks stiff (a fifth of its steps near
//    the stability boundary), after waiting `backoff` windows (doubled by a lost probe trial).
//    Rejected steps are no sign of stiffness: a non-stiff motion that turns sharply rejects steps too, and
//    counting a sixth as many rejections as steps handed such runs to radau5 at a loss (CPU time at rtol 1e-4:
//    a double pendulum 1.68 ms against dopri5's 0.75, the Bricard linkage 11.4 against 6.8 ms; on a chain of six
//    stiff springs over 0.05 s, whose steps stay at h ρ <= 0.67, it gained nothing: 1.69 against 1.75 ms at 1e-5).
// A hand-over is final. (Judging it too — over its first 26 steps against dopri5's last window or, from
// t0, against dopri5's best rate 3.3/ρ per 6 evaluations, and every 100 steps after — was measured on
// the benchmark's five scenes at rtol = 1e-1, 3e-2, 1e-2, 1e-4, 1e-6: trials were lost and repeated up
// to 9 times, 8 of the 25 runs took 1.11-1.48 times as long, 4 (the stiff 3D cantilever at rtol <= 3e-2)
// 0.61-0.81 times.) Work is counted, not timed, so the choice is the same on every run and machine: one unit per right-hand side (or residual) evaluation, nq per tangent (the analytic
// derivatives cost about nq evaluations) and max(1, (nq/50)²) per dense factorisation (one for the O(n) one;
// a Krylov tangent's evaluations are residuals, counted as such).
//
// dopri5 holds the state whatever the outputs, at rtol <= 1e-3 (atol scaled alike): looser, its error control
// lets the stiff modes of a beam go unstable (measured: the classical cantilever at rtol = 1e-2 ... 1e-1); an
// explicit method's stability rests on its error control, and a mode that no output sees would grow unseen
// until it does. The stiff method holds the tolerances as asked (on outputs where asked).
AutoChoice::AutoChoice(const System& sys, const IntegratorOptions& o, const Tolerances& asked, double t0,
                       const VecX& y0, IntegratorStats& stats)
    : sys_(sys), o_(o), asked_(asked), explicit_(auto_explicit_method(o)), t0_(t0), span_(asked.span), y0_(y0) {
  o_.stiff_method = auto_stiff_method(sys, o);
  near_ = explicit_ == Method::Dop853 ? 3.6 : 2.0;
  const int n = sys.nq;
  const double loosest = asked.rtol.size() ? asked.rtol.maxCoeff() : 0.0;  // nq = 0: no tolerance to tighten
  const double tighten = loosest > loosest_explicit ? loosest_explicit / loosest : 1.0;
  explicit_tol_ = asked.scaled(tighten);
  if (asked.measure) {
    explicit_tol_.measure = nullptr;
    explicit_tol_.atol = tighten * (o.atol.size() == 1 ? VecX::Constant(2 * n, o.atol(0)) : o.atol);
  }
  stats.omega_max = spectral_radius(sys, t0, y0.head(n), y0.segment(n, n), y0.segment(2 * n, sys.nz), stats.rhs_evaluations);
  IntegratorOptions stiff = o_;
  stiff.method = o_.stiff_method;
  direct_ = std::isfinite(stats.omega_max) && span_ * stats.omega_max >= direct_steps * dopri5_stability;
  krylov_ = krylov_tangent(sys, stiff);
}

IntegratorOptions AutoChoice::first(IntegratorStats& stats) {
  // on a stiff problem its stiff method from t0 for the whole run (h = 0: no dopri5 step to go back to)
  if (direct_) return switched(t0_, 0.0, stats);
  IntegratorOptions explicit_options = o_;
  explicit_options.method = explicit_;
  return explicit_options;
}

bool AutoChoice::after_step(double t, double h_rho, const IntegratorStats& stats) {
  if (stiff_running_) {  // final, unless it is the restarted probe trial and has lost to the probe
    if (!restarted_ || t < probe_end_) return false;
    restarted_ = false;
    const bool kept = (t - t_mark_) / std::max(work(stats) - work_mark_, 1.0) >= margin * probe_rate_;
    if (!kept) backoff_ *= 2;
    return !kept;
  }
  if (h_rho > near_) ++near_boundary_;
  if (++steps_ < window) return false;
  // Only steps at the stability boundary count, never rejections (see the rules above): dop853's long steps are
  // cut where the motion turns sharply (the Bricard linkage through its singular configuration at t = 4 s: a window
  // of 20 steps with 7 rejected, which once handed the run to radau5 at 7 times dop853's cost), dopri5's alike
  const bool near = near_boundary_ * 5 >= window;
  const bool trial = near && (first_window_ || ++windows_since_trial_ >= backoff_);
  first_window_ = false;
  mark(t, stats);
  return trial;
}

AutoChoice::HandOver AutoChoice::hand_over(double t, double h, const VecX& y, IntegratorStats& stats) {
  const VecX y1 = y;  // the state the other method goes on from (its own controller grows its step)
  const IntegratorOptions next = switched(t, h, stats);
  HandOver r{method_info(next.method).make(sys_, next, stats), h, false};
  if (restart(stats)) {  // the stiff method from the start: dopri5 was a probe
    stats.probe_steps = stats.steps;
    switched_at(t0_, stats);
    r.stepper->start(t0_, y0_);
    r.from_start = true;
    r.h = r.stepper->initial_step(span_, asked_, o_.max_step);
  } else {
    r.stepper->start(t, y1);
  }
  if (!stiff_running_) r.h = h_explicit_;  // dopri5 again after a lost trial: its last step
  return r;
}

/// The options of the method the run changes to, at time t; h: dopri5's step, to go on with should the
/// stiff method lose.
IntegratorOptions AutoChoice::switched(double t, double h, IntegratorStats& stats) {
  stiff_running_ = !stiff_running_;
  IntegratorOptions next = o_;
  next.adaptive = 1;
  next.method = stiff_running_ ? o_.stiff_method : explicit_;
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

/// Whether the trial just started should start from the initial state: the first, after at most
/// `probe` dopri5 steps over at most a fifth of the run (a longer probe is not thrown away; a tenth
/// until the stiff method started at once from 200 stability-bound steps instead of 500: a window of
/// 20 steps at the stability limit then spans more than a tenth of any run below that).
bool AutoChoice::restart(const IntegratorStats& stats) const {
  return stiff_running_ && stats.auto_trials == 1 && stats.steps <= probe && t_mark_ - t0_ <= 0.2 * span_;
}

/// The trial starts at t0 instead (restart): it will be measured when it reaches the time the probe
/// reached, against the probe's rate over the same interval (all the work so far).
void AutoChoice::switched_at(double t0, IntegratorStats& stats) {
  stats.switched_at = t0;
  restarted_ = true;
  probe_end_ = t_mark_;
  probe_rate_ = (t_mark_ - t0) / std::max(work_mark_, 1.0);
  mark(t0, stats);
}

/// The work done so far, in right-hand-side evaluations (see the rules above).
double AutoChoice::work(const IntegratorStats& s) const {
  const double n = sys_.nq;
  const double factorization = spring_ ? 1.0 : std::max(1.0, (n / 50.0) * (n / 50.0));
  const double tangent = krylov_ ? 0.0 : n;
  return static_cast<double>(s.rhs_evaluations) + tangent * static_cast<double>(s.jacobians) +
         factorization * static_cast<double>(s.factorizations);
}

/// A new window from t: its time and work measured from here, its steps counted from 0.
void AutoChoice::mark(double t, const IntegratorStats& stats) {
  t_mark_ = t, work_mark_ = work(stats);
  steps_ = 0, near_boundary_ = 0;
}

}  // namespace rigidfem
