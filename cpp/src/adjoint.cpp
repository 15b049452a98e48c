// The discrete adjoints of the Newmark family and of radau5, with checkpointing (adjoint.hpp).
#include "rigidfem/adjoint.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "rigidfem/constraints.hpp"
#include "rigidfem/derivatives.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/gmres.hpp"
#include "rigidfem/newmark.hpp"
#include "rigidfem/newton_matrix.hpp"
#include "rigidfem/radau.hpp"

namespace rigidfem {

namespace {

using Clock = std::chrono::steady_clock;

// The run's grid: t_k = t0 + k dt, the last step landing on t_end (as integrate() takes fixed steps).
std::vector<double> grid(double t0, double t_end, double dt) {
  const double span = t_end - t0, near_end = t_end - 1e-12 * span;
  std::vector<double> t{t0};
  while (t.back() < t_end) {
    double t1 = t0 + static_cast<double>(t.size()) * dt;
    if (t1 > near_end) t1 = t_end;
    t.push_back(t1);
  }
  return t;
}

/// The reverse mode's products r(z_i) of the vectors z_i a GMRES solve applied its operator to: its solution is
/// x = Σ y_i z_i (Gmres::combination), so r(x) = Σ y_i r(z_i) costs no further product.
class KeptProducts {
 public:
  void clear() { count_ = 0; }
  void keep(const ResidualVjp& r) {
    if (count_ == kept_.size()) kept_.push_back(r);
    else kept_[count_] = r;  // the vectors keep their storage
    ++count_;
  }
  /// sum() = Σ y_i r(z_i); false when y is not one coefficient per product kept.
  bool combine(const VecX& y) {
    if (static_cast<std::size_t>(y.size()) != count_ || count_ == 0) return false;
    sum_ = kept_[0];
    for (VecX* v : {&sum_.q, &sum_.qd, &sum_.qdd, &sum_.pq, &sum_.pqd, &sum_.pqdd}) v->setZero();
    for (std::size_t i = 0; i < count_; ++i) {
      const ResidualVjp& r = kept_[i];
      sum_.q += y(i) * r.q, sum_.qd += y(i) * r.qd, sum_.qdd += y(i) * r.qdd;
      sum_.pq += y(i) * r.pq, sum_.pqd += y(i) * r.pqd, sum_.pqdd += y(i) * r.pqdd;
    }
    return true;
  }
  const ResidualVjp& sum() const { return sum_; }

 private:
  std::vector<ResidualVjp> kept_;
  std::size_t count_ = 0;
  ResidualVjp sum_;
};

/// What both methods' transposes share: the reverse mode at a state, and GMRES on a transposed Newton matrix
/// with a preconditioner kept while it converges in a few iterations.
class Transposes : public AdjointSteps {
 public:
  Transposes(const System& sys, const IntegratorOptions& o, ParameterVjp& params)
      : sys_(sys), params_(params), d_(sys), e_(sys), transpose_(sys), matrix_(NewtonMatrix::make(sys, o, istats_)) {}

  void start(double t0, const VecX& q0, const VecX& qd0) override {
    VecX y0(2 * sys_.nq);
    y0 << q0, qd0;
    stepper().start(t0, y0);
  }
  const Data& at_end(const StepRecord& end) override {
    at(d_, end.t, end.q, end.v, end.qdd);
    return d_;
  }
  void step(double t, double h) override {
    double err = 0.0;
    if (!stepper().attempt(t, h, nullptr, err))
      step_failure(t, h, "Newton iterations did not converge in newton_max_iterations; reduce dt or raise "
                         "newton_max_iterations");
    stepper().accept();
    if (sys_.nl > 0) stepper().project(t + h);  // radau5 (as integrate() runs it; the Newmark family: nothing)
  }

