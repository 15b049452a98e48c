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
    const int n = sys_.nq, nz = sys_.nz;
    set_arm_forces(sys_, d_, y.segment(2 * n, nz));
    rates(t, y, forward_dynamics(sys_, d_, t, y.head(n), y.segment(n, n)), ydot);
  }
  /// [q, q̇] of y onto the loops' constraint manifold at t (closure residual <= 1e-12), the sensitivities
  /// onto its tangent there, and ydot = f(t, y) at the projected y, for about the price of the projection
  /// (project_and_forward_dynamics).
  void project_and_eval(double t, VecX& y, VecX& ydot) {
    const int n = sys_.nq, nz = sys_.nz;
    VecX q = y.head(n), qd = y.segment(n, n);
    set_arm_forces(sys_, d_, y.segment(2 * n, nz));
    const VecX& qdd = project_and_forward_dynamics(sys_, d_, t, q, qd, 1e-12, 10);
    y.head(n) = q, y.segment(n, n) = qd;
    for (int j = 0; sens_ && j < sens_->count(); ++j) sens_->project(j, t, q, qd, y.segment(state_size() + 2 * n * j, 2 * n));
    rates(t, y, qdd, ydot);
  }
  int controlled() const { return 2 * sys_.nq; }  ///< the error is controlled on y's first 2 nq: [q, q̇]
  bool loops() const { return sys_.nl > 0; }     ///< every accepted step is projected onto the loops (project)
  int state_size() const { return 2 * sys_.nq + sys_.nz; }  ///< [q, q̇, s]; the sensitivities follow
  /// The sensitivities' blocks, each [S_q, S_q̇] (symplectic Euler's rule treats them as [q, q̇]).
  int sensitivity_count() const { return sens_ ? sens_->count() : 0; }

 private:
  /// ydot = [q̇, q̈, ṡ, Ṡ_1 .. Ṡ_P] of y with q̈ the forward dynamics d_ has just evaluated at y.
  void rates(double t, const VecX& y, const VecX& qdd, VecX& ydot) {
    ++stats_.rhs_evaluations;
    const int n = sys_.nq, nz = sys_.nz;
    ydot.resize(y.size());
    ydot.head(n) = y.segment(n, n);
    ydot.segment(n, n) = qdd;
    arm_rates(sys_, y.segment(n, n), y.segment(2 * n, nz), ydot.segment(2 * n, nz));
    if (!sens_) return;
    const int k = state_size();
    sens_->rates(d_, t, y.head(n), y.segment(n, n), y.tail(y.size() - k), ydot.tail(y.size() - k));
  }

  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  std::unique_ptr<SensitivityEquations> sens_;
};

