#include "rigidfem/newton_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "rigidfem/arms.hpp"
#include "rigidfem/dense_lu.hpp"
#include "rigidfem/dynamics.hpp"
#include "rigidfem/errors.hpp"
#include "rigidfem/gmres.hpp"
#include "rigidfem/stepper.hpp"

namespace rigidfem {

bool krylov_tangent(const System& sys, const IntegratorOptions& o) {
  if (!articulated(sys)) return false;
  return o.iteration_matrix == IterationMatrix::Krylov ||
         (o.iteration_matrix == IterationMatrix::Auto && sys.nq > krylov_from_nq);
}

MatX NewtonMatrix::solve(const MatX& B) {
  MatX X(B.rows(), B.cols());
  VecX b, x;
  for (Eigen::Index j = 0; j < B.cols(); ++j) {
    b = B.col(j);
    solve(b, x);
    X.col(j) = x;
  }
  return X;
}

void DenseLU::compute(const MatX& S) {
  const Eigen::Index n = S.rows();
  if (n >= dense_lu_blocked_from) {
    const Eigen::PartialPivLU<MatX> lu(S);
    LU_ = lu.matrixLU();
    P_ = lu.permutationP();
    return;
  }
  LU_ = S;
  Eigen::Transpositions<Eigen::Dynamic> swaps(n);
  double* a = LU_.data();
  for (Eigen::Index k = 0; k < n; ++k) {
    double* lk = a + k * n;  // column k: u_kk, then l_ik below it
    Eigen::Index p = k;
    for (Eigen::Index i = k + 1; i < n; ++i)
      if (std::abs(lk[i]) > std::abs(lk[p])) p = i;
    swaps.indices()(k) = static_cast<int>(p);
    if (p != k)
      for (Eigen::Index j = 0; j < n; ++j) std::swap(a[k + j * n], a[p + j * n]);
    if (lk[k] == 0.0) continue;  // singular: regularity reports it
    const double r = 1.0 / lk[k];
    for (Eigen::Index i = k + 1; i < n; ++i) lk[i] *= r;
    // the trailing block less l u_k: column j less l u_kj
    for (Eigen::Index j = k + 1; j < n; ++j) {
      double* cj = a + j * n;
      const double u = cj[k];
      for (Eigen::Index i = k + 1; i < n; ++i) cj[i] -= lk[i] * u;
    }
  }
  P_ = swaps;
}

void DenseLU::solve(const VecX& b, VecX& x) const {
  x = P_ * b;
  const Eigen::Index n = x.size();
  double* y = x.data();
  const double* a = LU_.data();
  // L y = P b, column by column: y_i −= l_ik y_k below k
  for (Eigen::Index k = 0; k < n; ++k) {
    const double* c = a + k * n;
    const double v = y[k];
    for (Eigen::Index i = k + 1; i < n; ++i) y[i] -= c[i] * v;
  }
  // U x = y: x_k = y_k / u_kk, then y_i −= u_ik x_k above k
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    const double* c = a + k * n;
    const double v = y[k] /= c[k];
    for (Eigen::Index i = 0; i < k; ++i) y[i] -= c[i] * v;
  }
}

void DenseLU::solve_transposed(const VecX& b, VecX& x) const {
  x = b;
  LU_.transpose().triangularView<Eigen::Lower>().solveInPlace(x);      // Uᵀ z = b
  LU_.transpose().triangularView<Eigen::UnitUpper>().solveInPlace(x);  // Lᵀ w = z
  x = P_.transpose() * x;                                              // x = Pᵀ w
}