 protected:
  /// The method's own stepper, which the forward run and the replays step with.
  virtual Stepper& stepper() = 0;
  /// Loops: H v = ∂(G(q)ᵀλ)/∂q v at (t, q, q̇) for the multipliers λ, by a central difference along v.
  VecX hessian(double t, const VecX& q, const VecX& qd, const VecX& lambda, const VecX& v) {
    const double size = max_abs(v) / std::max(1.0, max_abs(q));
    if (size == 0.0) return VecX::Zero(sys_.nq);
    const double eps = 6e-6 / size;
    loop_equations(sys_, e_, t, q + eps * v, qd);
    const VecX up = free_jacobian(sys_, e_).transpose() * lambda;
    loop_equations(sys_, e_, t, q - eps * v, qd);
    return (up - free_jacobian(sys_, e_).transpose() * lambda) / (2.0 * eps);
  }
  /// set_state, q̈ and the axes on d at (t, q, q̇, q̈): what the reverse mode starts from.
  void at(Data& d, double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& v,
          const Eigen::Ref<const VecX>& a) {
    set_state(sys_, d, t, q, v);
    set_accelerations(sys_, d, a);
    tree_kinematics(sys_, d);
  }
  /// (Kᵀμ, Cᵀμ, Mμ) at (t, q, q̇, q̈); d_ keeps the state's spatial kinematics and RNEA pass (ParameterVjp::add).
  ResidualVjp vjp(double t, const Eigen::Ref<const VecX>& q, const Eigen::Ref<const VecX>& v,
                  const Eigen::Ref<const VecX>& a, const VecX& mu) {
    at(d_, t, q, v, a);
    transpose_.prepare(d_);
    return transpose_.apply(d_, mu);
  }
  /// x with S x = b by GMRES to 1e-11 (S, P as Gmres takes them), the preconditioner refreshed by `refresh` first
  /// when none is ready (`ready`: one the caller has; else the sweep's own, once made) or the last solve took more
  /// iterations than refresh_above_.
  template <class Op, class Prec, class Refresh>
  VecX gmres(const Op& S, const Prec& P, const VecX& b, Refresh&& refresh, double t, bool ready = false) {
    if (!(ready || fresh_) || last_iterations_ > refresh_above_) {
      refresh();
      fresh_ = true;
      ++stats->preconditioner_refreshes;
    }
    VecX x;
    last_iterations_ = gmres_.solve(S, P, b, x, 1e-11, 300);
    stats->linear_iterations += last_iterations_;
    if (!x.allFinite()) throw SimulationError(t, "the adjoint became NaN or inf");
    return x;
  }

  const System& sys_;
  ParameterVjp& params_;
  Data d_, e_;  // the state's, and the loops' equations'
  ResidualTranspose transpose_;  // the reverse mode at d_'s state, prepared once per state
  KeptProducts kept_;            // the reverse mode's products of one GMRES solve
  VecX y_;                       // its combination
  IntegratorStats istats_;
  std::unique_ptr<NewtonMatrix> matrix_;
  Gmres<double> gmres_;
  // measured on strips of 20-320 elements over 1000 steps: an O(n) armature factor is worth refreshing after 2
  // iterations, a dense LU after 5 (2.6-4.1 runs for the gradient; 4.6-5.4 after 3 or 4, 3.7-5.2 after 8); the
  // Newmark family's sweep lowers the dense one to 4 where the forward run kept each factorisation 100 steps or more
  // (NewmarkSteps::transpose)
  long refresh_above_ = matrix_->krylov() ? 2 : 5;
  bool fresh_ = false;
  long last_iterations_ = 0;
};

/// The Newmark family (adjoint.hpp): the adjoint state (q̄, q̇̄, ā, q̈̄).
class NewmarkSteps final : public Transposes {
 public:
  NewmarkSteps(const System& sys, const IntegratorOptions& o, ParameterVjp& params, double memory)
      : Transposes(sys, o, params), memory_(memory), stepper_(make_newmark_stepper(sys, o, istats_)), k_(stepper_->coefficients()) {}

  void start(double t0, const VecX& q0, const VecX& qd0) override {
    Transposes::start(t0, q0, qd0);
    factors_.clear(), made_at_.clear();
    keeping_ = in_forward_ = true;
    forward_steps_ = 0, forward_factors_ = 0, last_factor_.reset();
  }
  /// A step of the forward run keeps the stepper's dense factorisation when it made a new one (in a replay the
  /// stepper makes them again: not kept), while they fit into an eighth of the adjoint's memory.
  void step(double t, double h) override {
    Transposes::step(t, h);
    if (!in_forward_) return;
    ++forward_steps_;
    auto f = stepper_->dense_factor();
    if (!f || f == last_factor_) return;
    ++forward_factors_, last_factor_ = f;
    if (!keeping_) return;
    const double bytes = 8.0 * sys_.nq * sys_.nq * static_cast<double>(factors_.size() + 1);
    if (bytes > memory_ / 8.0) {
      keeping_ = false;
      return;
    }
    factors_.push_back(std::move(f));
    made_at_.push_back(t + h);
  }
  StepRecord record(double t, double h) const override {
    const NewmarkState& s = stepper_->current();
    return {t, h, s.q, s.v, s.qdd, s.a, s.lambda, {}, {}, {}, {}};
  }
  void restore(const StepRecord& r) override {
    keeping_ = in_forward_ = false;  // a replay's
    NewmarkState s;
    s.q = r.q, s.v = r.v, s.qdd = r.qdd, s.a = r.a, s.s = VecX(0), s.lambda = r.lambda;
    stepper_->restore(r.t, s);
  }
  int adjoint_size() const override { return 4; }

