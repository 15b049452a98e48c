#include "rigidfem/integrators.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rigidfem/errors.hpp"
#include "rigidfem/derivatives.hpp"
#include "rigidfem/lagrange.hpp"
#include "rigidfem/recursive.hpp"

namespace rigidfem {

namespace {

using Clock = std::chrono::steady_clock;

std::string num(double x) {
  std::ostringstream o;
  o.precision(6);
  o << x;
  return o.str();
}

[[noreturn]] void fail(double t, double h, const std::string& cause) {
  throw SimulationError(t, cause + " (step size h = " + num(h) + " s)");
}

/// y = [q, q̇] as a first-order system ẏ = [q̇, q̈(t, q, q̇)], counting evaluations.
class FirstOrder {
 public:
  FirstOrder(const System& sys, IntegratorStats& stats) : sys_(sys), d_(sys), stats_(stats) {}
  void eval(double t, const VecX& y, VecX& ydot) {
    if (!y.allFinite()) throw SimulationError(t, "the state became NaN or inf: the step was unstable");
    ++stats_.rhs_evaluations;
    const int n = sys_.nq;
    ydot.resize(2 * n);
    ydot.head(n) = y.tail(n);
    ydot.tail(n) = forward_dynamics(sys_, d_, t, y.head(n), y.tail(n));
  }