/// Hairer's starting step for a method of order p from (t0, y0), f0 = f(t0, y0) (Hairer, Nørsett & Wanner I,
/// II.4): h0 = 0.01 d0/d1, then h1 = (0.01 / max(d1, d2))^(1/(p+1)) with d2 the change of f over h0, all norms
/// scaled by the tolerances; the whole span when nothing moves (nq = 0).
double hairer_initial_step(FirstOrder& ode, int p, double t0, const VecX& y0, const VecX& f0, double span,
                           const Tolerances& tol, double max_step) {
  if (y0.size() == 0) return std::min(span, max_step);
  const int m = ode.controlled();
  const VecX sc = tol.atol.array() + tol.rtol.array() * y0.head(m).cwiseAbs().array();
  const double d0 = scaled_rms(y0.head(m), sc), d1 = scaled_rms(f0.head(m), sc);
  // 1e-6 s where either is negligible, or where a component of zero weight moves (d1 infinite: atol = 0)
  double h0 = (d0 < 1e-5 || d1 < 1e-5 || !std::isfinite(d1)) ? 1e-6 : 0.01 * d0 / d1;
  h0 = std::min({h0, max_step, span});
  VecX f1;
  ode.eval(t0 + h0, y0 + h0 * f0, f1);
  const double dm = std::max(d1, scaled_rms(f1.head(m) - f0.head(m), sc) / h0);
  // dm is infinite when a component with zero weight (atol = 0, starting at zero) moves: start small.
  const double h1 = dm <= 1e-15         ? std::max(1e-6, 1e-3 * h0)
                    : std::isfinite(dm) ? std::pow(0.01 / dm, 1.0 / (p + 1))
                                        : 1e-3 * h0;
  return std::min({100.0 * h0, h1, max_step, span});
}

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

  double initial_step(double span, const Tolerances& tol, double max_step) override {
    return hairer_initial_step(ode_, tab_.order, t_start_, y_, f_, span, tol, max_step);
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
    // f(t + h, y1), the next step's first stage and the dense output's end slope; a fixed-step method on loops
    // takes it at the projected state instead (project), saving an evaluation a step
    if (tab_.fsal)
      f1_ = k_[s - 1];
    else if (!(ode_.loops() && tab_.e.empty()))
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
    ode_.project_and_eval(t, y_, f_);  // the next step starts from the projected state
    if (tab_.e.empty()) f1_ = f_;  // the dense output's end slope (attempt left it to here)
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

// Dormand & Prince's 8(5,3) (Hairer, Nørsett & Wanner, Solving ODEs I, 2nd ed., II.5 and II.6; Hairer's DOP853): 12
// stages and f(t + h, y1) (FSAL: row 12 is b), then three more (rows 13–15) for the dense output of order 7.
namespace dop853 {
constexpr double c[16] = {0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726,
    0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6, 0.8571428571428571, 1.0, 1.0, 0.1, 0.2,
    0.7777777777777778};
constexpr double a[16][16] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.05260015195876773, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.0197250569845379, 0.0591751709536137, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.02958758547680685, 0.0, 0.08876275643042054, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
     0.0, 0.0},
    {0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
     0.0, 0.0, 0.0},
    {0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
     0.0, 0.0, 0.0},
    {0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402,
     0.008273789163814023, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671, 20.154067550477894,
     -43.48988418106996, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193, 15.279233632882423,
     -33.28821096898486, -0.020331201708508627, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927, -18.52006565999696,
     22.739487099350505, 2.4936055526796523, -3.0467644718982196, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188, 27.94888452941996,
     -2.8589982771350235, -8.87285693353063, 12.360567175794303, 0.6433927460157636, 0.0, 0.0, 0.0, 0.0, 0.0},
    {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585,
     0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259, 0.0, 0.0, 0.0, 0.0},
    {0.056167502283047954, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25350021021662483, -0.2462390374708025, -0.12419142326381637,
     0.15329179827876568, 0.00820105229563469, 0.007567897660545699, -0.008298, 0.0, 0.0, 0.0},
    {0.03183464816350214, 0.0, 0.0, 0.0, 0.0, 0.028300909672366776, 0.053541988307438566, -0.05492374857139099, 0.0,
     0.0, -0.00010834732869724932, 0.0003825710908356584, -0.00034046500868740456, 0.1413124436746325, 0.0, 0.0},
    {-0.42889630158379194, 0.0, 0.0, 0.0, 0.0, -4.697621415361164, 7.683421196062599, 4.06898981839711,
     0.3567271874552811, 0.0, 0.0, 0.0, -0.0013990241651590145, 2.9475147891527724, -9.15095847217987, 0.0},
};
constexpr double b[12] = {0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003,
    -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259};
// the embedded estimators of orders 5 and 3: b − b̂ of each (13 stages, the FSAL one included)
constexpr double e5[13] = {0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502,
    1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294, 0.0};
constexpr double e3[13] = {-0.18980075407240762, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003,
    -5.801203960010585, -0.4226823213237919, -0.1521609496625161, 0.20136540080403034, 0.02265179219836082, 0.0};