  void transpose(const StepRecord& s, VecX& bars, VecX& grad) override {
    const int n = sys_.nq;
    const double h = s.h, z = (1.0 - k_.af) / (1.0 - k_.am), c1 = k_.gamma * z * h, c2 = k_.beta * z * h * h;
    // a Jacobian that drifts slowly (the forward run's factorisations kept 100 steps or more each: Kane's smooth
    // spin-up, 222) keeps a refreshed preconditioner good for long, which pays for refreshing it one iteration
    // sooner: the gradient of that run by 108 parameters 2.86 → 2.72 runs; the shaken strip (20 steps each) not
    if (!matrix_->krylov()) refresh_above_ = forward_steps_ >= 100 * std::max<long>(1, forward_factors_) ? 4 : 5;
    auto qb = bars.segment(0, n), vb = bars.segment(n, n), ab = bars.segment(2 * n, n), zb = bars.segment(3 * n, n);
    const VecX g = zb + z * (ab + (k_.beta * h * h) * qb + (k_.gamma * h) * vb);
    // Sᵀ μ = g, Sᵀv = M v + c₁ Cᵀ v + c₂ Kᵀ v by the reverse mode at the step's end (d_: at_end)
    transpose_.prepare(d_);
    const bool loops = sys_.nl > 0;
    // A₁₁ᵀv = M v + c₁ Cᵀ v + c₂ (Kᵀ v − H v), H = ∂(Gᵀλ)/∂q (symmetric) with loops
    bool keep = !loops;  // the products of μ's own solve, whose combination is r(μ) (no loops: μ is that solve's)
    kept_.clear();
    auto S = [&](const VecX& v, VecX& out) {
      const ResidualVjp& r = transpose_.apply(d_, v);
      if (keep) kept_.keep(r);
      out = r.qdd + c1 * r.qd + c2 * r.q;
      if (loops) out -= c2 * hessian(s.t, s.q, s.v, s.lambda, v);
    };
    // the preconditioner: the forward run's factorisation of this step's Newton matrix (the latest made by t: the
    // step's own), or the sweep's own where that one took more than refresh_above_ iterations, until the sweep
    // reaches the steps of an earlier forward factorisation
    const auto it = std::upper_bound(made_at_.begin(), made_at_.end(), s.t);
    const DenseLU* forward = it == made_at_.begin() ? nullptr : factors_[it - made_at_.begin() - 1].get();
    if (forward != forward_) forward_ = forward, own_ = false, last_iterations_ = 0;
    auto P = [&](const VecX& v, VecX& out) {
      if (forward_ && !own_) forward_->solve_transposed(v, out);
      else matrix_->precondition_transposed(v, out);
    };
    auto refresh = [&] {
      matrix_->linearize(s.t, s.q, s.v, s.qdd, VecX());
      if (!(matrix_->factor(c1, c2, VecX()) > 1e-15))
        throw SimulationError(s.t, "the adjoint's Newton matrix M + γh C + βh² K is singular");
      own_ = forward_ != nullptr;
    };
    VecX mu = gmres(S, P, g, refresh, s.t, forward_ && !own_);
    keep = false;
    VecX nu, loop_q;
    if (loops) {  // the saddle system by its Schur complement: μ = x − Y ν, Y = A₁₁⁻ᵀ (c₂ Gᵀ), (G Y) ν = G x
      loop_equations(sys_, e_, s.t, s.q, s.v);
      const MatX G = free_jacobian(sys_, e_);
      MatX Y(sys_.nq, sys_.nl);
      for (int k = 0; k < sys_.nl; ++k)
        Y.col(k) = gmres(S, P, VecX(c2 * G.row(k).transpose()), refresh, s.t, forward_ && !own_);
      nu = least_norm(G * Y, G * mu);
      mu -= Y * nu;
      loop_q = G.transpose() * nu - hessian(s.t, s.q, s.v, s.lambda, mu);
    }
    // r(μ) = Σ y_i r(z_i) of GMRES's products, or one more product (d_ still at the step's end)
    const ResidualVjp& r = !loops && gmres_.combination(y_) && kept_.combine(y_) ? kept_.sum() : transpose_.apply(d_, mu);
    const VecX qh = loops ? VecX(qb - r.q - loop_q) : VecX(qb - r.q), vh = vb - r.qd;
    const VecX A = ab + (k_.beta * h * h) * qh + (k_.gamma * h) * vh;
    qb = qh;
    vb = h * qh + vh;
    ab = (h * h * (0.5 - k_.beta)) * qh + (h * (1.0 - k_.gamma)) * vh - (k_.am / (1.0 - k_.am)) * A;
    zb = (k_.af / (1.0 - k_.am)) * A;
    params_.add(d_, mu, r, -1.0, grad);
    if (loops) params_.add_loops(s.t, s.q, s.v, s.qdd, s.lambda, mu, nu, false, grad);
  }

