// The explicit Runge–Kutta family from Butcher tableaus, and the symplectic Euler rule.
#include <algorithm>
#include <cmath>
#include <vector>

#include "rigidfem/arms.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/sensitivities.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

namespace {

/// y = [q, q̇, s, S_1 .. S_P] as a first-order system ẏ = [q̇, q̈(t, q, q̇, s), ṡ(q̇, s), Ṡ_1 .. Ṡ_P] (s the Maxwell
/// arms' forces, arms.hpp; S_j = [∂q/∂p_j, ∂q̇/∂p_j] the forward sensitivities, sensitivities.hpp), counting
/// evaluations.
class FirstOrder {
 public:
  FirstOrder(const System& sys, const IntegratorOptions& o, IntegratorStats& stats)
      : sys_(sys), d_(sys), stats_(stats) {
    if (!o.sensitivities.empty()) sens_ = std::make_unique<SensitivityEquations>(sys, o.sensitivities);
  }
  void eval(double t, const VecX& y, VecX& ydot) {
    if (!y.allFinite())
      throw SimulationError(t, "the state became NaN or inf: the step was unstable");
    ++stats_.rhs_evaluations;
    const int n = sys_.nq, nz = sys_.nz;
    ydot.resize(y.size());
    ydot.head(n) = y.segment(n, n);
    set_arm_forces(sys_, d_, y.segment(2 * n, nz));
    ydot.segment(n, n) = forward_dynamics(sys_, d_, t, y.head(n), y.segment(n, n));
    arm_rates(sys_, y.segment(n, n), y.segment(2 * n, nz), ydot.segment(2 * n, nz));
    if (!sens_) return;
    const int k = state_size();
    sens_->rates(d_, t, y.head(n), y.segment(n, n), y.tail(y.size() - k), ydot.tail(y.size() - k));
  }
  /// [q, q̇] of y onto the loops' constraint manifold at t (closure residual <= 1e-12), and the
  /// sensitivities onto its tangent there.
  void project(double t, VecX& y) {
    const int n = sys_.nq;
    VecX q = y.head(n), qd = y.segment(n, n);
    project_onto_loops(sys_, d_, t, q, qd, 1e-12, 10);
    y.head(n) = q, y.segment(n, n) = qd;
    for (int j = 0; sens_ && j < sens_->count(); ++j) sens_->project(j, t, q, qd, y.segment(state_size() + 2 * n * j, 2 * n));
  }
  int controlled() const { return 2 * sys_.nq; }  ///< the error is controlled on y's first 2 nq: [q, q̇]
  int state_size() const { return 2 * sys_.nq + sys_.nz; }  ///< [q, q̇, s]; the sensitivities follow
  /// The sensitivities' blocks, each [S_q, S_q̇] (symplectic Euler's rule treats them as [q, q̇]).
  int sensitivity_count() const { return sens_ ? sens_->count() : 0; }

 private:
  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  std::unique_ptr<SensitivityEquations> sens_;
};

struct Tableau {
  std::vector<double> c;
  std::vector<std::vector<double>> a;  // a[i][j], j < i
  std::vector<double> b;               // propagated solution
  std::vector<double> e;               // error estimate b − b̂ (empty: fixed step only)
  int order;                           // order of the propagated solution
  bool fsal;                           // last stage is f(t + h, y1)
};

const Tableau& tableau(Method method) {
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
  // Bogacki & Shampine (1989) 3(2), FSAL (SciPy's RK23): e = b − b̂ with b̂ = (7/24, 1/4, 1/3, 1/8).
  static const Tableau bs23{{0.0, 0.5, 0.75, 1.0},
                            {{}, {0.5}, {0.0, 0.75}, {2.0 / 9, 1.0 / 3, 4.0 / 9}},
                            {2.0 / 9, 1.0 / 3, 4.0 / 9, 0.0},
                            {-5.0 / 72, 1.0 / 12, 1.0 / 9, -1.0 / 8},
                            3,
                            true};
  switch (method) {
    case Method::Euler:
    case Method::SymplecticEuler: return euler;
    case Method::RK4: return rk4;
    case Method::Dopri5: return dopri5;
    case Method::RKF45: return rkf45;
    case Method::BS23: return bs23;
    default: throw std::logic_error("tableau: not an explicit Runge-Kutta method");
  }
}

/// One explicit step y0 -> y1 with its dense output: a Runge–Kutta tableau, or the
/// semi-implicit (symplectic) Euler rule.
class RungeKutta final : public Stepper {
 public:
  RungeKutta(const System& sys, const IntegratorOptions& o, Method method, IntegratorStats& stats)
      : ode_(sys, o, stats), tab_(tableau(method)), k_(tab_.b.size()), dopri_(method == Method::Dopri5),
        rkf_(method == Method::RKF45), symplectic_(method == Method::SymplecticEuler) {}