void ComplexLU::compute(const Eigen::MatrixXcd& S) {
  const Eigen::Index n = S.rows();
  re_ = S.real(), im_ = S.imag();
  inverse_.resize(n);
  Eigen::Transpositions<Eigen::Dynamic> swaps(n);
  double *ar = re_.data(), *ai = im_.data();
  for (Eigen::Index k = 0; k < n; ++k) {
    double *rk = ar + k * n, *ik = ai + k * n;  // column k
    Eigen::Index p = k;
    double largest = std::abs(rk[k]) + std::abs(ik[k]);
    for (Eigen::Index i = k + 1; i < n; ++i)
      if (const double size = std::abs(rk[i]) + std::abs(ik[i]); size > largest) largest = size, p = i;
    swaps.indices()(k) = static_cast<int>(p);
    if (p != k)
      for (Eigen::Index j = 0; j < n; ++j) std::swap(ar[k + j * n], ar[p + j * n]), std::swap(ai[k + j * n], ai[p + j * n]);
    if (rk[k] == 0.0 && ik[k] == 0.0) {  // singular: regularity reports it
      inverse_(k) = 0.0;
      continue;
    }
    const cplx r = cplx(1.0) / cplx(rk[k], ik[k]);
    inverse_(k) = r;
    for (Eigen::Index i = k + 1; i < n; ++i) {  // l_ik = s_ik / u_kk
      const double x = rk[i], y = ik[i];
      rk[i] = x * r.real() - y * r.imag(), ik[i] = x * r.imag() + y * r.real();
    }
    // column j less l u_kj: (l_re + i l_im)(u_re + i u_im) in four real products
    for (Eigen::Index j = k + 1; j < n; ++j) {
      double *rj = ar + j * n, *ij = ai + j * n;
      const double ur = rj[k], ui = ij[k];
      for (Eigen::Index i = k + 1; i < n; ++i) {
        rj[i] -= rk[i] * ur - ik[i] * ui;
        ij[i] -= rk[i] * ui + ik[i] * ur;
      }
    }
  }
  P_ = swaps;
}

Eigen::VectorXcd ComplexLU::pivots() const {
  Eigen::VectorXcd u(re_.rows());
  u.real() = re_.diagonal(), u.imag() = im_.diagonal();
  return u;
}

void ComplexLU::solve(const Eigen::VectorXcd& b, Eigen::VectorXcd& x) const {
  const Eigen::Index n = b.size();
  xr_.resize(n), xi_.resize(n);
  const auto& to = P_.indices();
  for (Eigen::Index i = 0; i < n; ++i) xr_(to(i)) = b(i).real(), xi_(to(i)) = b(i).imag();  // P b
  double *yr = xr_.data(), *yi = xi_.data();
  const double *ar = re_.data(), *ai = im_.data();
  // L y = P b by columns
  for (Eigen::Index k = 0; k < n; ++k) {
    const double *rk = ar + k * n, *ik = ai + k * n, vr = yr[k], vi = yi[k];
    for (Eigen::Index i = k + 1; i < n; ++i) {
      yr[i] -= rk[i] * vr - ik[i] * vi;
      yi[i] -= rk[i] * vi + ik[i] * vr;
    }
  }
  // U x = y: x_k = y_k / u_kk (by the reciprocal), then y_i −= u_ik x_k above k
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    const double *rk = ar + k * n, *ik = ai + k * n;
    const cplx v = cplx(yr[k], yi[k]) * inverse_(k);
    yr[k] = v.real(), yi[k] = v.imag();
    for (Eigen::Index i = 0; i < k; ++i) {
      yr[i] -= rk[i] * v.real() - ik[i] * v.imag();
      yi[i] -= rk[i] * v.imag() + ik[i] * v.real();
    }
  }
  x.resize(n);
  x.real() = xr_, x.imag() = xi_;
}

