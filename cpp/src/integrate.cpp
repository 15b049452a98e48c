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
    {Method::Auto, "auto", 5, true, true, make_runge_kutta},  // dopri5 and its stiff method (auto_method.hpp)
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
  const Tolerances* tol = choice ? &choice->tolerances() : &asked;
  double h = o.dt > 0.0 ? std::min(o.dt, span) : stepper->initial_step(span, *tol, o.max_step);

  double t = t0;
  bool measured = false;  // the measure is linearised at the current state
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
      if (!control.accepts(t, hs, err, h)) {
        ++stats.rejected;
        continue;
      }
      control.stiffness(stepper->h_rho(), t1, stats);
    }
    stepper->accept();
    measured = false;
    if (sys.nl > 0) stepper->project(t1);
    t = t1;
    ++stats.steps;
    const VecX& y = stepper->state();
    out.step(t, y, *stepper);
    last_q = y.head(n);
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
  if ((o.method == Method::Radau5 || (o.method == Method::Auto && auto_stiff_method(sys, o) == Method::Radau5)) &&
      sys.nz > 0)
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
  if (o.method == Method::Newmark && !(o.gamma >= 0.5 && o.beta >= 0.25 * (0.5 + o.gamma) * (0.5 + o.gamma) - 1e-15))
    throw std::invalid_argument("beta, gamma: expected the unconditionally stable range gamma >= 1/2, "
                                "beta >= (gamma + 1/2)^2 / 4, got beta = " + num(o.beta) + ", gamma = " + num(o.gamma));
  if (o.method == Method::HHT && !(o.alpha >= -1.0 / 3.0 && o.alpha <= 0.0))
    throw std::invalid_argument("alpha: expected a value in [-1/3, 0], got " + num(o.alpha));
  if ((o.method == Method::GeneralizedAlpha || o.method == Method::ImplicitSpring) &&
      !(o.rho_inf >= 0.0 && o.rho_inf <= 1.0))
    throw std::invalid_argument("rho_inf: expected a value in [0, 1], got " + num(o.rho_inf));
  const Method stiff = auto_stiff_method(sys, o);
  if (o.method == Method::Auto && (!method_info(stiff).error_estimate || stiff == Method::Dopri5 ||
                                   stiff == Method::RKF45 || stiff == Method::Auto))
    throw std::invalid_argument(std::string("stiff_method: expected an implicit method with an error estimate, got '") +
                                method_name(stiff) + "'");
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
  traj.stats.method = o.method == Method::Auto ? auto_description(auto_stiff_method(sys, o), traj.stats, t0)
                                               : method_name(o.method);
  traj.stats.wall_time = std::chrono::duration<double>(Clock::now() - start).count();
  return traj;
}

}  // namespace rigidfem
