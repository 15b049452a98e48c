/// The one interface of every integration method, and the table that lists them.
///
/// integrate() runs one loop for every method, fixed or adaptive: it asks a Stepper to attempt a
/// step, controls the step size from the error estimate, records outputs by the stepper's dense
/// output and lands on t_end once. To add a method: its Method (integrators.hpp), and in its family's
/// file (runge_kutta.cpp, newmark.cpp, implicit_rk.cpp) its Stepper (or tableau) and its row of
/// MethodInfo; everything else, the Python layer included, reads the row.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "rigidfem/integrators.hpp"

namespace rigidfem {

class ErrorMeasure;

/// What a step's error is held to: per component of y = [q, q̇] (2 nq each) with the weights
/// sc_i = atol_i + rtol_i max(|y0_i|, |y1_i|), or, with a `measure`, on its outputs with the scalars
/// output_atol, output_rtol (error_measure.hpp). span: the run's length t_end − t0 (s), for the methods
/// that control the error per unit step.
struct Tolerances {
  VecX atol, rtol;
  double span = 0.0;
  ErrorMeasure* measure = nullptr;
  double output_atol = 0.0, output_rtol = 0.0;
  /// The scaled norm of the error e = [e_q, e_q̇] (2 nq) of the step y0 → y1 over h (s): on the
  /// outputs, or per component of the state.
  double norm(const VecX& e, const VecX& y0, const VecX& y1, double h) const;
  /// The tolerances scaled by `factor` (atol and rtol alike).
  Tolerances scaled(double factor) const;
};
/// RMS of v_i / sc_i, with 0/0 counted as 0 (an exactly zero component under a pure relative
/// tolerance); 0 for an empty vector (nq = 0).
double scaled_rms(const VecX& v, const VecX& sc);
/// Scaled RMS norm of an error e against the weights atol + rtol max(|y0|, |y1|), per component.
double error_norm(const VecX& e, const VecX& y0, const VecX& y1, const VecX& atol, const VecX& rtol);
/// max |v_i|, 0 for an empty vector.
inline double max_abs(const VecX& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }
/// Cubic Hermite interpolation of y on [t0, t0 + h] at θ = (t − t0)/h from y and ẏ at both ends.
VecX hermite(double theta, double h, const VecX& y0, const VecX& f0, const VecX& y1, const VecX& f1);
/// SimulationError naming the time, the step size and the cause.
[[noreturn]] void step_failure(double t, double h, const std::string& cause);

/// Step-size control of a method whose local error estimate is O(h^k):
/// h_new = h · min(growth, max(0.2, 0.9 err^(−β₁/k) err_prev^(β₂/k))), err_prev the estimate of the
/// last accepted step: the elementary controller (β₁ = 1, β₂ = 0) or a PI controller (Gustafsson:
/// β₁ = 0.7, β₂ = 0.4), the elementary one after a rejection.
struct StepControl {
  int k;
  double growth;           ///< largest growth after an accepted step
  bool hold_after_reject;  ///< no growth on the step after a rejection
  double keep_below;       ///< factors in [1, keep_below) keep h (and an iteration matrix with it)
  double beta1 = 1.0, beta2 = 0.0;  ///< the exponents of the PI controller
  /// Hairer's stiffness test: h ρ above this (just inside the method's stability boundary on the
  /// negative real axis) over 15 accepted steps means the step is bounded by stability.
  double stiff_limit = 3.25;
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  /// Takes the initial state y0 = [q0, q̇0, s0] (2 nq + nz, s the Maxwell arms' forces: arms.hpp) at t0
  /// and evaluates what the method needs there.
  virtual void start(double t0, const VecX& y0) = 0;
  /// A first step (s) for an adaptive run given no dt.
  virtual double initial_step(double span, const Tolerances& tol, double max_step) = 0;
  /// Attempts the step t → t + h from the current state; false if it could not be computed (Newton
  /// did not converge). err: the scaled norm of its error estimate against `tol`, 0 without one or
  /// when tol is null (a fixed-step run).
  virtual bool attempt(double t, double h, const Tolerances* tol, double& err) = 0;
  /// Makes the attempted step the current state.
  virtual void accept() = 0;
  /// The current state y = [q, q̇, s] (2 nq + nz); errors are controlled on [q, q̇].
  virtual const VecX& state() const = 0;
  /// y (2 nq + nz) at a time t within the last accepted step (dense output).
  virtual VecX dense(double t) const = 0;
  /// Systems with loops: moves the current state onto the constraint manifold at t (explicit
  /// methods, whose steps drift off it); the Newmark family satisfies g(q) = 0 in every step.
  virtual void project(double /*t*/) {}
  /// Systems with loops: the multipliers λ (nl) the method itself solved for, at a time t within the last
  /// accepted step; false where the method has none of its own. The Newmark family's (index 3: λ_{n+1}
  /// with q̈_{n+1}, linear between the steps' ends) differ from the forward dynamics' at the output's
  /// state by O(h²); the implicit Runge–Kutta methods take the forward dynamics' at each step's end
  /// (project), so they return false, as do the explicit ones.
  virtual bool multipliers(double /*t*/, VecX& /*lambda*/) const { return false; }
  /// h ρ of the last attempted step (ρ the dominant eigenvalue) where the method estimates it (dopri5,
  /// rkf45: from two stages at t + h), else 0.
  virtual double h_rho() const { return 0.0; }
  virtual StepControl control() const = 0;
};

/// The explicit Runge–Kutta family (runge_kutta.cpp), the Newmark family (newmark.cpp) and the
/// implicit Runge–Kutta methods of high order (implicit_rk.cpp).
std::unique_ptr<Stepper> make_runge_kutta(const System& sys, const IntegratorOptions& o, IntegratorStats& stats);
std::unique_ptr<Stepper> make_newmark(const System& sys, const IntegratorOptions& o, IntegratorStats& stats);
std::unique_ptr<Stepper> make_implicit_rk(const System& sys, const IntegratorOptions& o, IntegratorStats& stats);

/// A row of the method table: what a method is, described once. The Python layer reads it through the bindings
/// (rigidfem.methods(), the options each method reads, Richardson's order of its error estimate, whether it runs
/// at fixed steps by default); nothing outside the table names a method's facts.
struct MethodInfo {
  Method method;
  const char* name;
  const char* family;   ///< "explicit Runge-Kutta", "Newmark", "implicit Runge-Kutta", "auto"
  int order;            ///< order of the propagated solution
  bool error_estimate;  ///< an embedded error estimate: may run adaptive
  bool adaptive;        ///< adaptive by default
  /// error_on's default: the bodies' displacements (true) or the state [q, q̇] (false); auto: its stiff method's
  bool measures_outputs;
  bool adjoint;  ///< has a discrete adjoint at fixed steps (adjoint.hpp: rigidfem.gradient)
  std::vector<const char*> options;  ///< the options (integrator_options()) it reads
  const char* doc;      ///< the scheme, in a line or two (the site's table of methods)
  std::unique_ptr<Stepper> (*make)(const System&, const IntegratorOptions&, IntegratorStats&);
  /// The family's own checks of the options it reads (std::invalid_argument naming the first bad one); may be null.
  void (*check)(const System&, const IntegratorOptions&);
};
/// The families' rows (one list per family file) and the table of every method, auto last.
const std::vector<MethodInfo>& runge_kutta_methods();
const std::vector<MethodInfo>& newmark_methods();
const std::vector<MethodInfo>& implicit_rk_methods();
const std::vector<MethodInfo>& method_table();
const MethodInfo& method_info(Method method);

/// The options a method reads: dt and max_steps (every method), step-size control's with an error estimate (rtol,
/// atol, error_on, first_step, max_step, adaptive), Newton's for an implicit method (newton_tol,
/// newton_max_iterations, iteration_matrix), and its own.
std::vector<const char*> method_options(bool error_estimate, bool newton, std::initializer_list<const char*> own = {});

}  // namespace rigidfem