  /// a_0 = q̈_0 solves r(q_0, q̇_0, q̈_0) = 0: M μ_0 = ā_0 + q̈̄_0, q̄_0 −= Kᵀμ_0, q̇̄_0 −= Cᵀμ_0. With loops the
  /// constrained forward dynamics (r − Gᵀλ = 0, G q̈ = γ) transposed: M μ_0 + Gᵀν_0 = ā_0 + q̈̄_0, G μ_0 = 0, and
  /// q̄_0 −= −H μ_0 + ∂(G q̈ − γ)/∂qᵀ ν_0, q̇̄_0 −= ∂(G q̈ − γ)/∂q̇ᵀ ν_0 (central differences, coordinate by coordinate).
  void transpose_start(const StepRecord& s, VecX& bars, VecX& grad) override {
    const int n = sys_.nq;
    set_state(sys_, d_, s.t, s.q, s.v);
    tree_kinematics(sys_, d_);
    factor_mass(sys_, d_);
    VecX mu(n), nu;
    const VecX g = bars.segment(2 * n, n) + bars.segment(3 * n, n);
    solve_armature(sys_, d_, g, mu);
    if (sys_.nl > 0) {
      loop_equations(sys_, e_, s.t, s.q, s.v);
      const MatX G = free_jacobian(sys_, e_), Y = solve_armature(sys_, d_, MatX(G.transpose()));
      nu = least_norm(G * Y, G * mu);
      mu -= Y * nu;
    }
    const ResidualVjp r = vjp(s.t, s.q, s.v, s.qdd, mu);
    bars.segment(0, n) -= r.q;
    bars.segment(n, n) -= r.qd;
    params_.add(d_, mu, r, -1.0, grad);
    if (sys_.nl == 0) return;
    bars.segment(0, n) += hessian(s.t, s.q, s.v, s.lambda, mu);
    // ν_0ᵀ (G q̈_0 − γ)(q, q̇) differentiated by each coordinate of q and q̇
    auto c = [&](const VecX& q, const VecX& v) {
      loop_equations(sys_, e_, s.t, q, v);
      return nu.dot(free_jacobian(sys_, e_) * s.qdd - e_.gamma);
    };
    VecX q = s.q, v = s.v;
    for (int k = 0; k < n; ++k) {
      interruption_point();
      for (VecX* x : {&q, &v}) {
        const double x0 = (*x)(k), h = 6e-6 * std::max(1.0, std::abs(x0));
        (*x)(k) = x0 + h;
        const double up = c(q, v);
        (*x)(k) = x0 - h;
        const double down = c(q, v);
        (*x)(k) = x0;
        bars((x == &q ? 0 : n) + k) -= (up - down) / (2.0 * h);
      }
    }
    params_.add_loops(s.t, s.q, s.v, s.qdd, s.lambda, mu, nu, true, grad);
  }

 private:
  Stepper& stepper() override { return *stepper_; }

  double memory_;  // the adjoint's bytes: an eighth of it for the forward factorisations
  std::unique_ptr<NewmarkStepper> stepper_;
  NewmarkCoefficients k_;
  std::vector<std::shared_ptr<const DenseLU>> factors_;  // the forward run's, in order
  std::vector<double> made_at_;  // the end of the step that made each
  bool keeping_ = false;         // in the forward run (not a replay) and within memory
  bool in_forward_ = false;      // in the forward run
  long forward_steps_ = 0, forward_factors_ = 0;  // its steps and the dense factorisations it made
  std::shared_ptr<const DenseLU> last_factor_;  // the last of them
  const DenseLU* forward_ = nullptr;  // the forward factorisation in use
  bool own_ = false;             // the sweep's own factorisation preferred to forward_
};

/// radau5 (adjoint.hpp): the adjoint state (q̄, q̇̄).
class RadauSteps final : public Transposes {
 public:
  RadauSteps(const System& sys, const IntegratorOptions& o, ParameterVjp& params)
      : Transposes(sys, o, params), stepper_(make_implicit_rk(sys, o, istats_)),
        access_(dynamic_cast<RadauAccess*>(stepper_.get())) {
    if (!access_) throw std::logic_error("RadauSteps: the stepper is not radau5");
    for (int i = 0; i < 3; ++i) stage_d_[i] = std::make_unique<Data>(sys), stage_[i] = std::make_unique<ResidualTranspose>(sys);
  }

  StepRecord record(double t, double h) const override {
    StepRecord r{t, h, {}, {}, {}, {}, {}, {}, {}, {}, {}};
    access_->current(r.q, r.v, r.qdd);
    if (h > 0.0) access_->stages(r.Q, r.V, r.A);
    if (h > 0.0 && sys_.nl > 0) access_->stage_multipliers(r.L);
    return r;
  }
  void restore(const StepRecord& r) override { access_->restore(r.t, r.q, r.v, r.qdd); }
  int adjoint_size() const override { return 2; }