  void start(double t0, const VecX& y0) override {
    t_start_ = t0;
    y_ = y0;
    ode_.eval(t0, y_, f_);
  }

  /// Hairer's starting step for a method of order p (the whole span when nothing moves, nq = 0).
  double initial_step(double span, const Tolerances& tol, double max_step) override {
    if (y_.size() == 0) return std::min(span, max_step);
    const int p = tab_.order;
    const int m = ode_.controlled();
    const VecX sc = tol.atol.array() + tol.rtol.array() * y_.head(m).cwiseAbs().array();
    const double d0 = scaled_rms(y_.head(m), sc), d1 = scaled_rms(f_.head(m), sc);
    // 1e-6 s where either is negligible, or where a component of zero weight moves (d1 infinite: atol = 0)
    double h0 = (d0 < 1e-5 || d1 < 1e-5 || !std::isfinite(d1)) ? 1e-6 : 0.01 * d0 / d1;
    h0 = std::min({h0, max_step, span});
    VecX f1;
    ode_.eval(t_start_ + h0, y_ + h0 * f_, f1);
    const double d2 = scaled_rms(f1.head(m) - f_.head(m), sc) / h0;
    const double dm = std::max(d1, d2);
    // dm is infinite when a component with zero weight (atol = 0, starting at zero) moves: start small.
    const double h1 = dm <= 1e-15         ? std::max(1e-6, 1e-3 * h0)
                      : std::isfinite(dm) ? std::pow(0.01 / dm, 1.0 / (p + 1))
                                          : 1e-3 * h0;
    return std::min({100.0 * h0, h1, max_step, span});
  }

  bool attempt(double t, double h, const Tolerances* tol, double& err) override {
    t0_ = t, h_ = h, y0_ = y_, f0_ = f_;
    err = 0.0;
    if (symplectic_) {
      // q̇_{n+1} = q̇_n + h q̈(t_n, q_n, q̇_n), then q_{n+1} = q_n + h q̇_{n+1} (and s by Euler).
      const int n = ode_.controlled() / 2;
      y1_ = y0_ + h * f0_;
      y1_.head(n) = y0_.head(n) + h * y1_.segment(n, n);
      for (int j = 0; j < ode_.sensitivity_count(); ++j) {  // their [S_q, S_q̇] alike
        const int k = ode_.state_size() + 2 * n * j;
        y1_.segment(k, n) = y0_.segment(k, n) + h * y1_.segment(k + n, n);
      }
      ode_.eval(t + h, y1_, f1_);
      return true;
    }
    const int s = static_cast<int>(tab_.b.size());
    k_[0] = f0_;
    VecX yi;
    // k_i = f(t + c_i h, y0 + h Σ_j a_ij k_j)
    for (int i = 1; i < s; ++i) {
      yi = y0_;
      for (int j = 0; j < i; ++j)
        if (tab_.a[i][j] != 0.0) yi += (h * tab_.a[i][j]) * k_[j];
      ode_.eval(t + tab_.c[i] * h, yi, k_[i]);
      if (dopri_ && i == 5) y_stage6_ = yi;
      if (rkf_ && i == 4) y_stage_ = yi;
    }
    // y1 = y0 + h Σ b_i k_i
    y1_ = y0_;
    for (int i = 0; i < s; ++i)
      if (tab_.b[i] != 0.0) y1_ += (h * tab_.b[i]) * k_[i];
    if (tab_.fsal)
      f1_ = k_[s - 1];
    else
      ode_.eval(t + h, y1_, f1_);
    // Hairer's estimate of h ρ (ρ the dominant eigenvalue) from two evaluations at t + h: dopri5's
    // stages 6 and 7, rkf45's stage 5 (c₅ = 1) and f(t + h, y1).
    if (dopri_ || rkf_) {
      const VecX& ya = dopri_ ? y_stage6_ : y_stage_;
      const VecX& ka = dopri_ ? k_[5] : k_[4];
      const VecX& kb = dopri_ ? k_[6] : f1_;
      const int m = ode_.controlled();
      const double den = (y1_ - ya).head(m).squaredNorm();
      h_rho_ = den > 0.0 ? h * std::sqrt((kb - ka).head(m).squaredNorm() / den) : 0.0;
    }
    if (dopri_) {
      // Shampine's continuous extension of order 4 (as in Hairer's dopri5).
      static const double d[7] = {-12715105075.0 / 11282082432.0, 0.0, 87487479700.0 / 32700410799.0,
                                  -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                                  -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0};
      rcont5_ = VecX::Zero(y0_.size());
      for (int i = 0; i < 7; ++i)
        if (d[i] != 0.0) rcont5_ += (h * d[i]) * k_[i];
    }
    if (tab_.e.empty() || !tol) return true;
    VecX e = VecX::Zero(y0_.size());
    for (int i = 0; i < s; ++i)
      if (tab_.e[i] != 0.0) e += (h * tab_.e[i]) * k_[i];
    const int m = ode_.controlled();
    err = tol->norm(e.head(m), y0_.head(m), y1_.head(m), h);
    return true;
  }

