/// Time integration of A(q) q̈ = f(q, q̇, t) in C++ (book ch. 5.2): no Python per step.
///
/// Explicit methods integrate the first-order form y = [q, q̇], ẏ = [q̇, q̈]; the Newmark
/// family integrates the second-order form directly with Newton iterations on
/// M(q) q̈ − f(q, q̇, t) = 0. Every failure raises SimulationError with t, h and the cause.
/// The methods are listed once, in the table of integrate.cpp (stepper.hpp says how to add one).
#pragma once

#include <exception>
#include <functional>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "rigidfem/error_measure.hpp"
#include "rigidfem/events.hpp"
#include "rigidfem/sensitivities.hpp"
#include "rigidfem/system.hpp"

namespace rigidfem {

enum class Method {
  Euler,             ///< explicit Euler, order 1, fixed step
  SymplecticEuler,   ///< semi-implicit Euler (q̇ first, then q), order 1, fixed step
  RK4,               ///< classical Runge–Kutta, order 4, fixed step
  Dopri5,            ///< Dormand–Prince 5(4), adaptive
  RKF45,             ///< Runge–Kutta–Fehlberg 4(5), adaptive
  BS23,              ///< Bogacki–Shampine 3(2), adaptive
  Dop853,            ///< Dormand–Prince 8(5,3), adaptive
  Newmark,           ///< Newmark β, γ, Newton
  HHT,               ///< Hilber–Hughes–Taylor α
  GeneralizedAlpha,  ///< Chung–Hulbert generalised-α with ρ∞
  ImplicitSpring,    ///< generalised-α with the O(n) Newton matrix M + diag(γ'h b + β'h² c)
  Esdirk43,          ///< ESDIRK4(3)6L[2]SA (Kennedy & Carpenter), order 4, L-stable, adaptive
  Radau5,            ///< Radau IIA, 3 stages, order 5, L-stable, adaptive
  Gauss6,            ///< Gauss–Legendre, 3 stages, order 6, symmetric, A-stable, fixed step
  Radau9,            ///< Radau IIA, 5 stages, order 9, L-stable, adaptive
  /// dopri5 while it is the faster, `stiff_method` (adaptive) while that is: where dopri5's steps look
  /// bounded by stability, the stiff method runs a trial and keeps the run if it does less work per simulated second.
  Auto,
};
/// The method called `name` ("dopri5", ...); std::invalid_argument listing the methods otherwise. The methods and
/// their facts are listed once, in the method table (stepper.hpp).
Method parse_method(const std::string& name);
const char* method_name(Method method);

/// The implicit methods' Newton matrix: Tangent, M + γ'h ∂r/∂q̇ + β'h² ∂r/∂q (analytic for recursive
/// systems, factorised densely; γh and (γh)² for the ESDIRK's stages); Spring, M + diag(γ'h b + β'h² c)
/// (the sde springs and dampers as armature of the articulated-body algorithm: O(n)); Krylov, the
/// tangent applied matrix-free and solved by GMRES preconditioned with the spring matrix (recursive
/// systems, O(n) per iteration: newton_matrix.hpp); Auto, Spring for implicit_spring, else Krylov for
/// recursive systems of more than krylov_from_nq coordinates and Tangent below.
enum class IterationMatrix { Auto, Tangent, Spring, Krylov };
IterationMatrix parse_iteration_matrix(const std::string& name);
const char* iteration_matrix_name(IterationMatrix matrix);

struct IntegratorOptions {
  Method method = Method::Dopri5;
  double dt = 0.0;           ///< s: the step of fixed-step methods (first step of adaptive ones if > 0)
  /// Step-size control: dopri5/rkf45 by their embedded pair (default), the Newmark family by
  /// a local error estimate (off by default); false runs every method at the fixed step dt.
  int adaptive = -1;         ///< −1: the method's default, 0: fixed step dt, 1: adaptive
  VecX rtol = VecX::Constant(1, 1e-6);  ///< (1) or (2 nq): per component of y = [q, q̇]
  VecX atol = VecX::Constant(1, 1e-9);  ///< (1) or (2 nq)
  double max_step = std::numeric_limits<double>::infinity();
  long max_steps = 1000000;
  double beta = 0.25, gamma = 0.5;  ///< Newmark (average acceleration by default)
  double alpha = -0.05;             ///< HHT-α, in [−1/3, 0]
  double rho_inf = 0.8;             ///< generalised-α: spectral radius at infinite frequency, in [0, 1]
  double newton_tol = 1e-10;        ///< Newton: increments below newton_tol (1 + |q|), relative for adaptive runs
  /// The run's length t_end − t0 (s), set by integrate(): the Newmark family holds what Newton leaves in q̇
  /// to a fraction of its local error over it (0: to newton_tol alone).
  double span = 0.0;
  int newton_max_iterations = 10;
  /// dopri5 and rkf45: whether the Python layer warns (RuntimeWarning) when Hairer's stiffness test fires
  /// (stats.stiff_at is recorded either way).
  bool stiffness_warning = true;
  IterationMatrix iteration_matrix = IterationMatrix::Auto;
  /// auto: the implicit method it hands over to; Auto: auto_stiff_method's choice (radau5, or esdirk43 with
  /// Maxwell arms or the spring matrix)
  Method stiff_method = Method::Auto;
  VecX s0;  ///< (nz) the Maxwell arms' initial forces (N or N·m, arms.hpp); empty: relaxed, zero
  /// The outputs an adaptive method measures its local error on (error_measure.hpp), held to the
  /// scalars atol and rtol; empty: every component of the state [q, q̇] to its atol_i + rtol_i |y_i|.
  std::vector<OutputSpec> error_on;
  /// Forward sensitivities (sensitivities.hpp) integrated with the state by the explicit Runge–Kutta methods
  /// and the Newmark family; their error is not controlled (the steps are the state's).
  std::vector<SensitivityParameter> sensitivities;
  /// Functions whose roots the run locates (events.hpp): recorded in Trajectory::events, terminal ones end the run.
  std::vector<EventSpec> events;
};

/// An option's value as the Python layer gives and shows it: none, a number, an integer, a flag, a name or
/// numbers (a tolerance per component).
using OptionValue = std::variant<std::monostate, double, long, bool, std::string, std::vector<double>>;

/// How the Python layer writes an option: a real number, an integer, True or False, a name, a number or 2 nq of
/// them (rtol, atol), or outputs (error_on: points, bodies, coordinates, ... converted by the Python layer).
enum class OptionType { Real, Integer, Flag, Name, Reals, Outputs };

/// One option of integrate(), described once: its name, how it is written, its unit and what it does. Its
/// default is get(IntegratorOptions{}), the struct's own initialiser; `simulate(**options)`,
/// rigidfem.integrator_options, simulate's docstring and the site's table of options are read from here, and
/// which methods read it from the method table (MethodInfo::options).
struct OptionInfo {
  const char* name;
  OptionType type;
  const char* unit;
  const char* expected;  ///< what it takes, for the messages ("a positive finite step in s")
  const char* doc;
  bool none_allowed;  ///< None is a value (the method's default, or "not given")
  OptionValue (*get)(const IntegratorOptions&);
  /// Stores a value (its type converted by the bindings; its range judged by check_options and the families'
  /// checks); null for Outputs, which the Python layer converts (IntegratorOptions::error_on).
  void (*set)(IntegratorOptions&, const OptionValue&);
};
/// The options, each once.
const std::vector<OptionInfo>& integrator_options();
/// The option called `name`; std::invalid_argument listing them otherwise.
const OptionInfo& option_info(const std::string& name);

struct IntegratorStats {
  std::string method;  ///< what ran: the method's name, or for auto what it chose (auto_description)
  long steps = 0, rejected = 0, rhs_evaluations = 0, jacobians = 0, factorizations = 0, newton_iterations = 0;
  long linear_iterations = 0;  ///< GMRES iterations of a Krylov Newton matrix (each one residual evaluation)
  double wall_time = 0.0;  ///< s
  /// dopri5 only: first time (s) Hairer's stiffness test fired (h ρ > 3.25 over 15 accepted
  /// steps: the step is bounded by stability, not accuracy), NaN if never.
  double stiff_at = std::numeric_limits<double>::quiet_NaN();
  /// auto: the time (s) its stiff method took over for the rest of the run, NaN if the run ended on dopri5.
  double switched_at = std::numeric_limits<double>::quiet_NaN();
  long event_restarts = 0;  ///< steps taken again to end at a root that restarts (a contact's onset or separation)
  long auto_trials = 0;  ///< auto: trials of its stiff method (a lost trial returns to dopri5)
  /// auto: the spectral radius of y' = (q̇, q̈)'s Jacobian at t0 (rad/s; ω_max for an undamped
  /// structure), NaN for the other methods.
  double omega_max = std::numeric_limits<double>::quiet_NaN();
  long probe_steps = 0;  ///< auto: dopri5's steps before its stiff method restarted from t0 (0: no probe)
  /// The model's size L (m) that a relative tolerance on points and bodies refers to (error_on), NaN without.
  double model_size = std::numeric_limits<double>::quiet_NaN();
};

/// States at the output times (every accepted step when no output times are given).
struct Trajectory {
  std::vector<double> t;
  std::vector<VecX> q, qd;  // (len t) x (nq)
  std::vector<VecX> s;      // (len t) x (nz) the Maxwell arms' forces; empty without arms
  /// (len t) x (nl) the multipliers the method solved for itself at each output (Stepper::multipliers:
  /// the Newmark family's), a row of size 0 where it has none (the forward dynamics' then stand).
  std::vector<VecX> lambda;
  /// (len t) x (2 nq P) the sensitivities [S_q, S_q̇] of each parameter in turn; empty rows without them.
  std::vector<VecX> sensitivities;
  std::vector<EventRecord> events;  ///< the roots located, in time order
  IntegratorStats stats;
  bool interrupted = false;  ///< the monitor asked to stop: the trajectory ends early
  /// The exception that ended the run early — a SimulationError (numerical failure, max_steps),
  /// or one thrown by a user callback (a Python drive, force law or monitor: KeyboardInterrupt) —
  /// or null. The trajectory then holds the outputs of the steps accepted before it.
  std::exception_ptr error;
};

/// Called about every 0.05 s of wall time with the current time; returning false stops
/// the run (Ctrl-C), which then returns what it has.
using Monitor = std::function<bool(double)>;

/// Whether error_on's default for this run is the bodies' displacements (else the state): the method's row, and
/// for auto its stiff method's (auto_stiff_method).
bool measures_outputs(const System& sys, const IntegratorOptions& o);

/// The options' checks of integrate(): std::invalid_argument naming the first bad one.
void check_options(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
                   const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& o);

/// Integrates from (t0, q0, q̇0) to t_end. Output at `t_eval` (increasing, within
/// [t0, t_end]) by each method's dense output — Dormand–Prince's own continuous extension,
/// cubic Hermite interpolation of y and ẏ otherwise — or at every step if it is empty.
/// Fixed steps land on t0 + k·dt exactly (the last one on t_end). Bad options throw
/// std::invalid_argument; a failure during the run is returned in Trajectory::error with the
/// partial trajectory.
Trajectory integrate(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0,
                     const Eigen::Ref<const VecX>& t_eval, const IntegratorOptions& options, const Monitor& monitor);

}  // namespace rigidfem
