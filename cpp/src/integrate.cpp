// The integration loop shared by every method, the method table and the checks of the options.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "rigidfem/arms.hpp"
#include "rigidfem/auto_method.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/error_measure.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/kinematics.hpp"
#include "rigidfem/newton_matrix.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

namespace {

const char* iteration_matrices[] = {"auto", "tangent", "spring", "krylov"};

using Clock = std::chrono::steady_clock;

// auto's own checks: its stiff method is an implicit one with an error estimate, and takes what that method takes
// (its family's checks: the collocation methods no Maxwell arms, radau9 no sensitivities, ...).
void check_auto(const System& sys, const IntegratorOptions& o) {
  const Method stiff = auto_stiff_method(sys, o);
  const MethodInfo& m = method_info(stiff);
  if (!m.error_estimate || std::string(m.family) == "explicit Runge-Kutta" || stiff == Method::Auto)
    throw std::invalid_argument(std::string("stiff_method: expected an implicit method with an error estimate, got '") +
                                m.name + "'");
  if (m.check) {
    IntegratorOptions as_run = o;
    as_run.method = stiff;
    try {
      m.check(sys, as_run);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("stiff_method: auto's stiff method '") + m.name + "' refuses the run (" +
                                  e.what() + ")");
    }
  }
}

}  // namespace

std::vector<const char*> method_options(bool error_estimate, bool newton, std::initializer_list<const char*> own) {
  std::vector<const char*> names = error_estimate
                                       ? std::vector<const char*>{"dt", "rtol", "atol", "error_on", "first_step",
                                                                  "max_step", "max_steps", "adaptive"}
                                       : std::vector<const char*>{"dt", "max_steps"};
  if (newton) names.insert(names.end(), {"newton_tol", "newton_max_iterations", "iteration_matrix"});
  names.insert(names.end(), own);
  return names;
}

const std::vector<MethodInfo>& method_table() {
  static const std::vector<MethodInfo> table = [] {
    std::vector<MethodInfo> rows;
    for (const auto* family : {&runge_kutta_methods(), &newmark_methods(), &implicit_rk_methods()})
      for (const MethodInfo& m : *family) rows.push_back(m);
    // dopri5 and its stiff method (auto_method.hpp): the stiff method's order, error measure and options
    rows.push_back({Method::Auto, "auto", "auto", 5, true, true, true, false, method_options(true, true),
                    "radau5 (esdirk43 with Maxwell arms or the spring matrix) from the start where the highest "
                    "frequency at t0 (stats['omega_max'], by power iteration) would hold dopri5 to 200 steps or more "
                    "for stability alone; otherwise dopri5 (dop853 at rtol <= 1e-6), handing over for good where its steps sit at "
                    "the stability "
                    "limit (from the start if that is in its first window, kept if it beats dopri5's probe by a count "
                    "of work); stats['method'] says what ran",
                    make_runge_kutta, check_auto});
    return rows;
  }();
  return table;
}

const MethodInfo& method_info(Method method) {
  for (const MethodInfo& m : method_table())
    if (m.method == method) return m;
  throw std::logic_error("method_info: a method without a row in the table");
}

Method parse_method(const std::string& name) {
  std::string names;
  for (const MethodInfo& m : method_table()) {
    if (name == m.name) return m.method;
    names += std::string(names.empty() ? "" : ", ") + m.name;
  }
  bad("method", "one of " + names, "'" + name + "'");
}

const char* method_name(Method method) { return method_info(method).name; }