  void accept() override {
    y_ = y1_;
    f_ = f1_;
  }

  const VecX& state() const override { return y_; }

  void project(double t) override {
    ode_.project(t, y_);
    ode_.eval(t, y_, f_);  // the next step starts from the projected state
  }

  VecX dense(double t) const override {
    const double theta = (t - t0_) / h_;
    if (!dopri_) return hermite(theta, h_, y0_, f0_, y1_, f1_);
    const VecX dy = y1_ - y0_, r3 = h_ * f0_ - dy, r4 = dy - h_ * f1_ - r3;
    return y0_ + theta * (dy + (1.0 - theta) * (r3 + theta * (r4 + (1.0 - theta) * rcont5_)));
  }

  double h_rho() const override { return h_rho_; }
  /// rkf45's stability boundary on the negative real axis is at h ρ = 3.02 (dopri5's 3.31).
  StepControl control() const override {
    return {std::min(tab_.order, 5), 10.0, true, 1.0, 1.0, 0.0, rkf_ ? 2.95 : 3.25};
  }

 private:
  FirstOrder ode_;
  const Tableau& tab_;
  std::vector<VecX> k_;
  bool dopri_, rkf_, symplectic_;
  double t_start_ = 0, t0_ = 0, h_ = 1, h_rho_ = 0;
  VecX y_, f_;                             // the current state and ẏ there
  VecX y0_, y1_, f0_, f1_, rcont5_, y_stage6_, y_stage_;  // the last attempted step
};

}  // namespace

std::unique_ptr<Stepper> make_runge_kutta(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) {
  return std::make_unique<RungeKutta>(sys, o, o.method == Method::Auto ? Method::Dopri5 : o.method, stats);
}

const std::vector<MethodInfo>& runge_kutta_methods() {
  static const std::vector<MethodInfo> rows = {
      {Method::Euler, "euler", "explicit Runge-Kutta", 1, false, false, false, false, method_options(false, false),
       "explicit Euler, order 1", make_runge_kutta, nullptr},
      {Method::SymplecticEuler, "symplectic_euler", "explicit Runge-Kutta", 1, false, false, false,
       false, method_options(false, false), "semi-implicit Euler (q̇ first, then q), order 1", make_runge_kutta, nullptr},
      {Method::RK4, "rk4", "explicit Runge-Kutta", 4, false, false, false, false, method_options(false, false),
       "classical Runge–Kutta, order 4", make_runge_kutta, nullptr},
      {Method::Dopri5, "dopri5", "explicit Runge-Kutta", 5, true, true, false,
       false, method_options(true, false, {"stiffness_warning"}), "Dormand–Prince 5(4), dense output of order 4",
       make_runge_kutta, nullptr},
      {Method::RKF45, "rkf45", "explicit Runge-Kutta", 4, true, true, false,
       false, method_options(true, false, {"stiffness_warning"}), "Runge–Kutta–Fehlberg 4(5) (the book's), 4th order kept",
       make_runge_kutta, nullptr},
      {Method::BS23, "bs23", "explicit Runge-Kutta", 3, true, true, false, false, method_options(true, false),
       "Bogacki–Shampine 3(2) (SciPy's RK23): 3 evaluations a step (FSAL), 3rd order propagated, cubic Hermite dense "
       "output",
       make_runge_kutta, nullptr},
  };
  return rows;
}

}  // namespace rigidfem