// the dense output's terms 3 to 6 (of its 7), from all 16 stages
constexpr double d[4][16] = {
    {-8.428938276109013, 0.0, 0.0, 0.0, 0.0, 0.5667149535193777, -3.0689499459498917, 2.38466765651207,
     2.117034582445028, -0.871391583777973, 2.2404374302607883, 0.6315787787694688, -0.08899033645133331,
     18.148505520854727, -9.194632392478356, -4.436036387594894},
    {10.427508642579134, 0.0, 0.0, 0.0, 0.0, 242.28349177525817, 165.20045171727028, -374.5467547226902,
     -22.113666853125306, 7.733432668472264, -30.674084731089398, -9.332130526430229, 15.697238121770845,
     -31.139403219565178, -9.35292435884448, 35.81684148639408},
    {19.985053242002433, 0.0, 0.0, 0.0, 0.0, -387.0373087493518, -189.17813819516758, 527.8081592054236,
     -11.57390253995963, 6.8812326946963, -1.0006050966910838, 0.7777137798053443, -2.778205752353508,
     -60.19669523126412, 84.32040550667716, 11.99229113618279},
    {-25.69393346270375, 0.0, 0.0, 0.0, 0.0, -154.18974869023643, -231.5293791760455, 357.6391179106141,
     93.40532418362432, -37.45832313645163, 104.0996495089623, 29.8402934266605, -43.53345659001114, 96.32455395918828,
     -39.17726167561544, -149.72683625798564},
};
}  // namespace dop853

/// DOP853: Dormand & Prince's explicit pair of order 8 with Hairer's error estimate from two embedded estimators,
/// err = ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) (each a scaled norm: Tolerances::norm), O(h⁸), and a dense output of order 7
/// that costs three more evaluations in a step where it is asked for. 12 evaluations a step (FSAL).
class Dop853 final : public Stepper {
 public:
  Dop853(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) : ode_(sys, o, stats), k_(16) {}

  void start(double t0, const VecX& y0) override {
    y_ = y0;
    ode_.eval(t0, y_, f_);
    t_start_ = t0;
  }

  double initial_step(double span, const Tolerances& tol, double max_step) override {
    return hairer_initial_step(ode_, 8, t_start_, y_, f_, span, tol, max_step);
  }

  /// An adaptive step whose stages cannot be evaluated (a stage's state singular or not finite: its long steps reach
  /// farther than dopri5's) is rejected, and the run retries with a quarter of the step; at fixed steps it fails.
  bool attempt(double t, double h, const Tolerances* tol, double& err) override {
    using namespace dop853;
    t0_ = t, h_ = h, y0_ = y_, k_[0] = f_, extended_ = false;
    err = 0.0;
    // k_i = f(t + c_i h, y0 + h Σ_j a_ij k_j), i = 1 … 11; y1 = y0 + h Σ b_i k_i; k_12 = f(t + h, y1)
    VecX yi;
    try {
      for (int i = 1; i < 12; ++i) {
        stage(i, yi);
        ode_.eval(t + c[i] * h, yi, k_[i]);
      }
      y1_ = y0_;
      for (int i = 0; i < 12; ++i)
        if (b[i] != 0.0) y1_ += (h * b[i]) * k_[i];
      ode_.eval(t + h, y1_, k_[12]);
    } catch (const SimulationError&) {
      if (!tol) throw;
      return false;
    }
    // Hairer's h ρ from the two evaluations at t + h: stage 11 (c = 1, at yi) and f(t + h, y1)
    const int m = ode_.controlled();
    const double den = (y1_ - yi).head(m).squaredNorm();
    h_rho_ = den > 0.0 ? h * std::sqrt((k_[12] - k_[11]).head(m).squaredNorm() / den) : 0.0;
    if (!tol) return true;
    VecX err5 = VecX::Zero(y0_.size()), err3 = VecX::Zero(y0_.size());
    for (int i = 0; i < 13; ++i) {
      if (e5[i] != 0.0) err5 += (h * e5[i]) * k_[i];
      if (e3[i] != 0.0) err3 += (h * e3[i]) * k_[i];
    }
    const double n5 = tol->norm(err5.head(m), y0_.head(m), y1_.head(m), h);
    const double n3 = tol->norm(err3.head(m), y0_.head(m), y1_.head(m), h);
    err = n5 > 0.0 ? n5 * n5 / std::sqrt(n5 * n5 + 0.01 * n3 * n3) : 0.0;
    return true;
  }