bool measures_outputs(const System& sys, const IntegratorOptions& o) {
  return method_info(o.method == Method::Auto ? auto_stiff_method(sys, o) : o.method).measures_outputs;
}

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
  Recorder(const System& sys, Trajectory& traj, const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o)
      : sys_(sys), traj_(traj), t_eval_(t_eval), nq_(sys.nq) {
    if (sys.nl > 0) d_ = std::make_unique<Data>(sys);
    if (sys.nl > 0 && !o.sensitivities.empty())
      sens_ = std::make_unique<SensitivityEquations>(sys, o.sensitivities);
  }
  /// y = [q, q̇, s, S_1 .. S_P] at t; the stepper's own multipliers there, if any (Stepper::multipliers).
  void push(double t, const VecX& y, const Stepper* stepper = nullptr) {
    traj_.t.push_back(t);
    traj_.lambda.emplace_back();
    if (stepper && !stepper->multipliers(t, traj_.lambda.back())) traj_.lambda.back().resize(0);
    traj_.q.push_back(y.head(nq_));
    traj_.qd.push_back(y.segment(nq_, nq_));
    const int m = 2 * nq_ + sys_.nz;
    traj_.s.push_back(y.segment(2 * nq_, sys_.nz));
    traj_.sensitivities.push_back(y.tail(y.size() - m));
    if (d_) project_onto_loops(sys_, *d_, t, traj_.q.back(), traj_.qd.back(), 1e-12, 10);
    for (int j = 0; sens_ && j < sens_->count(); ++j)
      sens_->project(j, t, traj_.q.back(), traj_.qd.back(), traj_.sensitivities.back().segment(2 * nq_ * j, 2 * nq_));
  }
  void start(double t0, const VecX& y0, const Stepper& stepper) {
    if (t_eval_.size() == 0) {
      push(t0, y0, &stepper);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t0) push(t_eval_(next_++), y0, &stepper);
  }
  /// A terminal event at t (within the last accepted step) with the state y there: the requested times up to t by
  /// dense output, or t itself when every step is recorded; the run ends.
  void end(double t, const VecX& y, const Stepper& stepper) {
    if (t_eval_.size() == 0) {
      push(t, y, &stepper);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t) {
      const double te = t_eval_(next_++);
      push(te, te == t ? y : stepper.dense(te), &stepper);
    }
  }
  /// Forgets every output (a run that starts again from t0).
  void clear() {
    traj_.t.clear(), traj_.q.clear(), traj_.qd.clear(), traj_.s.clear(), traj_.lambda.clear();
    traj_.sensitivities.clear();
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
  std::unique_ptr<SensitivityEquations> sens_;  // with loops: projects the outputs' sensitivities
  Eigen::Index next_ = 0;
};

bool is_adaptive(const IntegratorOptions& o) {
  return o.adaptive >= 0 ? o.adaptive == 1 : method_info(o.method).adaptive;
}


/// The tolerances of a run, `measure` made when the error is measured on outputs (adaptive runs with
/// error_on; its size L into stats.model_size). On outputs, the state's weights (Newton's increments, first
/// steps) take as atol the rotation (rad) that moves a point at the model's far end L by the length
/// tolerance: (atol + rtol L)/L.
Tolerances run_tolerances(const System& sys, const IntegratorOptions& o, double t0, double t_end, const VecX& q0,
                          std::unique_ptr<ErrorMeasure>& measure, IntegratorStats& stats) {
  const int n = sys.nq;
  if (is_adaptive(o) && !o.error_on.empty()) {
    measure = std::make_unique<ErrorMeasure>(sys, o.error_on, t0, q0);
    stats.model_size = measure->length();
  }
  const double state_atol = measure ? (o.atol(0) + o.rtol(0) * measure->length()) / measure->length() : o.atol(0);
  return {o.atol.size() == 1 ? VecX::Constant(2 * n, state_atol) : o.atol,
          o.rtol.size() == 1 ? VecX::Constant(2 * n, o.rtol(0)) : o.rtol,
          t_end - t0,
          measure.get(),
          o.atol(0),
          o.rtol(0)};
}

/// The step-size control of an adaptive run (StepControl's rule) and Hairer's stiffness test.
class StepSizeControl {
 public:
  explicit StepSizeControl(const StepControl& c) : c_(c) {}
  /// After a step of size hs with the error estimate err: whether it is accepted, and the next step
  /// into h — h_new = h · min(growth, max(0.2, 0.9 err^(−β₁/k) err_prev^(β₂/k))), the elementary
  /// controller after a rejection; no growth right after a rejection where the method asks so, and h
  /// kept for small gains where it reuses a matrix.
  bool accepts(double t, double hs, double err, double& h) {
    const double growth = c_.hold_after_reject && rejected_last_ ? 1.0 : c_.growth;
    const double e = std::max(err, 1e-10);
    const double pi = rejected_last_ || !(err <= 1.0)
                          ? std::pow(e, -1.0 / c_.k)
                          : std::pow(e, -c_.beta1 / c_.k) * std::pow(err_prev_, c_.beta2 / c_.k);
    double factor = std::min(growth, std::max(0.2, 0.9 * pi));
    if (factor >= 1.0 && factor < c_.keep_below) factor = 1.0;
    if (!(err <= 1.0)) {
      if (!std::isfinite(err) && hs < 1e-300) step_failure(t, hs, "the error estimate is NaN or inf");
      rejected_last_ = true;
      h = hs * (std::isfinite(err) ? factor : 0.2);
      return false;
    }
    rejected_last_ = false;
    err_prev_ = e;
    h = hs * factor;
    return true;
  }
  /// Hairer's test after an accepted step ending at t1: h ρ above the method's limit over 15 accepted
  /// steps (6 below it forget them) sets stats.stiff_at once.
  void stiffness(double h_rho, double t1, IntegratorStats& stats) {
    if (h_rho > c_.stiff_limit) {
      nonstiff_steps_ = 0;
      if (++stiff_steps_ == 15 && std::isnan(stats.stiff_at)) stats.stiff_at = t1;
    } else if (++nonstiff_steps_ == 6) {
      stiff_steps_ = 0;
    }
  }
  /// Another method goes on (auto): its rule, no history.
  void restart(const StepControl& c) { c_ = c, rejected_last_ = false, err_prev_ = 1.0; }