void ComplexLU::solve_transposed(const Eigen::VectorXcd& b, Eigen::VectorXcd& x) const {
  const Eigen::Index n = b.size();
  xr_ = b.real(), xi_ = b.imag();
  double *yr = xr_.data(), *yi = xi_.data();
  const double *ar = re_.data(), *ai = im_.data();
  // Uᵀ z = b: z_j = (b_j − Σ_{i<j} u_ij z_i) / u_jj, u_ij (i < j) in column j above the diagonal
  for (Eigen::Index j = 0; j < n; ++j) {
    const double *rj = ar + j * n, *ij = ai + j * n;
    double sr = yr[j], si = yi[j];
    for (Eigen::Index i = 0; i < j; ++i) {
      sr -= rj[i] * yr[i] - ij[i] * yi[i];
      si -= rj[i] * yi[i] + ij[i] * yr[i];
    }
    const cplx z = cplx(sr, si) * inverse_(j);
    yr[j] = z.real(), yi[j] = z.imag();
  }
  // Lᵀ w = z: w_j = z_j − Σ_{i>j} l_ij w_i, l_ij in column j below the diagonal
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    const double *rj = ar + j * n, *ij = ai + j * n;
    double sr = yr[j], si = yi[j];
    for (Eigen::Index i = j + 1; i < n; ++i) {
      sr -= rj[i] * yr[i] - ij[i] * yi[i];
      si -= rj[i] * yi[i] + ij[i] * yr[i];
    }
    yr[j] = sr, yi[j] = si;
  }
  // x = Pᵀ w: x_i = w_{to(i)}
  x.resize(n);
  const auto& to = P_.indices();
  for (Eigen::Index i = 0; i < n; ++i) x(i) = cplx(yr[to(i)], yi[to(i)]);
}

namespace {

/// What check_regular tests against 1e-15 for a factorisation with these pivots (the diagonal of U): their
/// spread min |u_ii| / max |u_ii| (|re| + |im| for a complex pivot) while it is above 1e-8, else rcond(), the
/// estimate of 1/cond₁(S). The estimate takes several solves and, in complex arithmetic, a hypot per entry: on
/// the crane (n = 21) radau5's complex estimate cost as much as its factorisation. A singular S leaves a pivot at
/// round-off of the largest, so the spread falls far below 1e-8 there and the estimate decides as before.
template <class Pivots, class Rcond>
double regularity(const Pivots& pivots, Rcond&& rcond) {
  double least = std::numeric_limits<double>::infinity(), most = 0.0;
  for (Eigen::Index i = 0; i < pivots.size(); ++i) {
    const double size = std::abs(std::real(pivots(i))) + std::abs(std::imag(pivots(i)));
    if (!std::isfinite(size)) return rcond();
    least = std::min(least, size), most = std::max(most, size);
  }
  const double spread = least / most;
  return spread > 1e-8 ? spread : rcond();
}

/// The dense form: M, C, K at the tangent, S by LU.
class DenseNewtonMatrix final : public NewtonMatrix {
 public:
  DenseNewtonMatrix(const System& sys, IntegratorStats& stats) : sys_(sys), d_(sys), stats_(stats) {}

  void linearize(double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& s) override {
    set_arm_forces(sys_, d_, s);
    auto [drdq, drdqd] = inverse_dynamics_derivatives(sys_, d_, t, q, qd, qdd);
    K_ = std::move(drdq), C_ = std::move(drdqd);
    M_ = mass_matrix(sys_, d_, t, q);
    ++stats_.jacobians;
    if (!analytic_derivatives(sys_)) stats_.rhs_evaluations += 4 * sys_.nq;  // the central differences
  }

  void derivative(const VecX& dq, const VecX& dqd, const VecX& dqdd, VecX& out) override {
    out.noalias() = M_ * dqdd;
    out.noalias() += C_ * dqd;
    out.noalias() += K_ * dq;
  }

  double factor(double c1, double c2, const VecX& e) override {
    S_ = M_ + c1 * C_ + c2 * K_;
    if (e.size()) S_.diagonal() += e;
    auto lu = std::make_shared<DenseLU>();
    lu->compute(S_);
    lu_ = lu;
    ++stats_.factorizations;
    return regularity(lu_->pivots(), [&] { return Eigen::PartialPivLU<MatX>(S_).rcond(); });
  }

  double factor(cplx c1, cplx c2, int slot) override {
    Sc_ = M_.cast<cplx>() + c1 * C_.cast<cplx>() + c2 * K_.cast<cplx>();
    luc_[slot].compute(Sc_);
    ++stats_.factorizations;
    return regularity(luc_[slot].pivots(), [&] { return Eigen::PartialPivLU<Eigen::MatrixXcd>(Sc_).rcond(); });
  }