  void transpose(const StepRecord& s, VecX& bars, VecX& grad) override {
    const int n = sys_.nq, nl = sys_.nl;
    const bool loops = nl > 0;
    const double h = s.h, t0 = s.t - h;
    const Eigen::Matrix3d& a = tab_.a;
    const Eigen::Matrix3d a2 = a * a;
    if (loops) transpose_projection(s, bars, grad);
    MatX Qb = MatX::Zero(n, 3), Vb = MatX::Zero(n, 3);
    Qb.col(2) = bars.head(n), Vb.col(2) = bars.tail(n);
    // loops: each stage's G_i, and (∂c_i/∂V_i, ∂c_i/∂Q_i) of its constraint c_i = G_i A_i − γ_i (loop_rates)
    MatX Gs[3], DV[3], DQ[3];
    if (loops)
      for (int i = 0; i < 3; ++i) loop_rates(t0 + tab_.c(i) * h, s.Q.col(i), s.V.col(i), s.A.col(i), Gs[i], DV[i], DQ[i]);
    const MatX Vt = Vb + h * Qb * a;
    const MatX G = h * Vt * a;
    // the reverse mode at each stage, prepared once for the step's products
    for (int i = 0; i < 3; ++i) {
      at(*stage_d_[i], t0 + tab_.c(i) * h, s.Q.col(i), s.V.col(i), s.A.col(i));
      stage_[i]->prepare(*stage_d_[i]);
    }
    // 𝒮ᵀ μ by the reverse mode at each stage: M_j μ_j + h Σ_i a_ij C_iᵀ μ_i + h² Σ_i (a²)_ij K_iᵀ μ_i
    MatX Kmu(n, 3), Cmu(n, 3), Mmu(n, 3);
    auto products = [&](const MatX& mu) {
      for (int i = 0; i < 3; ++i) {
        const double ti = t0 + tab_.c(i) * h;
        const ResidualVjp& r = stage_[i]->apply(*stage_d_[i], mu.col(i));
        Kmu.col(i) = r.q, Cmu.col(i) = r.qd, Mmu.col(i) = r.qdd;
        if (loops) Kmu.col(i) -= hessian(ti, s.Q.col(i), s.V.col(i), s.L.col(i), mu.col(i));  // K_i − H_i
      }
    };
    auto S = [&](const VecX& v, VecX& out) {
      products(Eigen::Map<const MatX>(v.data(), n, 3));
      const MatX y = Mmu + h * Cmu * a + (h * h) * Kmu * a2;
      out = Eigen::Map<const VecX>(y.data(), 3 * n);
    };
    // the transposed blocks of one tangent: X̃ = X P, (M + h d_k C + h² d_k² K)ᵀ ỹ_k = x̃_k, Y = Re(Ỹ P⁻¹)
    auto P = [&](const VecX& v, VecX& out) {
      const Eigen::MatrixXcd Xt = Eigen::Map<const MatX>(v.data(), n, 3).cast<cplx>() * tab_.P;
      Eigen::MatrixXcd Yt(n, 3);
      VecX x = Xt.col(0).real(), y;
      matrix_->precondition_transposed(x, y);
      Yt.col(0) = y.cast<cplx>();
      VecXc z = Xt.col(1), w;
      matrix_->precondition_transposed(z, w);
      Yt.col(1) = w;
      Yt.col(2) = w.conjugate();
      const MatX Y = Yt.real() * tab_.Pinv.real() - Yt.imag() * tab_.Pinv.imag();
      out = Eigen::Map<const VecX>(Y.data(), 3 * n);
    };
    const VecX g = Eigen::Map<const VecX>(G.data(), 3 * n);
    auto refresh = [&] {
      matrix_->linearize(s.t, s.q, s.v, s.qdd, VecX());
      const double gr = h * tab_.d(0).real();
      const cplx gc = h * tab_.d(1);
      if (!(matrix_->factor(gr, gr * gr, VecX()) > 1e-15) || !(matrix_->factor(gc, gc * gc) > 1e-15))
        throw SimulationError(s.t, "the adjoint's Newton matrix of radau5 is singular");
    };
    VecX m = gmres(S, P, g, refresh, s.t);
    MatX nu;  // (nl, 3) the stages' constraint adjoints
    if (loops) {
      // 𝒮ᵀμ + Zν = g, G_i μ_i = 0 (each stage), Z = (∂c/∂A)ᵀ: (Zν)_j = G_jᵀν_j + h Σ_i a_ij DV_iᵀν_i +
      // h² Σ_i (a²)_ij DQ_iᵀν_i. By the Schur complement: μ = x − Wν, W = 𝒮⁻ᵀZ (3 nl solves), (𝒢W)ν = 𝒢x.
      MatX W(3 * n, 3 * nl), GW(3 * nl, 3 * nl);
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < nl; ++k) {
          MatX z = MatX::Zero(n, 3);
          z.col(i) = Gs[i].row(k).transpose();
          for (int j = 0; j < 3; ++j)
            z.col(j) += (h * a(i, j)) * DV[i].row(k).transpose() + (h * h * a2(i, j)) * DQ[i].row(k).transpose();
          W.col(i * nl + k) = gmres(S, P, Eigen::Map<const VecX>(z.data(), 3 * n), refresh, s.t);
        }
      auto stage_constraints = [&](const VecX& x) {  // 𝒢x: (G_i x_i) stacked
        VecX c(3 * nl);
        for (int i = 0; i < 3; ++i) c.segment(i * nl, nl) = Gs[i] * x.segment(i * n, n);
        return c;
      };
      for (int col = 0; col < 3 * nl; ++col) GW.col(col) = stage_constraints(W.col(col));
      const VecX v = least_norm(GW, stage_constraints(m));
      m -= W * v;
      nu = Eigen::Map<const MatX>(v.data(), nl, 3);
    }
    const MatX mu = Eigen::Map<const MatX>(m.data(), n, 3);
    // q̂ = Q̄ − Kμ, V̂ = V̄ − Cμ (loops: − (K − H)μ − DQᵀν, − DVᵀν); q̄_n = Σ Q̂_i, q̇̄_n = Σ V̂_i + h Σ c_i Q̂_i;
    // dJ/dp −= Σ μ_iᵀ ∂r_i/∂p (loops: + μ_iᵀ ∂(−G_iᵀΛ_i)/∂p + ν_iᵀ ∂c_i/∂p)
    VecX qb = VecX::Zero(n), vb = VecX::Zero(n);
    for (int i = 0; i < 3; ++i) {
      const double ti = t0 + tab_.c(i) * h;
      const ResidualVjp& r = stage_[i]->apply(*stage_d_[i], mu.col(i));
      VecX Qh = Qb.col(i) - r.q, Vh = Vb.col(i) - r.qd;
      params_.add(*stage_d_[i], mu.col(i), r, -1.0, grad);
      if (loops) {
        Qh += hessian(ti, s.Q.col(i), s.V.col(i), s.L.col(i), mu.col(i)) - DQ[i].transpose() * nu.col(i);
        Vh -= DV[i].transpose() * nu.col(i);
        params_.add_loops(ti, s.Q.col(i), s.V.col(i), s.A.col(i), s.L.col(i), mu.col(i), nu.col(i), true, grad);
      }
      qb += Qh;
      vb += Vh + (h * tab_.c(i)) * Qh;
    }
    bars << qb, vb;
  }