 private:
  StepControl c_;
  double err_prev_ = 1.0;  // the error estimate of the last accepted step (PI control)
  bool rejected_last_ = false;
  int stiff_steps_ = 0, nonstiff_steps_ = 0;
};

/// After a step cut a hair before roots where the right-hand side changes (contacts' onsets and separations: the
/// cluster of those within 1e-6 of the step of the first) the run goes on from t + τ, the state there by the step's
/// dense output, τ the smallest (from 4ε max(1, |t|), by factors of 4, up to twice the cluster's reach past t or 1e-6
/// of the step h) that puts every one of their functions on its new side. The next step's first stage then takes the
/// new side's right-hand side and its Jacobian (a linear contact's jumps from 0 to k at touch-down: the
/// sensitivities' equations feel it), not the old side's limit; the state moves by O(τ²) against the steps' own
/// errors. Returns the time the run goes on from (t itself where no such τ is found).
double past_root(EventLocator& events, const std::vector<EventRecord>& roots, double t, double h, Stepper& stepper) {
  double reach = 0.0;
  for (const EventRecord& r : roots) reach = std::max(reach, r.located - t);
  const double limit = std::max(1e-6 * h, 2.0 * reach);
  for (double tau = 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)); tau <= limit; tau *= 4.0) {
    const VecX y = stepper.dense(t + tau);
    const bool crossed = std::all_of(roots.begin(), roots.end(), [&](const EventRecord& r) {
      const double g = events.g(r.event, t + tau, y);
      return (g > 0.0 ? 1 : (g < 0.0 ? -1 : 0)) == r.direction;
    });
    if (crossed) {
      stepper.start(t + tau, y);
      return t + tau;
    }
  }
  return t;
}