  void solve(const VecX& b, VecX& x) override { lu_->solve(b, x); }
  void solve(const VecXc& b, VecXc& x, int slot) override { luc_[slot].solve(b, x); }
  void precondition_transposed(const VecX& b, VecX& x) override { lu_->solve_transposed(b, x); }
  void precondition_transposed(const VecXc& b, VecXc& x) override { luc_[0].solve_transposed(b, x); }
  bool krylov() const override { return false; }
  std::shared_ptr<const DenseLU> dense_factor() const override { return lu_; }

 private:
  const System& sys_;
  Data d_;
  IntegratorStats& stats_;
  MatX K_, C_, M_, S_;
  Eigen::MatrixXcd Sc_;
  std::shared_ptr<DenseLU> lu_;
  ComplexLU luc_[complex_slots];
};

/// M + diag(δ) for complex δ factorised by the articulated-body recursion (recursive.hpp's aba_factor and
/// aba_solve, which the real shift uses, in complex arithmetic, for a system at rest without gravity or
/// loads): leaves to root, U = I^A S, D = Sᵀ U + diag δ (inverted by LU), the parent gets I^A − U D⁻¹ Uᵀ;
/// the solve runs ABA's bias passes with the forces b. Transposes, not adjoints: M + diag δ is complex
/// symmetric.
class ComplexArticulated {
  using Scalar = cplx;
  using Mat6s = Eigen::Matrix<Scalar, 6, 6>;
  using Vec6s = Eigen::Matrix<Scalar, 6, 1>;
  using Sub = Eigen::Matrix<Scalar, 6, Eigen::Dynamic, 0, 6, 6>;
  using Small = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
  using SmallVec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1, 0, 6, 1>;
  using VecS = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

 public:
  explicit ComplexArticulated(const System& sys)
      : sys_(sys), IA_(sys.nbodies), S_(sys.nbodies), U_(sys.nbodies), Dinv_(sys.nbodies), pA_(sys.nbodies),
        a_(sys.nbodies), u_(sys.nbodies) {}

  /// At the spatial kinematics of d (its inertias I_p and axes).
  void factor(const Data& d, const VecS& delta) {
    for (int p = 0; p < sys_.nbodies; ++p) IA_[p] = d.I[p].cast<Scalar>();
    for (int p = sys_.nbodies - 1; p >= 0; --p) {
      const int k0 = sys_.q_index[p], nf = sys_.nq_of[p];
      S_[p].resize(6, nf);
      for (int k = 0; k < nf; ++k) S_[p].col(k) = d.axes[sys_.q_use[k0 + k]].cast<Scalar>();
      U_[p].noalias() = IA_[p] * S_[p];
      if (nf > 0) {
        Small D = S_[p].transpose() * U_[p];
        D.diagonal() += delta.segment(k0, nf);
        Dinv_[p] = D.inverse();
        if (!Dinv_[p].allFinite())
          throw SimulationError(d.t, "the preconditioner M + diag(c1 b + c2 k) of the Newton matrix is singular at body '" +
                                         sys_.body_names[p] + "'");
        IA_[p].noalias() -= U_[p] * Dinv_[p] * U_[p].transpose();
        // I^A is complex symmetric; its rounding is not, and the antisymmetric part grows up a chain of stiff
        // springs (measured: ×3.8 per body of a 40-element strip at radau5's complex shift, the solve 30 % off at
        // the root). Kept symmetric, it matches the real recursion at a real shift to 1e-13.
        IA_[p] = (0.5 * (IA_[p] + IA_[p].transpose())).eval();
      }
      if (sys_.parent[p] >= 0) IA_[sys_.parent[p]] += IA_[p];
    }
  }