  /// q̈_0 only starts the first step's Newton iterations: nothing depends on it.
  void transpose_start(const StepRecord&, VecX&, VecX&) override {}

 private:
  Stepper& stepper() override { return *stepper_; }

  /// Loops: the step's end (Q_3, V_3) is projected onto them (project_onto_loops), whose derivative at the
  /// projected (q, q̇) is (SensitivityEquations::project)
  ///   δq' = Π δq − B g_p,   δq̇' = Π δq̇ − B (D δq' + ġ_p),   Π = 1 − B G,  B = Y (G Y)⁺,  Y = M⁻¹Gᵀ,  D = ∂ġ/∂q.
  /// Transposed: w = Bᵀq̇̄', x = q̄' − Dᵀw, q̄ = Πᵀx, q̇̄ = Πᵀq̇̄' and dJ/dp −= (Bᵀx)ᵀ g_p + wᵀ ġ_p (a drive's numbers);
  /// Bᵀy = (G Y)⁺ Yᵀ y (G Y symmetric), Dᵀw by a central difference of Gᵀw along the motion (loop_rates).
  void transpose_projection(const StepRecord& s, VecX& bars, VecX& grad) {
    const int n = sys_.nq;
    loop_equations(sys_, e_, s.t, s.q, s.v);
    const MatX G = free_jacobian(sys_, e_);
    factor_mass(sys_, e_);
    const MatX Y = solve_armature(sys_, e_, MatX(G.transpose())), GY = G * Y;
    const VecX qbar = bars.head(n), vbar = bars.tail(n);
    const VecX w = least_norm(GY, Y.transpose() * vbar);
    const double eps = motion_step(s.q, s.v, VecX::Zero(n), 6e-6);
    loop_equations(sys_, e_, s.t + eps, s.q + eps * s.v, s.v);
    VecX Dw = free_jacobian(sys_, e_).transpose() * w;
    loop_equations(sys_, e_, s.t - eps, s.q - eps * s.v, s.v);
    Dw = (Dw - free_jacobian(sys_, e_).transpose() * w) / (2.0 * eps);
    const VecX x = qbar - Dw, bx = least_norm(GY, Y.transpose() * x);
    bars.head(n) = x - G.transpose() * bx;
    bars.tail(n) = vbar - G.transpose() * w;
    params_.add_projection(s.t, s.q, s.v, bx, w, grad);
  }

  /// G (nl, nq) at a stage (t, q, q̇, q̈), and the derivatives of c = G q̈ − γ = g̈ by q̇ and q: ∂c/∂q̇ = 2 dG/dt
  /// and ∂c/∂q = d²G/dt² (row by row, the gradients of νᵀg̈), along the motion q(τ) = q + τ q̇ + τ²/2 q̈ at t + τ
  /// (the prescribed coordinates along their profiles): central differences, first and second.
  void loop_rates(double t, const VecX& q, const VecX& v, const VecX& acc, MatX& G, MatX& DV, MatX& DQ) {
    auto jacobian = [&](double tau) {
      loop_equations(sys_, e_, t + tau, q + tau * v + (0.5 * tau * tau) * acc, v + tau * acc);
      return MatX(free_jacobian(sys_, e_));
    };
    G = jacobian(0.0);
    const double e1 = motion_step(q, v, acc, 6e-6), e2 = motion_step(q, v, acc, 1e-4);
    DV = (jacobian(e1) - jacobian(-e1)) / e1;  // 2 (G(+) − G(−))/(2ε)
    DQ = (jacobian(e2) - 2.0 * G + jacobian(-e2)) / (e2 * e2);
  }