/// The one loop, into traj: attempt a step, control its size by the error estimate (adaptive runs)
/// or keep to the grid t0 + k·dt (fixed steps), record the outputs it covers, ask the monitor; the
/// last step lands on t_end exactly. last_q: the last accepted coordinates.
void run(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
         const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o, const Monitor& monitor, Trajectory& traj,
         VecX& last_q) {
  auto last_check = Clock::now();
  IntegratorStats& stats = traj.stats;
  Recorder out(sys, traj, t_eval, o);
  const int n = sys.nq;
  const bool adaptive = is_adaptive(o);
  std::unique_ptr<ErrorMeasure> measure;  // the outputs the error is measured on (error_measure.hpp), or none
  const Tolerances asked = run_tolerances(sys, o, t0, t_end, q0, measure, stats);
  const double span = t_end - t0, grid = std::min(o.dt, o.max_step), near_end = t_end - 1e-12 * span;

  VecX y0(2 * n + sys.nz + 2 * n * static_cast<int>(o.sensitivities.size()));
  y0.head(2 * n + sys.nz) << q0, qd0, (o.s0.size() ? o.s0 : VecX::Zero(sys.nz));
  if (!o.sensitivities.empty()) {
    SensitivityEquations sens(sys, o.sensitivities);
    y0.tail(2 * n * sens.count()) = sens.initial();
    for (int j = 0; sys.nl > 0 && j < sens.count(); ++j)  // initial values move along the loops (as assemble() would)
      sens.project(j, t0, q0, qd0, y0.segment(2 * n + sys.nz + 2 * n * j, 2 * n));
  }
  // method="auto": its policy (auto_method.hpp) picks the first method and, after each step, whether to change
  std::unique_ptr<AutoChoice> choice;
  if (o.method == Method::Auto) choice = std::make_unique<AutoChoice>(sys, o, asked, t0, y0, stats);
  IntegratorOptions first = choice ? choice->first(stats) : o;
  first.span = span;
  std::unique_ptr<Stepper> stepper = method_info(first.method).make(sys, first, stats);
  StepSizeControl control(stepper->control());
  stepper->start(t0, y0);
  out.start(t0, stepper->state(), *stepper);
  EventLocator events(sys, o.events, static_cast<int>(o.sensitivities.size()));
  if (!events.empty()) events.start(t0, stepper->state());
  VecX y_start;          // events: the state at the step's start, to take the step again
  double y_start_time = t0;
  bool arrived = false;  // the last step ended before roots that restart
  std::vector<EventRecord> cap;  // roots that restart: the steps end a hair before the first (cap_t)
  double cap_t = 0.0;
  bool capped = false;
  int retaken = 0;       // times the step from the current t was taken again
  const Tolerances* tol = choice ? &choice->tolerances() : &asked;
  double h = o.dt > 0.0 ? std::min(o.dt, span) : stepper->initial_step(span, *tol, o.max_step);

  // A fixed step of an explicit method beyond its stability limit: the state (q, q̇) growing more than 1e10 times in
  // one step (from at least 1 of its units) ends the run, as NaN would a few steps later (an event located in such a
  // step would be noise, not a root)
  const bool blowups = !adaptive && method_info(first.method).make == make_runge_kutta && n > 0;
  const auto size = [&] { return stepper->state().head(2 * n).cwiseAbs().maxCoeff(); };
  double t = t0;
  bool measured = false;  // the measure is linearised at the current state
  while (t < t_end) {
    // The step: to the grid point t0 + k·dt (fixed) or by h (adaptive), to t_end for the last one.
    double hs, t1;
    if (adaptive) {
      hs = std::min({h, o.max_step, t_end - t});
      if (t + hs > near_end) hs = t_end - t;
      t1 = t + hs >= near_end ? t_end : t + hs;
      if (capped && t1 >= cap_t) t1 = cap_t, hs = cap_t - t;  // to the roots the step was cut at
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
    if (!events.empty() && adaptive) y_start = stepper->state(), y_start_time = t;
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
      if (!control.accepts(t, hs, err, h)) {
        ++stats.rejected;
        continue;
      }
      control.stiffness(stepper->h_rho(), t1, stats);
    }
    const double before = blowups ? size() : 0.0;
    stepper->accept();
    if (blowups && size() > 1e10 * std::max(1.0, before))
      throw SimulationError(t, "the fixed step dt = " + num(o.dt) + " s is beyond the stability limit of " +
                                   std::string(method_name(first.method)) + " for this problem: the largest of q and q̇ "
                                   "went from " + num(before) + " to " + num(size()) + " (m, rad, per s) in one step");
    measured = false;
    if (sys.nl > 0) stepper->project(t1);
    if (!events.empty()) {
      const auto dense = [&](double te) { return stepper->dense(te); };
      const std::vector<EventRecord> found =
          events.roots(t, t1, stepper->state(), dense, capped && t1 == cap_t ? &cap : nullptr);
      // the first root inside the step (not within 1e-9 of it from either end) that restarts: the step again from its
      // start, ending there (adaptive runs; a fourth time from the same start, the roots are taken where this step's
      // dense output puts them)
      const double near = 1e-9 * (t1 - t) + 16.0 * std::numeric_limits<double>::epsilon() * std::abs(t1);
      const auto restarts = [&](const EventRecord& r) { return adaptive && events.spec(r.event).restarts; };
      const auto first = std::find_if(found.begin(), found.end(), [&](const EventRecord& r) {
        return restarts(r) && r.t > t + near && r.t < t1 - near;
      });
      if (first != found.end() && retaken < 3) {
        // the step ends a hair (1e-9 of it) before the first root: its last stages stay on the old side, as the
        // dense output has them, whatever the re-taken step's own error. The roots within 1e-6 of the step after it
        // (two contacts touching together, or a user's event on a contact's gap) arrive with it; past_root crosses
        // them all afterwards.
        cap.clear();
        for (const EventRecord& r : found)
          if (restarts(r) && r.t >= first->t && r.t <= first->t + 1e-6 * (t1 - t)) cap.push_back(r);
        cap_t = first->t - std::min(1e-9 * (t1 - t) + 16.0 * std::numeric_limits<double>::epsilon() * std::abs(first->t),
                                    0.5 * (first->t - t));
        capped = true, ++retaken, ++stats.event_restarts;
        stepper->start(t, y_start);
        continue;
      }
      if (capped && t1 == cap_t) capped = false, arrived = true;
      retaken = 0;
      for (const EventRecord& r : found) {
        traj.events.push_back(r);
        if (!events.spec(r.event).terminal) continue;
        ++stats.steps;
        out.end(r.t, r.y, *stepper);
        last_q = r.y.head(n);
        return;
      }
      events.commit();
    }
    t = t1;
    ++stats.steps;
    const VecX& y = stepper->state();
    out.step(t, y, *stepper);
    last_q = y.head(n);
    if (arrived) {
      arrived = false;
      if (t < near_end) t = past_root(events, cap, t, t - y_start_time, *stepper);
    }
    if (choice && choice->after_step(t, stepper->h_rho(), stats)) {  // auto changes method
      AutoChoice::HandOver next = choice->hand_over(t, h, y, stats);
      stepper = std::move(next.stepper);
      control.restart(stepper->control());
      h = next.h;
      tol = &choice->tolerances();
      if (next.from_start) {
        t = t0;
        out.clear();
        out.start(t0, stepper->state(), *stepper);
        last_q = q0;
        traj.events.clear(), capped = false, retaken = 0;
        if (!events.empty()) events.start(t0, stepper->state());
      }
      measured = false;
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
  if (e.cause.rfind("the fixed step dt", 0) == 0) return e;  // the run's own blow-up stop says it already
  const double growth = max_abs(last_q) / std::max(max_abs(q0), 1e-6);
  const bool explicit_method = method_info(o.method).make == make_runge_kutta;
  if (!is_adaptive(o) && explicit_method && (growth > 1e3 || !last_q.allFinite()))
    return SimulationError(e.time, "the fixed step dt = " + num(o.dt) + " s is probably beyond the stability limit of " +
                                       std::string(method_name(o.method)) + " for this problem: the state grew " +
                                       num(growth) + " times, then " + e.cause);
  return SimulationError(e.time, e.cause + gimbal_lock_hint(sys, last_q, 1e-3));
}

/// std::invalid_argument unless the run's sensitivities fit the system (every C++ method integrates them).
void check_sensitivities(const System& sys, const IntegratorOptions& o) {
  if (o.sensitivities.empty()) return;
  if (sys.nz > 0)
    throw std::invalid_argument("sensitivities: not available for a system with Maxwell arms (it has " +
                                std::to_string(sys.nz) + " arm forces as internal variables)");
  for (std::size_t j = 0; j < o.sensitivities.size(); ++j) {
    const SensitivityParameter& p = o.sensitivities[j];
    check_vector(p.S0, 2 * sys.nq, "sensitivities", "2 nq initial sensitivities");
    if (p.plus && !(p.h != 0.0 && std::isfinite(p.h)))
      throw std::invalid_argument("sensitivities: expected a finite non-zero step h, got " + num(p.h));
    if (!p.plus && p.minus) throw std::invalid_argument("sensitivities: expected a system at p + h with one at p - h");
    for (const auto& other : {p.plus, p.minus})
      if (other && (other->nq != sys.nq || other->nbodies != sys.nbodies || other->nl != sys.nl ||
                    other->np != sys.np || other->algorithm != sys.algorithm))
        throw std::invalid_argument("sensitivities: expected systems with this system's coordinates (parameter " +
                                    std::to_string(j) + ")");
  }
}

}  // namespace

namespace {

// The conversions of OptionValue the table's rows use.
double real(const OptionValue& v) { return std::get<double>(v); }
OptionValue step_or_none(double h) { return h > 0.0 ? OptionValue(h) : OptionValue(); }
// A step given (dt, first_step): the options hold 0 for "none", so it must be positive on its way in.
double positive_step(const OptionValue& v, const char* name) {
  const double h = real(v);
  if (!(h > 0.0 && std::isfinite(h))) bad(name, "a positive finite step in s", num(h));
  return h;
}
VecX reals(const OptionValue& v) {
  if (const double* x = std::get_if<double>(&v)) return VecX::Constant(1, *x);
  const auto& x = std::get<std::vector<double>>(v);
  return Eigen::Map<const VecX>(x.data(), static_cast<Eigen::Index>(x.size()));
}

}  // namespace

const std::vector<OptionInfo>& integrator_options() {
  using O = IntegratorOptions;
  using V = const OptionValue&;
  static const std::vector<OptionInfo> table = {
      {"dt", OptionType::Real, "s", "a positive finite step in s",
       "Step of the fixed-step methods: steps end on t0 + k·dt exactly, the last on t_end. Given to an adaptive "
       "method (dopri5, dop853, rkf45, bs23, esdirk43, radau5, auto) it sets only the first step, with a UserWarning saying so "
       "(``adaptive=False`` runs those at fixed steps of dt).",
       true, [](const O& o) { return step_or_none(o.dt); },
       [](O& o, V v) { o.dt = std::holds_alternative<double>(v) ? positive_step(v, "dt") : 0.0; }},
      {"rtol", OptionType::Reals, "1", "a non-negative number or 2 nq of them",
       "Relative tolerance of adaptive runs (float, or (2 nq,) per component of y = [q, q̇] with "
       "``error_on='state'``). On outputs each output's local error is held to atol + rtol × scale: for points and "
       "bodies the model's size L (m, ``stats['model_size']``) or the farthest a centre of mass has moved if larger; "
       "the largest magnitude reached so far for coordinates, element forces and loop reactions. On the state: "
       "atol_i + rtol_i |y_i| (atol = 0: purely relative; an exactly zero component counts as exact). SciPy's methods "
       "raise rtol to their floor 100 ε; scipy:Radau and scipy:BDF take one rtol, the smallest given.",
       false, [](const O& o) { return OptionValue(o.rtol(0)); }, [](O& o, V v) { o.rtol = reals(v); }},
      {"atol", OptionType::Reals, "m, rad (per s for rates)", "a non-negative number or 2 nq of them", "Absolute tolerance of adaptive runs, as rtol.", false,
       [](const O& o) { return OptionValue(o.atol(0)); }, [](O& o, V v) { o.atol = reals(v); }},
      {"error_on", OptionType::Outputs, "", "points, bodies, coordinates, elements or loops",
       "What the adaptive C++ methods measure their local error on (``rigidfem.simulation.error_control``): a list of points "
       "and bodies (their positions, m), coordinate names or indices (m or rad), force element names (their axial "
       "force, N) and loop names (their multipliers, N or N·m), each error mapped from the state's through the "
       "output's Jacobian, a velocity's held as the displacement it makes over the step. None (the default): "
       "'bodies' — every body's displacement, the RMS over its material √(|δc|² + δθᵀ I_C δθ/m) — for radau5, the "
       "adaptive Newmark family and auto's radau5; 'state' for dopri5, dop853, rkf45, bs23, esdirk43 and auto's explicit phase. "
       "A mode that no output sees is not resolved: the L-stable radau5 damps it (the released strip of 1 m, m = 32: "
       "2,800 steps to 1e-6 m instead of 177,000).",
       true, [](const O&) { return OptionValue(); }, nullptr},
      {"first_step", OptionType::Real, "s", "a positive finite step in s", "First step of an adaptive run; estimated (Hairer's rule) by default.",
       true, [](const O&) { return OptionValue(); },
       [](O& o, V v) {
         if (std::holds_alternative<double>(v)) o.dt = positive_step(v, "first_step");
       }},
      {"max_step", OptionType::Real, "s", "a positive step in s (inf for no limit)", "Largest step of an adaptive run.", false,
       [](const O& o) { return OptionValue(o.max_step); }, [](O& o, V v) { o.max_step = real(v); }},
      {"max_steps", OptionType::Integer, "", "a positive number of steps",
       "A run that needs more steps (accepted and rejected) raises SimulationError carrying the partial result.",
       false, [](const O& o) { return OptionValue(o.max_steps); },
       [](O& o, V v) { o.max_steps = std::get<long>(v); }},
      {"adaptive", OptionType::Flag, "", "None, True or False",
       "Step-size control: on by default for dopri5, dop853, rkf45, bs23, esdirk43 and radau5 (False runs them at the fixed "
       "step dt), off by default for the Newmark family (True switches on its local error estimate); auto takes None "
       "or True.",
       true, [](const O& o) { return o.adaptive < 0 ? OptionValue() : OptionValue(o.adaptive == 1); },
       [](O& o, V v) { o.adaptive = std::holds_alternative<bool>(v) ? int(std::get<bool>(v)) : -1; }},
      {"stiffness_warning", OptionType::Flag, "", "True or False",
       "dopri5, dop853 and rkf45 run Hairer's stiffness test (h ρ > 3.25, dop853 6.0, rkf45 2.95, over 15 accepted "
       "steps): the step is "
       "then bounded by stability, so it costs ~t ω_max/3.3 steps, and at loose tolerances the stiff modes keep "
       "errors ~rtol ω_max/ω, or grow. It warns (RuntimeWarning) and records the time in ``stats['stiff_at']``; "
       "False keeps the record and drops the warning.",
       false, [](const O& o) { return OptionValue(o.stiffness_warning); },
       [](O& o, V v) { o.stiffness_warning = std::get<bool>(v); }},
      {"beta", OptionType::Real, "1", "a number", "Newmark's β.", false, [](const O& o) { return OptionValue(o.beta); },
       [](O& o, V v) { o.beta = real(v); }},
      {"gamma", OptionType::Real, "1", "a number", "Newmark's γ.", false, [](const O& o) { return OptionValue(o.gamma); },
       [](O& o, V v) { o.gamma = real(v); }},
      {"alpha", OptionType::Real, "1", "a number", "HHT's α ∈ [−1/3, 0].", false, [](const O& o) { return OptionValue(o.alpha); },
       [](O& o, V v) { o.alpha = real(v); }},
      {"rho_inf", OptionType::Real, "1", "a number", "Generalised-α's spectral radius at infinite frequency ρ∞ ∈ [0, 1].", false,
       [](const O& o) { return OptionValue(o.rho_inf); }, [](O& o, V v) { o.rho_inf = real(v); }},
      {"newton_tol", OptionType::Real, "1", "a positive finite tolerance",
       "Newton stops when the increments of q and q̇ fall below newton_tol (1 + |q|); the Newmark family also holds "
       "them to 0.03 of the step's local error estimate e_q (q̇'s to 0.03 e_q/T, T the run's length), down to "
       "1e-3 newton_tol (1 + |q|) and at least 500 ε (1 + |q|), so that small steps keep the method's order; adaptive "
       "esdirk43 and radau5 runs stop it at 0.03 of the error weights instead; gauss6 holds them to 1e-4 newton_tol "
       "(1 + |q|), or newton_tol where they stop contracting or the iterations run out (its leftovers, of one sign, "
       "would make a conservative system's energy drift).",
       false, [](const O& o) { return OptionValue(o.newton_tol); }, [](O& o, V v) { o.newton_tol = real(v); }},
      {"newton_max_iterations", OptionType::Integer, "", "an integer in [1, 1000000]", "Newton iterations per step (or stage) at most.", false,
       [](const O& o) { return OptionValue(long(o.newton_max_iterations)); },
       [](O& o, V v) { o.newton_max_iterations = static_cast<int>(std::get<long>(v)); }},
      {"iteration_matrix", OptionType::Name, "", "'auto', 'tangent', 'spring' or 'krylov'",
       "Newton matrix of the implicit methods: 'tangent' (the exact tangent M + γ'h ∂r/∂q̇ + β'h² ∂r/∂q, analytic "
       "for recursive systems, dense LU: O(n³)), 'krylov' (the same tangent, never formed: its products are "
       "directional derivatives of the inverse dynamics and its solves GMRES preconditioned by the spring matrix, "
       "O(n) per iteration; recursive systems), 'spring' (the O(n) matrix of implicit_spring: M + diag(γ'h b + β'h² "
       "c)) or 'auto' (spring for implicit_spring, else krylov for a recursive system of more than 200 coordinates "
       "and tangent below). radau5 takes the tangent, dense or krylov. ``stats['linear_iterations']`` counts the "
       "GMRES iterations.",
       false, [](const O& o) { return OptionValue(std::string(iteration_matrix_name(o.iteration_matrix))); },
       [](O& o, V v) { o.iteration_matrix = parse_iteration_matrix(std::get<std::string>(v)); }},
  };
  return table;
}

const OptionInfo& option_info(const std::string& name) {
  std::string names;
  for (const OptionInfo& option : integrator_options()) {
    if (name == option.name) return option;
    names += std::string(names.empty() ? "" : ", ") + option.name;
  }
  bad("name", "an option of the integrators (" + names + ")", "'" + name + "'");
}

void check_options(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
                   const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o) {
  const MethodInfo& m = method_info(o.method);
  if (!std::isfinite(t0)) bad("t0", "a finite start time in s", num(t0));
  if (!std::isfinite(t_end) || !(t_end > t0))
    throw std::invalid_argument("t_end: expected a finite end time after t0 = " + num(t0) + " s, got " + num(t_end));
  check_vector(q0, sys.nq, "q0", "nq");
  // beyond 1e15 a double no longer resolves a step of a tenth: a coordinate's steps drown in its rounding
  for (Eigen::Index k = 0; k < q0.size(); ++k)
    if (std::abs(q0(k)) > 1e15)
      bad("q0", "coordinates within ±1e+15 (m, rad), beyond which a double no longer resolves a step of a tenth (its "
                "spacing is 1/8 at 1e15)",
          num(q0(k)) + " (" + sys.coordinate_names()[k] + ")");
  check_vector(qd0, sys.nq, "qd0", "nq");
  if (!m.error_estimate && o.adaptive == 1) {
    std::string adaptive;
    for (const MethodInfo& other : method_table())
      if (other.error_estimate && other.method != Method::Auto) adaptive += (adaptive.empty() ? "" : ", ") + std::string(other.name);
    throw std::invalid_argument(std::string("adaptive: the method '") + m.name + "' has no error estimate; use " +
                                adaptive);
  }
  if (o.s0.size() != 0) check_vector(o.s0, sys.nz, "s0", "nz (the Maxwell arms' forces, N or N·m)");
  if (o.iteration_matrix == IterationMatrix::Krylov && !articulated(sys))
    throw std::invalid_argument("iteration_matrix: 'krylov' needs a system compiled with algorithm='recursive' (its "
                                "products are the recursive inverse dynamics'); use 'tangent' or 'auto'");
  if (!is_adaptive(o) && !(o.dt > 0.0 && std::isfinite(o.dt)))
    throw std::invalid_argument(std::string("dt: expected a positive step in s for the fixed-step method '") + m.name +
                                "', got " + num(o.dt));
  for (Eigen::Index k = 0; k < t_eval.size(); ++k)
    if (!(t_eval(k) >= t0 && t_eval(k) <= t_end) || (k > 0 && !(t_eval(k) > t_eval(k - 1))))
      throw std::invalid_argument("t_eval: expected increasing times within [t0, t_end] = [" + num(t0) + ", " +
                                  num(t_end) + "] s, got " + num(t_eval(k), 10) + " at index " + std::to_string(k) +
                                  (k > 0 ? " after " + num(t_eval(k - 1), 10) : std::string()));
  // one option at a time first, then the tolerances (whose rtol = atol = 0 is wrong only together)
  if (!(o.max_step > 0.0))
    throw std::invalid_argument("max_step: expected a positive step in s (inf for no limit), got " + num(o.max_step));
  if (o.max_steps < 1)
    throw std::invalid_argument("max_steps: expected a positive number of steps, got " + std::to_string(o.max_steps));
  if (!(o.newton_tol > 0.0 && std::isfinite(o.newton_tol)))
    throw std::invalid_argument("newton_tol: expected a positive finite tolerance, got " + num(o.newton_tol));
  if (o.newton_max_iterations < 1 || o.newton_max_iterations > 1000000)
    throw std::invalid_argument("newton_max_iterations: expected an integer in [1, 1000000], got " +
                                std::to_string(o.newton_max_iterations));
  for (const auto& [tol, name] : {std::pair<const VecX*, const char*>{&o.rtol, "rtol"}, {&o.atol, "atol"}})
    if (tol->size() == 0 || (tol->size() != 1 && tol->size() != 2 * sys.nq) || !(tol->minCoeff() >= 0.0) ||
        !tol->allFinite())
      throw std::invalid_argument(std::string(name) + ": expected a non-negative number or 2 nq = " +
                                  std::to_string(2 * sys.nq) + " of them, got " +
                                  (tol->size() == 1 ? num((*tol)(0)) : std::to_string(tol->size()) + " values") +
                                  (tol->size() > 1 && !(tol->allFinite() && tol->minCoeff() >= 0.0)
                                       ? " (min " + num(tol->minCoeff()) + ")"
                                       : ""));
  if (!o.error_on.empty() && (o.rtol.size() != 1 || o.atol.size() != 1))
    throw std::invalid_argument("rtol, atol: expected one value each with error_on (the tolerances of its outputs), "
                                "got " + std::to_string(o.rtol.size()) + " and " + std::to_string(o.atol.size()));
  if (o.rtol.maxCoeff() == 0.0 && o.atol.minCoeff() == 0.0)
    throw std::invalid_argument("atol: expected positive values when rtol is zero");
  if (m.check) m.check(sys, o);  // the family's own options
  check_sensitivities(sys, o);
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
  traj.stats.method = o.method == Method::Auto ? auto_description(auto_stiff_method(sys, o), auto_explicit_method(o),
                                                                    traj.stats, t0)
                                               : method_name(o.method);
  traj.stats.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
  return traj;
}

}  // namespace rigidfem