  void accept() override {
    y_ = y1_;
    f_ = k_[12];
  }

  const VecX& state() const override { return y_; }

  void project(double t) override { ode_.project_and_eval(t, y_, f_); }

  /// y(t0 + θh) = y0 + Σ of the seven terms F_k, nested in θ and 1 − θ alternately (Hairer's CONTD8): F_0 = Δy,
  /// F_1 = h f0 − Δy, F_2 = 2 Δy − h (f0 + f1), F_{3..6} = h Σ_j d_kj k_j over the 16 stages.
  VecX dense(double t) const override {
    if (!extended_) extend();
    const double theta = (t - t0_) / h_;
    VecX y = VecX::Zero(y0_.size());
    for (int i = 6; i >= 0; --i) {
      y += F_[i];
      y *= (6 - i) % 2 == 0 ? theta : 1.0 - theta;
    }
    return y + y0_;
  }

  double h_rho() const override { return h_rho_; }
  /// Its error estimate is O(h⁸); steps grow at most 6 times (Hairer's); its stability boundary on the negative real
  /// axis is at h ρ = 6.1 (Hairer's stiffness test).
  StepControl control() const override { return {8, 6.0, true, 1.0, 1.0, 0.0, 6.0}; }

 private:
  // y0 + h Σ_{j<i} a_ij k_j into yi
  void stage(int i, VecX& yi) const {
    yi = y0_;
    for (int j = 0; j < i; ++j)
      if (dop853::a[i][j] != 0.0) yi += (h_ * dop853::a[i][j]) * k_[j];
  }
  // The three stages 13–15 of the dense output, and its terms F.
  void extend() const {
    using namespace dop853;
    VecX yi;
    for (int i = 13; i < 16; ++i) {
      stage(i, yi);
      ode_.eval(t0_ + c[i] * h_, yi, k_[i]);
    }
    const VecX dy = y1_ - y0_;
    F_[0] = dy;
    F_[1] = h_ * k_[0] - dy;
    F_[2] = 2.0 * dy - h_ * (k_[0] + k_[12]);
    for (int r = 0; r < 4; ++r) {
      F_[3 + r] = VecX::Zero(y0_.size());
      for (int j = 0; j < 16; ++j)
        if (d[r][j] != 0.0) F_[3 + r] += (h_ * d[r][j]) * k_[j];
    }
    extended_ = true;
  }

  mutable FirstOrder ode_;  // mutable: the dense output evaluates its three stages on demand
  mutable std::vector<VecX> k_;
  mutable VecX F_[7];
  mutable bool extended_ = false;
  double t_start_ = 0, t0_ = 0, h_ = 1, h_rho_ = 0;
  VecX y_, f_, y0_, y1_;
};

}  // namespace

std::unique_ptr<Stepper> make_dop853(const System& sys, const IntegratorOptions& o, IntegratorStats& stats) {
  return std::make_unique<Dop853>(sys, o, stats);
}

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
      {Method::Dop853, "dop853", "explicit Runge-Kutta", 8, true, true, false, false,
       method_options(true, false, {"stiffness_warning"}),
       "Dormand–Prince 8(5,3) (Hairer's DOP853): 12 evaluations a step (FSAL), dense output of order 7 (3 more where "
       "asked)",
       make_dop853, nullptr},
      {Method::BS23, "bs23", "explicit Runge-Kutta", 3, true, true, false, false, method_options(true, false),
       "Bogacki–Shampine 3(2) (SciPy's RK23): 3 evaluations a step (FSAL), 3rd order propagated, cubic Hermite dense "
       "output",
       make_runge_kutta, nullptr},
  };
  return rows;
}

}  // namespace rigidfem