 private:
  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
};

/// Scaled RMS norm of an error e against the weights atol + rtol max(|y0|, |y1|), per component.
double error_norm(const VecX& e, const VecX& y0, const VecX& y1, const VecX& atol, const VecX& rtol) {
  const VecX sc = atol.array() + rtol.array() * y0.cwiseAbs().cwiseMax(y1.cwiseAbs()).array();
  return std::sqrt((e.array() / sc.array()).square().mean());
}

/// Cubic Hermite interpolation of y on [t0, t0 + h] from y and ẏ at both ends.
VecX hermite(double theta, double h, const VecX& y0, const VecX& f0, const VecX& y1, const VecX& f1) {
  const double t2 = theta * theta, t3 = t2 * theta;
  return (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + theta) * h * f0 + (-2 * t3 + 3 * t2) * y1 +
         (t3 - t2) * h * f1;
}

// ---------------------------------------------------------------------------------------
// Explicit Runge–Kutta methods from their Butcher tableaus.

struct Tableau {
  std::vector<double> c;
  std::vector<std::vector<double>> a;  // a[i][j], j < i
  std::vector<double> b;               // propagated solution
  std::vector<double> e;               // error estimate b − b̂ (empty: fixed step only)
  int order;                           // order of the propagated solution
  bool fsal;                           // last stage is f(t + h, y1)
};

const Tableau& tableau(const std::string& method) {
  static const Tableau euler{{0.0}, {{}}, {1.0}, {}, 1, false};
  static const Tableau rk4{{0.0, 0.5, 0.5, 1.0},
                           {{}, {0.5}, {0.0, 0.5}, {0.0, 0.0, 1.0}},
                           {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6},
                           {},
                           4,
                           false};
  // Dormand & Prince (1980) 5(4), FSAL; error coefficients e = b − b̂.
  static const Tableau dopri5{
      {0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0},
      {{},
       {0.2},
       {3.0 / 40, 9.0 / 40},
       {44.0 / 45, -56.0 / 15, 32.0 / 9},
       {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
       {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
       {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}},
      {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0.0},
      {71.0 / 57600, 0.0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525, -1.0 / 40},
      5,
      true};
  // Runge–Kutta–Fehlberg 4(5) as in the book: the 4th-order solution is propagated.
  static const Tableau rkf45{
      {0.0, 0.25, 3.0 / 8, 12.0 / 13, 1.0, 0.5},
      {{},
       {0.25},
       {3.0 / 32, 9.0 / 32},
       {1932.0 / 2197, -7200.0 / 2197, 7296.0 / 2197},
       {439.0 / 216, -8.0, 3680.0 / 513, -845.0 / 4104},
       {-8.0 / 27, 2.0, -3544.0 / 2565, 1859.0 / 4104, -11.0 / 40}},
      {25.0 / 216, 0.0, 1408.0 / 2565, 2197.0 / 4104, -0.2, 0.0},
      {25.0 / 216 - 16.0 / 135, 0.0, 1408.0 / 2565 - 6656.0 / 12825, 2197.0 / 4104 - 28561.0 / 56430, -0.2 + 9.0 / 50,
       -2.0 / 55},
      4,
      false};
  if (method == "euler" || method == "symplectic_euler") return euler;
  if (method == "rk4") return rk4;
  if (method == "dopri5") return dopri5;
  return rkf45;
}

/// One explicit step y0 -> y1 with its dense output: a Runge–Kutta tableau, or the
/// semi-implicit (symplectic) Euler rule.
class ExplicitRK {
 public:
  ExplicitRK(FirstOrder& ode, const std::string& method)
      : ode_(ode), tab_(tableau(method)), k_(tab_.b.size()), dopri_(method == "dopri5"),
        symplectic_(method == "symplectic_euler") {}

  int order() const { return tab_.order; }
  double h_rho() const { return h_rho_; }  ///< dopri5: h ρ of the last step (0 otherwise)

  /// Fills y1, f1 = ẏ(t + h, y1) and returns the error norm (0 without an estimate).
  double step(double t, double h, const VecX& y0, const VecX& f0, VecX& y1, VecX& f1, const VecX& atol,
              const VecX& rtol) {
    t0_ = t, h_ = h, y0_ = y0, f0_ = f0;
    if (symplectic_) {
      // q̇_{n+1} = q̇_n + h q̈(t_n, q_n, q̇_n), then q_{n+1} = q_n + h q̇_{n+1}.
      const int n = static_cast<int>(y0.size()) / 2;
      y1 = y0;
      y1.tail(n) += h * f0.tail(n);
      y1.head(n) += h * y1.tail(n);
      ode_.eval(t + h, y1, f1);
      y1_ = y1, f1_ = f1;
      return 0.0;
    }
    const int s = static_cast<int>(tab_.b.size());
    k_[0] = f0;
    VecX yi;
    // k_i = f(t + c_i h, y0 + h Σ_j a_ij k_j)
    for (int i = 1; i < s; ++i) {
      yi = y0;
      for (int j = 0; j < i; ++j)
        if (tab_.a[i][j] != 0.0) yi += (h * tab_.a[i][j]) * k_[j];
      ode_.eval(t + tab_.c[i] * h, yi, k_[i]);
      if (dopri_ && i == 5) y_stage6_ = yi;
    }
    // y1 = y0 + h Σ b_i k_i
    y1 = y0;
    for (int i = 0; i < s; ++i)
      if (tab_.b[i] != 0.0) y1 += (h * tab_.b[i]) * k_[i];
    if (tab_.fsal)
      f1 = k_[s - 1];
    else
      ode_.eval(t + h, y1, f1);
    y1_ = y1, f1_ = f1;
    if (dopri_) {
      // Hairer's estimate of h ρ (ρ the dominant eigenvalue) from stages 6 and 7, both at t + h.
      const double den = (y1 - y_stage6_).squaredNorm();
      h_rho_ = den > 0.0 ? h * std::sqrt((k_[6] - k_[5]).squaredNorm() / den) : 0.0;
    }
    if (dopri_) {
      // Shampine's continuous extension of order 4 (as in Hairer's dopri5).
      static const double d[7] = {-12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
                                  -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                                  -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0};
      rcont5_ = VecX::Zero(y0.size());
      for (int i = 0; i < 7; ++i)
        if (d[i] != 0.0) rcont5_ += (h * d[i]) * k_[i];
    }
    if (tab_.e.empty()) return 0.0;
    VecX err = VecX::Zero(y0.size());
    for (int i = 0; i < s; ++i)
      if (tab_.e[i] != 0.0) err += (h * tab_.e[i]) * k_[i];
    return error_norm(err, y0, y1, atol, rtol);
  }

  /// y at time t within the last step.
  VecX dense(double t) const {
    const double theta = (t - t0_) / h_;
    if (!dopri_) return hermite(theta, h_, y0_, f0_, y1_, f1_);
    const VecX dy = y1_ - y0_, r3 = h_ * f0_ - dy, r4 = dy - h_ * f1_ - r3;
    return y0_ + theta * (dy + (1.0 - theta) * (r3 + theta * (r4 + (1.0 - theta) * rcont5_)));
  }

 private:
  FirstOrder& ode_;
  const Tableau& tab_;
  std::vector<VecX> k_;
  bool dopri_, symplectic_;
  double t0_ = 0, h_ = 1, h_rho_ = 0;
  VecX y0_, y1_, f0_, f1_, rcont5_, y_stage6_;
};

// ---------------------------------------------------------------------------------------
// The Newmark family in the generalised-α form of Arnold & Brüls (2007): the equations
// of motion hold at t_{n+1}, M(q_{n+1}) q̈_{n+1} = f(q_{n+1}, q̇_{n+1}, t_{n+1}), and a
// pseudo-acceleration a carries the method:
//   (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q̈_{n+1} + α_f q̈_n,
//   q_{n+1} = q_n + h q̇_n + h² [(½ − β) a_n + β a_{n+1}],
//   q̇_{n+1} = q̇_n + h [(1 − γ) a_n + γ a_{n+1}].
// Newmark: α_m = α_f = 0; HHT-α: α_m = 0, α_f = −α; generalised-α from ρ∞ (Chung & Hulbert).

struct NewmarkState {
  VecX q, v, qdd, a;
};

class NewmarkFamily {
 public:
  NewmarkFamily(const System& sys, IntegratorStats& stats, const IntegratorOptions& o)
      : sys_(sys),
        d_(sys),
        stats_(stats),
        tol_(o.newton_tol),
        max_it_(o.newton_max_iterations),
        recursive_(sys.algorithm == Algorithm::Recursive),
        spring_(o.iteration_matrix == "spring" || (o.iteration_matrix == "auto" && o.method == "implicit_spring")),
        armature_(sys.nq) {
    if (o.method == "newmark") {
      am_ = af_ = 0.0;
      beta_ = o.beta;
      gamma_ = o.gamma;
    } else if (o.method == "hht") {
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
  NewmarkState start(double t, const VecX& q, const VecX& v) {
    ++stats_.rhs_evaluations;
    const VecX qdd = forward_dynamics(sys_, d_, t, q, v);
    return {q, v, qdd, qdd};
  }

  /// Newton iterations for q̈_{n+1}; false when they do not converge.
  bool step(double t, double h, const NewmarkState& s, NewmarkState& s1) {
    const double bp = beta_ * (1.0 - af_) / (1.0 - am_), gp = gamma_ * (1.0 - af_) / (1.0 - am_);
    // Attempts: the kept iteration matrix; a fresh one (if it was old); Newton proper, the
    // tangent rebuilt at every iterate (spring: its matrix is always fresh, one attempt).
    for (int attempt = 0; attempt < 3; ++attempt) {
      if (attempt > 0 && spring_) return false;
      if (attempt == 1 && fresh_) continue;
      valid_ = valid_ && attempt == 0;
      full_newton_ = attempt == 2;
      // Predictor: no displacement beyond q̇_n h (a_{n+1} = −(½ − β)/β a_n), so a stiff
      // mode's large acceleration does not throw the first iterate far off.
      const VecX a1 = (-(0.5 - beta_) / beta_) * s.a;
      s1.qdd = ((1.0 - am_) * a1 - af_ * s.qdd + am_ * s.a) / (1.0 - af_);
      double previous = std::numeric_limits<double>::infinity();
      for (int it = 0; it < max_it_; ++it) {
        update(h, s, s1);
        const VecX r = residual(t + h, s1);
        const VecX dx =
            spring_ ? spring_correction(t + h, h, r, bp, gp) : tangent_correction(t + h, h, r, bp, gp, it == 0);
        ++stats_.newton_iterations;
        if (!dx.allFinite()) break;
        s1.qdd += dx;
        // Converged when the position and velocity errors left are negligible: the increments
        // times η = θ/(1 − θ) once a contraction rate θ < 1 is seen (the sum of the remaining
        // increments of a contraction; Hairer & Wanner IV.8), the increments themselves before.
        const double size = dx.cwiseAbs().maxCoeff();
        const double eta = it >= 1 && size < previous ? (size / previous) / (1.0 - size / previous) : 1.0;
        const double dq = eta * bp * h * h * size, dv = eta * gp * h * size;
        if (dq <= tol_ * (1.0 + s1.q.cwiseAbs().maxCoeff()) && dv <= tol_ * (1.0 + s1.v.cwiseAbs().maxCoeff())) {
          update(h, s, s1);
          if (it > 4) valid_ = false;  // slow convergence: refresh the iteration matrix next step
          fresh_ = false;
          return true;
        }
        if (it >= 2 && size > 2.0 * previous) break;  // diverging
        // A tangent from another state (an earlier step or the predictor) converging slowly:
        // rebuild it at the next iterate (Newton proper).
        if (!spring_ && ((it >= 1 && size > 0.5 * previous) || full_newton_)) valid_ = false;
        previous = size;
      }
    }
    return false;
  }

  /// Local error estimate of q over the step, h² (β − 1/6)(a_{n+1} − a_n).
  VecX error_estimate(double h, const NewmarkState& s, const NewmarkState& s1) const {
    return (h * h * (beta_ - 1.0 / 6.0)) * (s1.a - s.a);
  }

 private:
  void update(double h, const NewmarkState& s, NewmarkState& s1) const {
    s1.a = ((1.0 - af_) * s1.qdd + af_ * s.qdd - am_ * s.a) / (1.0 - am_);
    s1.q = s.q + h * s.v + (h * h) * ((0.5 - beta_) * s.a + beta_ * s1.a);
    s1.v = s.v + h * ((1.0 - gamma_) * s.a + gamma_ * s1.a);
  }

  /// r = M(q) q̈ − f(q, q̇, t) at the iterate (inverse dynamics: O(n) for recursive systems).
  VecX residual(double t, const NewmarkState& s1) {
    set_state(sys_, d_, t, s1.q, s1.v);
    set_accelerations(sys_, d_, s1.qdd);
    kinematics(sys_, d_, !recursive_);  // the Lagrange forces need T̈; RNEA needs T and U only
    ++stats_.rhs_evaluations;
    return inverse_dynamics(sys_, d_);
  }

  /// Newton: −S⁻¹ r with the tangent S = M + γ' h ∂r/∂q̇ + β' h² ∂r/∂q, kept while h stays
  /// within 30 % of its own (it only steers the iterations).
  VecX tangent_correction(double t, double h, const VecX& r, double bp, double gp, bool predictor) {
    if (!valid_ || std::abs(h / h_ - 1.0) > 0.3) {
      // At the iterate of residual(); at the predictor with q̈ = 0: there the inertia term
      // ∂(M q̈)/∂q of a stiff mode's far-off q̈ steers worse than leaving it to the iterations
      // (measured on a stiff 3D beam at h = 2e-3 s), while near the solution it makes Newton's
      // convergence quadratic.
      if (predictor) set_accelerations(sys_, d_, VecX::Zero(sys_.nq));
      auto [drdq, drdqd] = inverse_dynamics_derivatives(sys_, d_);
      mass_matrix(sys_, d_);
      ++stats_.jacobians;
      ++stats_.factorizations;
      if (!recursive_) stats_.rhs_evaluations += 4 * sys_.nq;  // the central differences
      lu_.compute(d_.A + (gp * h) * drdqd + (bp * h * h) * drdq);
      // The reciprocal condition number, not the determinant, which under- or overflows for large n.
      if (!(lu_.rcond() > 1e-15))
        throw SimulationError(t, "the Newton iteration matrix M + γh C + βh² K is singular (step size h = " + num(h) +
                                     " s)");
      valid_ = true;
      fresh_ = true;
      h_ = h;
    }
    return -lu_.solve(r);
  }

  /// The O(n) step: −(M + diag(γ' h b + β' h² c))⁻¹ r, the springs c and dampers b of the
  /// coordinates entering like joint armature in the articulated-body recursion (the rest
  /// of the tangent, geometric and gyroscopic, is left to the iterations).
  VecX spring_correction(double t, double h, const VecX& r, double bp, double gp) {
    for (int k = 0; k < sys_.nq; ++k) {
      const Coordinate& c = sys_.coords[sys_.free_coords[k]];
      armature_(k) = gp * h * c.damping + bp * h * h * c.stiffness;
    }
    ++stats_.factorizations;
    if (recursive_) {  // residual() left the spatial kinematics of the iterate in d_
      aba_factor(sys_, d_, armature_);
      VecX dx = -r;
      aba_solve(sys_, d_, dx, dx);
      return dx;
    }
    mass_matrix(sys_, d_);
    d_.A.diagonal() += armature_;
    d_.llt.compute(d_.A);
    if (d_.llt.info() != Eigen::Success) throw SimulationError(t, "the mass matrix is not positive definite");
    return -d_.llt.solve(r);
  }

  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  double tol_;
  int max_it_;
  bool recursive_, spring_;
  VecX armature_;
  double am_ = 0, af_ = 0, beta_ = 0.25, gamma_ = 0.5;
  Eigen::PartialPivLU<MatX> lu_;
  bool valid_ = false, fresh_ = false, full_newton_ = false;
  double h_ = 0.0;
};

// ---------------------------------------------------------------------------------------
// Output at requested times (or every step) and the monitor.

class Recorder {
 public:
  Recorder(Trajectory& traj, const VecX& t_eval, int nq) : traj_(traj), t_eval_(t_eval), nq_(nq) {}
  void push(double t, const VecX& y) {
    traj_.t.push_back(t);
    traj_.q.push_back(y.head(nq_));
    traj_.qd.push_back(y.tail(nq_));
  }
  void start(double t0, const VecX& y0) {
    if (t_eval_.size() == 0) {
      push(t0, y0);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t0) push(t_eval_(next_++), y0);
  }
  /// After an accepted step ending at t1: the requested times in (t0, t1] by dense output.
  template <class Dense>
  void step(double t1, const VecX& y1, Dense&& dense) {
    if (t_eval_.size() == 0) {
      push(t1, y1);
      return;
    }
    while (next_ < t_eval_.size() && t_eval_(next_) <= t1) {
      const double t = t_eval_(next_++);
      push(t, t == t1 ? y1 : dense(t));
    }
  }

 private:
  Trajectory& traj_;
  const VecX& t_eval_;
  int nq_;
  Eigen::Index next_ = 0;
};

bool is_newmark(const IntegratorOptions& o) {
  return o.method == "newmark" || o.method == "hht" || o.method == "generalized_alpha" || o.method == "implicit_spring";
}

bool is_adaptive(const IntegratorOptions& o) {
  if (o.adaptive >= 0) return o.adaptive == 1;
  return o.method == "dopri5" || o.method == "rkf45";
}

void check_options(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0, const VecX& t_eval,
                   const IntegratorOptions& o) {
  static const char* methods[] = {"euler", "symplectic_euler", "rk4", "dopri5", "rkf45", "newmark", "hht",
                                  "generalized_alpha", "implicit_spring"};
  if (std::find(std::begin(methods), std::end(methods), o.method) == std::end(methods))
    throw std::invalid_argument("method: expected one of euler, symplectic_euler, rk4, dopri5, rkf45, newmark, hht, "
                                "generalized_alpha, implicit_spring, got '" + o.method + "'");
  if (o.iteration_matrix != "auto" && o.iteration_matrix != "tangent" && o.iteration_matrix != "spring")
    throw std::invalid_argument("iteration_matrix: expected 'auto', 'tangent' or 'spring', got '" + o.iteration_matrix +
                                "'");
  if (!std::isfinite(t0) || !std::isfinite(t_end) || !(t_end > t0))
    throw std::invalid_argument("t_end: expected a finite end time after t0 = " + num(t0) + " s, got " + num(t_end));
  if (q0.size() != sys.nq || !q0.allFinite())
    throw std::invalid_argument("q0: expected " + std::to_string(sys.nq) + " (nq) finite values");
  if (qd0.size() != sys.nq || !qd0.allFinite())
    throw std::invalid_argument("qd0: expected " + std::to_string(sys.nq) + " (nq) finite values");
  const bool fixed = !is_adaptive(o);
  if ((o.method == "euler" || o.method == "symplectic_euler" || o.method == "rk4") && o.adaptive == 1)
    throw std::invalid_argument("adaptive: the method '" + o.method + "' has no error estimate; use dopri5, rkf45 or "
                                "the Newmark family");
  if (fixed && !(o.dt > 0.0 && std::isfinite(o.dt)))
    throw std::invalid_argument("dt: expected a positive step in s for the fixed-step method '" + o.method + "', got " +
                                num(o.dt));
  for (const auto& [tol, name] : {std::pair<const VecX*, const char*>{&o.rtol, "rtol"}, {&o.atol, "atol"}})
    if (tol->size() == 0 || (tol->size() != 1 && tol->size() != 2 * sys.nq) || !(tol->minCoeff() >= 0.0) ||
        !tol->allFinite())
      throw std::invalid_argument(std::string(name) + ": expected non-negative tolerances, one or 2 nq = " +
                                  std::to_string(2 * sys.nq) + " of them");
  if (o.rtol.maxCoeff() == 0.0 && o.atol.minCoeff() == 0.0)
    throw std::invalid_argument("atol: expected positive values when rtol is zero");
  if (!(o.max_step > 0.0)) throw std::invalid_argument("max_step: expected a positive step in s");
  if (o.max_steps < 1) throw std::invalid_argument("max_steps: expected a positive number of steps");
  if (o.method == "newmark" && !(o.gamma >= 0.5 && o.beta >= 0.25 * (0.5 + o.gamma) * (0.5 + o.gamma) - 1e-15))
    throw std::invalid_argument("beta, gamma: expected the unconditionally stable range gamma >= 1/2, "
                                "beta >= (gamma + 1/2)^2 / 4, got beta = " + num(o.beta) + ", gamma = " + num(o.gamma));
  if (o.method == "hht" && !(o.alpha >= -1.0 / 3.0 && o.alpha <= 0.0))
    throw std::invalid_argument("alpha: expected a value in [-1/3, 0], got " + num(o.alpha));
  if ((o.method == "generalized_alpha" || o.method == "implicit_spring") && !(o.rho_inf >= 0.0 && o.rho_inf <= 1.0))
    throw std::invalid_argument("rho_inf: expected a value in [0, 1], got " + num(o.rho_inf));
  for (Eigen::Index k = 0; k < t_eval.size(); ++k)
    if (!(t_eval(k) >= t0 && t_eval(k) <= t_end) || (k > 0 && !(t_eval(k) > t_eval(k - 1))))
      throw std::invalid_argument("t_eval: expected increasing times within [t0, t_end]");
}

/// Hairer's starting step for a method of order p.
double initial_step(FirstOrder& ode, double t0, const VecX& y0, const VecX& f0, const VecX& atol, const VecX& rtol,
                    int p, double max_step, double span) {
  const VecX sc = atol.array() + rtol.array() * y0.cwiseAbs().array();
  const double d0 = std::sqrt((y0.array() / sc.array()).square().mean());
  const double d1 = std::sqrt((f0.array() / sc.array()).square().mean());
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = std::min({h0, max_step, span});
  VecX f1;
  ode.eval(t0 + h0, y0 + h0 * f0, f1);
  const double d2 = std::sqrt((((f1 - f0).array() / sc.array())).square().mean()) / h0;
  const double dm = std::max(d1, d2);
  const double h1 = dm <= 1e-15 ? std::max(1e-6, 1e-3 * h0) : std::pow(0.01 / dm, 1.0 / (p + 1));
  return std::min({100.0 * h0, h1, max_step, span});
}

}  // namespace

namespace {

Trajectory run(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0, const VecX& t_eval,
               const IntegratorOptions& o, const Monitor& monitor, VecX& last_q) {
  const auto start_clock = Clock::now();
  auto last_check = start_clock;
  Trajectory traj;
  IntegratorStats& stats = traj.stats;
  Recorder out(traj, t_eval, sys.nq);
  const int n = sys.nq;
  const VecX atol = o.atol.size() == 1 ? VecX::Constant(2 * n, o.atol(0)) : o.atol;
  const VecX rtol = o.rtol.size() == 1 ? VecX::Constant(2 * n, o.rtol(0)) : o.rtol;
  const bool newmark = is_newmark(o);
  const bool adaptive = is_adaptive(o);
  const double span = t_end - t0;

  // Ask the monitor about every 0.05 s; false means stop (e.g. Ctrl-C).
  auto keep_going = [&](double t) {
    if (!monitor) return true;
    const auto now = Clock::now();
    if (now - last_check < std::chrono::milliseconds(50)) return true;
    last_check = now;
    return monitor(t);
  };
  auto finish = [&]() {
    stats.wall_time = std::chrono::duration<double>(Clock::now() - start_clock).count();
    return traj;
  };
  auto check_budget = [&](double t, double h) {
    if (stats.steps + stats.rejected >= o.max_steps) fail(t, h, "max_steps = " + std::to_string(o.max_steps) + " reached");
    if (h < 16.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)))
      fail(t, h, "the step size fell below the minimum: the problem is too stiff or singular for this method");
  };

  VecX y0(2 * n);
  y0 << q0, qd0;
  double t = t0;
  // An accepted step of size h ending in state y1: advance t (landing on t_end exactly),
  // record the outputs it covers by dense output, ask the monitor; false: interrupted.
  auto accept = [&](double h, const VecX& y1, auto&& dense) {
    t = (t + h >= t_end - 1e-12 * span) ? t_end : t + h;
    ++stats.steps;
    out.step(t, y1, dense);
    last_q = y1.head(n);
    if (keep_going(t)) return true;
    traj.interrupted = true;
    return false;
  };

  if (newmark) {
    NewmarkFamily nm(sys, stats, o);
    NewmarkState s = nm.start(t0, q0, qd0), s1;
    out.start(t0, y0);
    double h = o.dt > 0.0 ? std::min(o.dt, span) : std::min(1e-3 * span, o.max_step);
    while (t < t_end) {
      double hs = std::min({h, o.max_step, t_end - t});
      if (t + hs > t_end - 1e-12 * span) hs = t_end - t;  // land on t_end exactly
      check_budget(t, hs);
      if (!nm.step(t, hs, s, s1)) {
        if (!adaptive) fail(t, hs, "Newton iterations did not converge; reduce dt");
        ++stats.rejected;
        h = 0.25 * hs;
        continue;
      }
      if (!s1.q.allFinite() || !s1.v.allFinite()) fail(t, hs, "the state became NaN or inf");
      if (adaptive) {
        const double err = error_norm(nm.error_estimate(hs, s, s1), s.q, s1.q, atol.head(n), rtol.head(n));
        double factor = std::min(5.0, std::max(0.2, 0.9 * std::pow(std::max(err, 1e-10), -1.0 / 3.0)));
        if (factor >= 1.0 && factor < 1.25) factor = 1.0;  // keep h (and the iteration matrix) for small gains
        if (err > 1.0) {
          ++stats.rejected;
          h = hs * factor;
          continue;
        }
        h = hs * factor;
      }
      VecX ya(2 * n), yb(2 * n), fa(2 * n), fb(2 * n);
      ya << s.q, s.v;
      yb << s1.q, s1.v;
      fa << s.v, s.qdd;
      fb << s1.v, s1.qdd;
      const double ta = t;
      s = s1;
      if (!accept(hs, yb, [&](double tt) { return hermite((tt - ta) / hs, hs, ya, fa, yb, fb); })) break;
    }
    return finish();
  }

  FirstOrder ode(sys, stats);
  VecX f0, y1, f1;
  ode.eval(t0, y0, f0);
  out.start(t0, y0);
  VecX y = y0;

  ExplicitRK rk(ode, o.method);
  double h = adaptive ? (o.dt > 0.0 ? std::min(o.dt, span)
                                    : initial_step(ode, t0, y0, f0, atol, rtol, rk.order(), o.max_step, span))
                      : o.dt;
  bool rejected_last = false;
  int stiff_steps = 0, nonstiff_steps = 0;  // Hairer's stiffness test (dopri5)
  while (t < t_end) {
    double hs = std::min({h, o.max_step, t_end - t});
    if (t + hs > t_end - 1e-12 * span) hs = t_end - t;
    check_budget(t, hs);
    const double err = rk.step(t, hs, y, f0, y1, f1, atol, rtol);
    if (adaptive) {
      // h_new = h · min(f_max, max(0.2, 0.9 err^(−1/(p̂+1)))), p̂ the lower order of the pair.
      const double expo = -1.0 / std::min(rk.order(), 5);
      const double fmax = rejected_last ? 1.0 : 10.0;
      const double factor = std::min(fmax, std::max(0.2, 0.9 * std::pow(std::max(err, 1e-10), expo)));
      if (!(err <= 1.0)) {
        if (!std::isfinite(err) && hs < 1e-300) fail(t, hs, "the error estimate is NaN or inf");
        ++stats.rejected;
        rejected_last = true;
        h = hs * (std::isfinite(err) ? factor : 0.2);
        continue;
      }
      rejected_last = false;
      h = hs * factor;
      if (rk.h_rho() > 3.25) {
        nonstiff_steps = 0;
        if (++stiff_steps == 15 && std::isnan(stats.stiff_at)) stats.stiff_at = t + hs;
      } else if (++nonstiff_steps == 6) {
        stiff_steps = 0;
      }
    }
    y = y1;
    f0 = f1;
    if (!accept(hs, y, [&](double tt) { return rk.dense(tt); })) break;
  }
  return finish();
}

}  // namespace

Trajectory integrate(const System& sys, double t0, double t_end, const VecX& q0, const VecX& qd0, const VecX& t_eval,
                     const IntegratorOptions& o, const Monitor& monitor) {
  check_options(sys, t0, t_end, q0, qd0, t_eval, o);
  VecX last_q = q0;
  try {
    return run(sys, t0, t_end, q0, qd0, t_eval, o, monitor, last_q);
  } catch (const SimulationError& e) {
    // What the last accepted state says about the failure: Euler angles near gimbal lock,
    // or a fixed step beyond the method's stability limit (the state grew by orders of magnitude).
    const double growth = last_q.cwiseAbs().maxCoeff() / std::max(q0.cwiseAbs().maxCoeff(), 1e-300);
    if (!is_adaptive(o) && (growth > 1e3 || !last_q.allFinite()))
      throw SimulationError(e.time, "the fixed step dt = " + num(o.dt) + " s is probably beyond the stability limit of " +
                                        o.method + " for this problem: the state grew " + num(growth) +
                                        " times, then " + e.cause);
    const std::string hint = gimbal_lock_hint(sys, last_q, 1e-3);
    if (hint.empty()) throw;
    throw SimulationError(e.time, e.cause + hint);
  }
}

}  // namespace rigidfem