  /// x = (M + diag δ)⁻¹ b (x may not be b).
  void solve(const VecS& b, VecS& x) {
    x.resize(sys_.nq);
    for (int p = 0; p < sys_.nbodies; ++p) pA_[p].setZero();
    // u = b − Sᵀ p^A, the parent gets p^A + U D⁻¹ u (leaves to root)
    for (int p = sys_.nbodies - 1; p >= 0; --p) {
      Vec6s pa = pA_[p];
      if (sys_.nq_of[p] > 0) {
        u_[p] = b.segment(sys_.q_index[p], sys_.nq_of[p]) - S_[p].transpose() * pA_[p];
        pa.noalias() += U_[p] * (Dinv_[p] * u_[p]);
      }
      if (sys_.parent[p] >= 0) pA_[sys_.parent[p]] += pa;
    }
    // x_p = D⁻¹ (u − Uᵀ a_λ), a = a_λ + S x_p (root to leaves)
    for (int p = 0; p < sys_.nbodies; ++p) {
      Vec6s a = sys_.parent[p] >= 0 ? a_[sys_.parent[p]] : Vec6s::Zero();
      if (sys_.nq_of[p] > 0) {
        const SmallVec xp = Dinv_[p] * (u_[p] - U_[p].transpose() * a);
        x.segment(sys_.q_index[p], sys_.nq_of[p]) = xp;
        a.noalias() += S_[p] * xp;
      }
      a_[p] = a;
    }
  }

 private:
  const System& sys_;
  std::vector<Mat6s> IA_;
  std::vector<Sub> S_, U_;
  std::vector<Small> Dinv_;
  std::vector<Vec6s> pA_, a_;
  std::vector<SmallVec> u_;
};

/// The matrix-free form (the header's comment).
class KrylovNewtonMatrix final : public NewtonMatrix {
 public:
  /// GMRES stops at a relative residual of 1e-3, an inexact Newton step: measured on Kane's beam (m = 100,
  /// 15 s), 1.5-3 times cheaper than at 1e-6 (GMRES iterations per Newton iteration 1.7 against 2.4 for
  /// generalised-α, 6.2 against 8.7 for radau5), the tip within 2e-9 m of the dense tangent's at m = 200.
  static constexpr double rtol = 1e-3;
  static constexpr int max_iterations = 60;

  KrylovNewtonMatrix(const System& sys, IntegratorStats& stats)
      : sys_(sys), d0_(sys), dp_(sys), stats_(stats) {
    complex_.emplace_back(sys);
  }

  void linearize(double t, const VecX& q, const VecX& qd, const VecX& qdd, const VecX& s) override {
    t_ = t, q_ = q, qd_ = qd, qdd_ = qdd;
    set_arm_forces(sys_, d0_, s);
    set_arm_forces(sys_, dp_, s);
    r0_ = inverse_dynamics(sys_, d0_, t, q, qd, qdd);  // leaves the spatial kinematics the factors use
    ++stats_.rhs_evaluations;
    ++stats_.jacobians;
  }

  /// (r(q + ε δq, q̇ + ε δq̇, q̈ + ε δq̈) − r)/ε, ε making the larger relative change of q and q̇ √ε_mach
  /// (of q̈ when both are zero). r is linear in q̈, so δq̈ does not limit ε: held to √ε_mach too, the
  /// displacements (γh)² δq̈ of a stiff beam's step would be round-off in r (measured: GMRES then stalled
  /// at relative residuals of 1e-5, taking its 60 iterations per solve on a 100-element cantilever).
  void derivative(const VecX& dq, const VecX& dqd, const VecX& dqdd, VecX& out) override {
    double size = std::max(max_abs(dq) / (1.0 + max_abs(q_)), max_abs(dqd) / (1.0 + max_abs(qd_)));
    if (size == 0.0) size = max_abs(dqdd) / (1.0 + max_abs(qdd_));
    if (size == 0.0) {
      out.setZero(sys_.nq);
      return;
    }
    const double eps = std::sqrt(std::numeric_limits<double>::epsilon()) / size;
    qe_ = q_ + eps * dq, qde_ = qd_ + eps * dqd, qdde_ = qdd_ + eps * dqdd;
    out = (inverse_dynamics(sys_, dp_, t_, qe_, qde_, qdde_) - r0_) / eps;
    ++stats_.rhs_evaluations;
  }