  /// τ (s) that moves q along the motion by about `size` relative to max(1, |q|), and t by at most `size`.
  static double motion_step(const VecX& q, const VecX& v, const VecX& acc, double size) {
    const double scale = std::max(1.0, max_abs(q));
    const double rate = std::max({max_abs(v) / scale, std::sqrt(max_abs(acc) / scale), 1.0});
    return size / rate;
  }

  std::unique_ptr<Stepper> stepper_;
  RadauAccess* access_;
  const RadauTableau tab_;
  std::unique_ptr<Data> stage_d_[3];                // each stage's state, kinematics and RNEA pass
  std::unique_ptr<ResidualTranspose> stage_[3];     // the reverse mode prepared there
};

}  // namespace

Adjoint::Adjoint(std::shared_ptr<const System> sys, const IntegratorOptions& o, std::vector<OutputSpec> outputs,
                 double memory)
    : sys_(std::move(sys)), o_(o), outputs_(std::move(outputs)), memory_(memory), d_(*sys_) {
  const System& s = *sys_;
  if (!reverse_mode(s))
    throw std::invalid_argument("system: expected a system compiled with algorithm='recursive' (the adjoint "
                                "transposes the recursive engine's derivatives), got algorithm='lagrange'");
  if (s.nz > 0) throw std::invalid_argument("system: expected no Maxwell arms (not implemented for the adjoint yet)");
  if (!(o.dt > 0.0)) bad("dt", "a fixed step > 0 (s)", num(o.dt));
  if (!(memory > 0.0)) bad("memory", "a number of bytes > 0", num(memory));
  for (const OutputSpec& out : outputs_) {
    if (out.kind == OutputSpec::Kind::Point) {
      check_body(s, out.index, "outputs");
    } else if (out.kind != OutputSpec::Kind::Coordinate || out.index < 0 || out.index >= s.nq) {
      bad("outputs", "points and free coordinates", "another output");
    }
  }
  params_ = std::make_unique<ParameterVjp>(s, o.sensitivities);
  o_.sensitivities.clear();  // the stepper runs the state alone
  o_.adaptive = 0;
  if (o.method == Method::Radau5)
    steps_ = std::make_unique<RadauSteps>(s, o_, *params_);
  else if (o.method == Method::Newmark || o.method == Method::HHT || o.method == Method::GeneralizedAlpha ||
           o.method == Method::ImplicitSpring)
    steps_ = std::make_unique<NewmarkSteps>(s, o_, *params_, memory_);
  else
    bad("method", "generalized_alpha, newmark, hht, implicit_spring or radau5 (the methods with an adjoint)",
        method_name(o.method));
  steps_->stats = &stats_;
}

Adjoint::~Adjoint() = default;

void Adjoint::forward(double t0, double t_end, const VecX& q0, const VecX& qd0) {
  const auto start = Clock::now();
  const System& s = *sys_;
  const int n = s.nq, K = output_size(outputs_);
  if (!(t_end > t0)) bad("t_end", "a time after t0 = " + num(t0) + " s", num(t_end));
  // the work bounded before anything is allocated: N = ⌈(t_end − t0)/dt⌉ steps, the grid and the outputs
  // (N + 1)(1 + K) numbers kept whatever the checkpointing
  const double steps = std::ceil((t_end - t0) / o_.dt);
  if (!(steps <= static_cast<double>(o_.max_steps)))
    bad("t_end, dt", "at most max_steps = " + std::to_string(o_.max_steps) + " steps of dt over [t0, t_end]",
        "(t_end - t0)/dt = " + num(steps) + " steps");
  if (!((steps + 1.0) * 8.0 * (1.0 + K) <= memory_))
    bad("memory", "at least " + num((steps + 1.0) * 8.0 * (1.0 + K)) + " bytes (the grid and the outputs at its " +
                      num(steps + 1.0) + " times)",
        num(memory_));
  t_ = grid(t0, t_end, o_.dt);
  const long N = static_cast<long>(t_.size()) - 1;
  // every state if they fit, else checkpoints every k = ⌈√N⌉ steps and one segment of k states
  const double stages = o_.method == Method::Radau5 ? 9.0 : 0.0;
  const double state_bytes = 8.0 * ((4.0 + stages) * n + 4.0 * s.nl + 16.0);  // radau5 with loops: Λ too
  interval_ = 1;
  if ((N + 1) * state_bytes > memory_) {
    interval_ = static_cast<long>(std::ceil(std::sqrt(static_cast<double>(N))));
    const double need = (N / interval_ + 2 + interval_) * state_bytes;
    if (need > memory_)
      bad("memory", "at least " + num(need) + " bytes (2√N states of this run's " + std::to_string(N) + " steps)",
          num(memory_));
  }
  stats_ = {};
  // the initial values' directions [∂q₀/∂p, ∂q̇₀/∂p]; with loops, the initial state moves along them as
  // assemble() would, also by a drive's or an actuator's numbers (∂g/∂p, ∂ġ/∂p at t0)
  initial_.resize(2 * n, params_->count());
  std::unique_ptr<SensitivityEquations> sens;
  for (int j = 0; j < params_->count(); ++j) {
    initial_.col(j) = params_->initial(j);
    if (s.nl > 0 && (initial_.col(j).any() || params_->parameters()[j].minus)) {
      if (!sens) sens = std::make_unique<SensitivityEquations>(s, params_->parameters());
      VecX S0 = initial_.col(j);
      sens->project(j, t0, q0, qd0, S0);
      initial_.col(j) = S0;
    }
  }
  steps_->start(t0, q0, qd0);
  checkpoints_.assign(1, steps_->record(t0, 0.0));
  Y_.resize(N + 1, K);
  auto outputs_at = [&](long k, const VecX& q, const VecX& v) {
    set_state(s, d_, t_[k], q, v);
    tree_kinematics(s, d_);
    objective_outputs(s, d_, outputs_, Y_.row(k).transpose());
  };
  outputs_at(0, q0, qd0);
  for (long k = 0; k < N; ++k) {
    interruption_point();
    steps_->step(t_[k], t_[k + 1] - t_[k]);
    StepRecord r = steps_->record(t_[k + 1], t_[k + 1] - t_[k]);
    if (!r.q.allFinite() || !r.v.allFinite())
      throw SimulationError(t_[k + 1], "the state became NaN or inf (step dt = " + num(t_[k + 1] - t_[k]) +
                                           " s); reduce dt");
    outputs_at(k + 1, r.q, r.v);
    if ((k + 1) % interval_ == 0) checkpoints_.push_back(std::move(r));
  }
  stats_.steps = N;
  stats_.checkpoints = static_cast<long>(checkpoints_.size());
  stats_.interval = interval_;
  stats_.forward_time = std::chrono::duration<double>(Clock::now() - start).count();
}