  double factor(double c1, double c2, const VecX& e) override {
    c1_ = c1, c2_ = c2;
    e_ = e.size() ? e : VecX::Zero(sys_.nq);
    spring_armature(sys_, d0_, c1, c2, real_delta_);
    real_delta_ += e_;
    factor_armature(sys_, d0_, real_delta_);  // at the spatial kinematics linearize() left in d0_
    ++stats_.factorizations;
    return 1.0;  // a singular pivot of the recursion throws
  }

  double factor(cplx c1, cplx c2, int slot) override {
    z1_[slot] = c1, z2_[slot] = c2;
    spring_armature(sys_, d0_, c1, c2, delta_);
    while (slot >= static_cast<int>(complex_.size())) complex_.emplace_back(sys_);  // radau9's second block
    complex_[slot].factor(d0_, delta_);
    ++stats_.factorizations;
    return 1.0;
  }

  /// GMRES on S x = (K c₂ + C c₁ + M) x + e ⊙ x, preconditioned by the real factor.
  void solve(const VecX& b, VecX& x) override {
    auto S = [&](const VecX& v, VecX& out) {
      cq_ = c2_ * v, cv_ = c1_ * v;
      derivative(cq_, cv_, v, out);
      out.array() += e_.array() * v.array();
    };
    auto P = [&](const VecX& v, VecX& out) { solve_armature(sys_, d0_, v, out); };
    stats_.linear_iterations += gmres_.solve(S, P, b, x, rtol, max_iterations);
  }

  /// GMRES on S x = (K c₂ + C c₁ + M) x for complex x and shifts: S is real-linear in x, so each product is
  /// two directional derivatives, of the real and of the imaginary part.
  void solve(const VecXc& b, VecXc& x, int slot) override {
    auto S = [&](const VecXc& v, VecXc& out) {
      out.resize(v.size());
      zq_ = z2_[slot] * v, zv_ = z1_[slot] * v;
      for (int part = 0; part < 2; ++part) {
        if (part == 0)
          cq_ = zq_.real(), cv_ = zv_.real(), ca_ = v.real();
        else
          cq_ = zq_.imag(), cv_ = zv_.imag(), ca_ = v.imag();
        derivative(cq_, cv_, ca_, w_);
        if (part == 0)
          out.real() = w_;
        else
          out.imag() = w_;
      }
    };
    auto P = [&](const VecXc& v, VecXc& out) { complex_[slot].solve(v, out); };
    stats_.linear_iterations += gmresc_.solve(S, P, b, x, rtol, max_iterations);
  }

  void precondition_transposed(const VecX& b, VecX& x) override { solve_armature(sys_, d0_, b, x); }
  void precondition_transposed(const VecXc& b, VecXc& x) override { complex_[0].solve(b, x); }
  bool krylov() const override { return true; }

 private:
  const System& sys_;
  Data d0_, dp_;  // the tangent's state; the perturbed states
  IntegratorStats& stats_;
  double t_ = 0.0, c1_ = 0.0, c2_ = 0.0;
  cplx z1_[complex_slots], z2_[complex_slots];
  VecX q_, qd_, qdd_, r0_, qe_, qde_, qdde_, e_, cq_, cv_, ca_, w_;
  VecX real_delta_;      // the real shift's armature
  VecXc delta_, zq_, zv_;  // the complex shift's armature; c₂ x and c₁ x of a complex product
  std::vector<ComplexArticulated> complex_;  // a factorisation per complex slot used (one for radau5's runs)
  Gmres<double> gmres_;
  Gmres<cplx> gmresc_;
};

}  // namespace

std::unique_ptr<NewtonMatrix> NewtonMatrix::make(const System& sys, const IntegratorOptions& o,
                                                 IntegratorStats& stats) {
  if (krylov_tangent(sys, o)) return std::make_unique<KrylovNewtonMatrix>(sys, stats);
  return std::make_unique<DenseNewtonMatrix>(sys, stats);
}

}  // namespace rigidfem