void Adjoint::replay(long first, long last, std::vector<StepRecord>& states) {
  states.clear();
  states.push_back(checkpoints_[first / interval_]);
  if (last == first) return;
  if (interval_ == 1) {  // every state kept
    states.push_back(checkpoints_[last]);
    return;
  }
  steps_->restore(states[0]);
  for (long k = first; k < last; ++k) {
    steps_->step(t_[k], t_[k + 1] - t_[k]);
    ++stats_.recomputed_steps;
    states.push_back(steps_->record(t_[k + 1], t_[k + 1] - t_[k]));
  }
}

void Adjoint::output_vjp(const Data& d, const VecX& ybar, Eigen::Ref<VecX> qbar, VecX& grad) {
  const System& sys = *sys_;
  VecX pbar = VecX::Zero(sys.np);
  objective_outputs_vjp(sys, d, outputs_, ybar, qbar, pbar);
  if (sys.np > 0) params_->add_prescribed(d.t, pbar, grad);
}

VecX Adjoint::backward(const Eigen::Ref<const RowMatX>& ybar) {
  const auto start = Clock::now();
  const System& sys = *sys_;
  const int n = sys.nq;
  const long N = static_cast<long>(t_.size()) - 1;
  if (N < 1 || checkpoints_.empty()) throw std::logic_error("Adjoint::backward before forward");
  if (ybar.rows() != N + 1 || ybar.cols() != Y_.cols())
    bad("ybar", "an array (" + std::to_string(N + 1) + ", " + std::to_string(Y_.cols()) + ")",
        "(" + std::to_string(ybar.rows()) + ", " + std::to_string(ybar.cols()) + ")");
  stats_.recomputed_steps = stats_.linear_iterations = stats_.preconditioner_refreshes = 0;
  const int P = params_->count();
  VecX grad = VecX::Zero(P), bars = VecX::Zero(steps_->adjoint_size() * n);
  std::vector<StepRecord> states;
  for (long last = N; last > 0;) {
    const long first = ((last - 1) / interval_) * interval_;
    replay(first, last, states);
    for (long m = last; m > first; --m) {
      interruption_point();
      const StepRecord& s = states[m - first];
      const Data& d = steps_->at_end(s);
      output_vjp(d, ybar.row(m).transpose(), bars.head(n), grad);  // the objective at t_m
      steps_->transpose(s, bars, grad);                            // the step m−1 → m
    }
    last = first;
  }
  const StepRecord& s0 = checkpoints_[0];
  output_vjp(steps_->at_end(s0), ybar.row(0).transpose(), bars.head(n), grad);
  steps_->transpose_start(s0, bars, grad);
  q0bar_ = bars.head(n), qd0bar_ = bars.segment(n, n);
  for (int j = 0; j < P; ++j) grad(j) += initial_.col(j).head(n).dot(q0bar_) + initial_.col(j).tail(n).dot(qd0bar_);
  stats_.backward_time = std::chrono::duration<double>(Clock::now() - start).count();
  return grad;
}

}  // namespace rigidfem
