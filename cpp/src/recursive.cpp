#include "rigidfem/recursive.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "rigidfem/errors.hpp"

namespace rigidfem {

void spatial_inertia(double m, const Vec3& c, const Mat3& Ic, Mat6& I) {
  // [[I_C + m C Cᵀ, m C], [m Cᵀ, m 1]], C = [c]×, C Cᵀ = |c|² 1 − c cᵀ
  const Vec3 mc = m * c;
  I.topLeftCorner<3, 3>() = Ic - mc * c.transpose();
  I.topLeftCorner<3, 3>().diagonal().array() += mc.dot(c);
  I.topRightCorner<3, 3>() << 0.0, -mc.z(), mc.y(), mc.z(), 0.0, -mc.x(), -mc.y(), mc.x(), 0.0;
  I.bottomLeftCorner<3, 3>() = I.topRightCorner<3, 3>().transpose();
  I.bottomRightCorner<3, 3>() = m * Mat3::Identity();
}

Mat6 spatial_inertia(double m, const Vec3& c, const Mat3& Ic) {
  Mat6 I;
  spatial_inertia(m, c, Ic, I);
  return I;
}

namespace {

void require_tree(const System& sys) {
  if (sys.algorithm != Algorithm::Recursive)
    throw std::logic_error("recursive algorithms need a system compiled with algorithm=recursive");
}

}  // namespace

Vec6 gravity_acceleration(const System& sys, const Data& d) {
  Vec6 a0 = Vec6::Zero();
  a0.tail<3>() = -d.load_factor * sys.gravity;  // the base accelerates upwards: a_0 = −g
  return a0;
}

void spatial_kinematics(const System& sys, Data& d) {
  // The previous body's velocity v = (ω, v_O): the parent's in a chain (no reload of d.v). Its halves and the joint
  // bias c = (c_ω, c_v) are kept as 3-vectors: as 6-vectors GCC paired components across the halves and stalled on
  // reading back what it had just stored (measured: a quarter of the spatial kinematics' time).
  Vec3 w = Vec3::Zero(), vO = Vec3::Zero();
  for (int p = 0; p < sys.nbodies; ++p) {
    if (sys.parent[p] != p - 1) {
      const Vec6 v = sys.parent[p] >= 0 ? d.v[sys.parent[p]] : Vec6(Vec6::Zero());
      w = v.head<3>(), vO = v.tail<3>();
    }
    Vec3 cw = Vec3::Zero(), cv = Vec3::Zero();
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
      const Vec3 sw = d.axes[u].head<3>(), sv = d.axes[u].tail<3>();
      const double qd = d.qda(sys.use_coord[u]);
      // ṡ = v_before ×m s (the axis moves with the frame carrying it): c += (ω × s_ω, ω × s_v + v_O × s_ω) q̇
      cw += w.cross(sw) * qd;
      cv += (w.cross(sv) + vO.cross(sw)) * qd;
      w += sw * qd;
      vO += sv * qd;
    }
    d.v[p] << w, vO;
    d.c[p] << cw, cv;
    const Mat3 R = d.T[p].topLeftCorner<3, 3>();
    const Mat3 RI = R * d.inertia[p];
    spatial_inertia(d.mass[p], R * d.com[p] + d.T[p].topRightCorner<3, 1>(), RI * R.transpose(), d.I[p]);
    d.fext[p].setZero();
  }
  for_each_body_load(sys, d, true, [&](int body, const AppliedLoad& a, bool) {
    // As a spatial force at the global origin: (x × F + τ, F).
    d.fext[body].head<3>() += a.x.cross(a.F) + a.tau;
    d.fext[body].tail<3>() += a.F;
  });
}

void rnea_pass(const System& sys, Data& d) {
  const Vec6 a0 = gravity_acceleration(sys, d);
  Vec6 a = a0;  // the previous body's acceleration: the parent's in a chain
  for (int p = 0; p < sys.nbodies; ++p) {
    if (sys.parent[p] != p - 1) a = parent_value(sys, d.a, p, a0);
    a += d.c[p];
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) a += d.axes[u] * d.qdda(sys.use_coord[u]);
    d.a[p] = a;
    d.sf[p] = d.I[p] * a + crossf(d.v[p], d.I[p] * d.v[p]) - d.fext[p];
  }
  accumulate_subtrees(sys, d.sf);
}

void rnea_forces(const System& sys, Data& d) {
  require_tree(sys);
  spatial_kinematics(sys, d);
  rnea_pass(sys, d);
  // f = −(Sᵀ f̄)_free + passive: what drives the free coordinates besides A q̈.
  for (int k = 0; k < sys.nq; ++k) {
    const int i = sys.free_coords[k];
    d.f(k) = -d.axes[sys.q_use[k]].dot(d.sf[sys.coords[i].body]) + passive_force(sys, d, i, true);
  }
}

void crba(const System& sys, Data& d) {
  require_tree(sys);
  spatial_kinematics(sys, d);
  // Composite inertias I^c_p = Σ_subtree I_k (ground coordinates: plain sums).
  d.IA = d.I;
  accumulate_subtrees(sys, d.IA);
  // a_ij = s_iᵀ I^c_b s_j for coordinate i on the path from the root to j's body b; the other
  // entries (coordinates on different branches) stay zero from the first allocation.
  if (d.A.rows() != sys.nq) d.A.setZero(sys.nq, sys.nq);
  for (int b = 0; b < sys.nbodies; ++b)
    for (int v = sys.use_start[b]; v < sys.use_start[b + 1]; ++v) {
      interruption_point();
      const int l = sys.use_q[v];
      if (l < 0) continue;
      const Vec6 F = d.IA[b] * d.axes[v];
      for (int body = b; body >= 0; body = sys.parent[body]) {
        const int last = body == b ? v : sys.use_start[body + 1] - 1;
        for (int u = sys.use_start[body]; u <= last; ++u) {
          const int k = sys.use_q[u];
          if (k >= 0) d.A(k, l) = d.A(l, k) = d.axes[u].dot(F);
        }
      }
    }
}

namespace {

using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;

// D⁻¹ of a symmetric positive definite D (4 ≤ nf ≤ 6) by Cholesky; false if D is not positive definite.
bool invert_spd(const SmallMat& D, SmallMat& Dinv) {
  const Eigen::LLT<SmallMat> llt(D);
  if (llt.info() != Eigen::Success) return false;
  Dinv = llt.solve(SmallMat::Identity(D.rows(), D.cols()));
  return true;
}

// D⁻¹ of a symmetric 3 × 3 D through its factors D = L diag(d) Lᵀ (L unit lower: Cholesky's arithmetic without its
// square roots), written out: N = L⁻¹, D⁻¹ = Nᵀ diag(1/d) N; false unless D is positive definite. The pivots'
// reciprocals come from leading minors, so that their three divisions run side by side instead of one after the
// other (they stood in the chain of dependent operations from one body to the next): d₁ = p₁/d₀ with
// p₁ = D₀₀ D₁₁ − D₁₀², d₂ = n/(d₀ p₁) with n = p₁ q − m² = D₀₀ det D (Desnanot–Jacobi), q = D₀₀ D₂₂ − D₂₀²,
// m = D₀₀ D₂₁ − D₁₀ D₂₀: the same products as the elimination's, scaled, so the same accuracy (ε cond D: measured on
// 1,800 random matrices of condition 1e2 to 1e12 against exact rational inverses, where the cofactors' det D gave up
// to ε cond² D). Positive d₀, p₁ and n are Sylvester's criterion. Where d₀, p₁ or n is out of range (entries beyond
// about 1e±18, or D close to singular) the elimination in its own order.
bool invert_spd3(const Mat3& D, Mat3& Dinv) {
  const double d0 = D(0, 0), b = D(1, 0), c = D(2, 0);
  const double p1 = d0 * D(1, 1) - b * b, q = d0 * D(2, 2) - c * c, m = d0 * D(2, 1) - b * c;
  const double n = p1 * q - m * m;
  const double i0 = 1.0 / d0, l10 = b * i0, l20 = c * i0, e21 = D(2, 1) - l20 * b;
  constexpr double lo = 0x1p-250, hi = 0x1p250;
  double i1, i2;
  if (d0 > 0x1p-125 && d0 < 0x1p125 && p1 > lo && p1 < hi && n > lo && n < hi) {
    const double r1 = 1.0 / p1, rn = 1.0 / n;
    i1 = d0 * r1;
    i2 = (d0 * p1) * rn;
  } else {
    const double d1 = D(1, 1) - l10 * b;
    if (!(d0 > 0.0 && d1 > 0.0)) return false;
    i1 = 1.0 / d1;
    const double d2 = D(2, 2) - l20 * c - (e21 * i1) * e21;
    if (!(d2 > 0.0)) return false;
    i2 = 1.0 / d2;
  }
  const double l21 = e21 * i1;
  const double n10 = -l10, n21 = -l21, n20 = l21 * l10 - l20;
  Dinv(0, 0) = i0 + n10 * n10 * i1 + n20 * n20 * i2;
  Dinv(1, 0) = Dinv(0, 1) = n10 * i1 + n21 * n20 * i2;
  Dinv(2, 0) = Dinv(0, 2) = n20 * i2;
  Dinv(1, 1) = i1 + n21 * n21 * i2;
  Dinv(2, 1) = Dinv(1, 2) = n21 * i2;
  Dinv(2, 2) = i2;
  return true;
}

[[noreturn]] void singular_articulated_inertia(const System& sys, const Data& d, int p) {
  throw SimulationError(d.t, "articulated inertia of body '" + sys.body_names[p] +
                                 "' is singular (a massless chain or a singular configuration)");
}

// D⁻¹ of a symmetric N × N D (N = 1, 2, 3: the fixed-size paths); false unless D is positive definite.
template <int N>
bool invert_fixed(const Eigen::Matrix<double, N, N>& D, Eigen::Matrix<double, N, N>& Dinv) {
  if constexpr (N == 1) {
    if (!(D(0, 0) > 0.0)) return false;
    Dinv(0, 0) = 1.0 / D(0, 0);
    return true;
  } else if constexpr (N == 2) {  // D⁻¹ = [[d, −b], [−b, a]] / (a d − b²)
    const double det = D(0, 0) * D(1, 1) - D(0, 1) * D(0, 1);
    if (!(D(0, 0) > 0.0 && det > 0.0)) return false;
    Dinv << D(1, 1) / det, -D(0, 1) / det, -D(0, 1) / det, D(0, 0) / det;
    return true;
  } else {
    return invert_spd3(D, Dinv);
  }
}

// Calls f(std::integral_constant<int, N>()) for a body's N = nf free coordinates where N is 1, 2 or 3 (the
// fixed-size paths); false for any other nf.
template <class F>
bool fixed_size(int nf, F&& f) {
  switch (nf) {
    case 1: f(std::integral_constant<int, 1>()); return true;
    case 2: f(std::integral_constant<int, 2>()); return true;
    case 3: f(std::integral_constant<int, 3>()); return true;
    default: return false;
  }
}

// A ball body (System::ball) turns about one point o, its frame's origin, by three free rotations about axes
// E = [e₁ e₂ e₃] through it: S = Φ E with Φ = [1; [o]×] (each axis is (e, o × e)). Then U = P E and D = Eᵀ Q E with
// P = I^A Φ and Q = Φᵀ I^A Φ, the articulated inertia about o, and U D⁻¹ Uᵀ = P Q⁻¹ Pᵀ (E cancels: a spherical
// joint's projection, which its angles do not change). D is as ill-conditioned as E squared: near a gimbal lock
// (|det E| = |cos φ2| of ZYX angles → 0) inverting it lost digits of the accelerations, and 1e-6 rad from pitch π/2
// its Sylvester test failed (a spurious "singular" where the mass matrix is still positive definite), while Q stays
// well-conditioned. So where |det E| < pivot_det the factors come from Q: D⁻¹ = E⁻¹ Q⁻¹ E⁻ᵀ, E⁻¹'s rows
// (e₂ × e₃, e₃ × e₁, e₁ × e₂) / det E, and the passes use them as they stand (q̈ then carries an error of about
// ε / |det E| relative to its size, where solving with the factors apart would keep ε; measured: a residual of A q̈ = f
// of 1.6e-13 |A| |q̈| 1e-6 rad from the lock, at most 1.6e-12 in 200 random chains).
constexpr double pivot_det = 1e-2;

// det E = e₁ · (e₂ × e₃) of a ball body's axes S = Φ E.
double axes_volume(const Subspace& S) { return S.col(0).head<3>().dot(S.col(1).head<3>().cross(S.col(2).head<3>())); }

// The ball body's inertia part from its factors about its pivot: U = P E, D⁻¹ = E⁻¹ Q⁻¹ E⁻ᵀ, I^a = I^A − P Q⁻¹ Pᵀ.
// Out of line and in its own arithmetic (Cholesky's inverse, products in another order): sharing invert_spd3 and
// Eigen's 6 × 3 product with fixed_inertia, GCC stopped inlining them there (measured 8-13 % slower).
[[gnu::cold, gnu::noinline]] void pivot_inertia(const System& sys, Data& d, int p) {
  const auto E = d.S[p].leftCols<3>().topRows<3>();
  Mat3 N;  // E⁻¹ det E
  N << E.col(1).cross(E.col(2)).transpose(), E.col(2).cross(E.col(0)).transpose(), E.col(0).cross(E.col(1)).transpose();
  const double det = N.row(0).dot(E.col(0));
  if (!(std::abs(det) > 0.0)) singular_articulated_inertia(sys, d, p);
  const SmallMat Einv = N / det;
  const Vec3 o = d.T[p].topRightCorner<3, 1>();
  Mat6& IA = d.IA[p];
  // P = I^A Φ = I^A_{:,ω} + I^A_{:,v} [o]× (column by column), Q = Φᵀ P = P_ω − [o]× P_v
  Eigen::Matrix<double, 6, 3> P;
  P.col(0) = IA.col(0) + IA.col(4) * o.z() - IA.col(5) * o.y();
  P.col(1) = IA.col(1) + IA.col(5) * o.x() - IA.col(3) * o.z();
  P.col(2) = IA.col(2) + IA.col(3) * o.y() - IA.col(4) * o.x();
  SmallMat Q(3, 3), Qinv;
  for (int j = 0; j < 3; ++j) Q.col(j) = P.col(j).head<3>() - o.cross(P.col(j).tail<3>());
  if (!invert_spd(Q, Qinv)) singular_articulated_inertia(sys, d, p);
  d.U6[p] = P * E;
  d.Dinv[p] = Einv * (Qinv * Einv.transpose());
  IA.noalias() -= P * (Qinv * P.transpose());
}

// ABA pass 2, inertia part, of a body with N = 1, 2 or 3 free coordinates (a revolute joint, an sde's two or
// three rotations) in fixed-size arithmetic: U = I^A S, D = Sᵀ U + diag(δ), I^a = I^A − U D⁻¹ Uᵀ; a ball body near
// a gimbal lock without an armature on its coordinates (with one, D = Eᵀ Q E + diag(δ) does not factor through E)
// from its pivot's.
template <int N>
void fixed_inertia(const System& sys, Data& d, const VecX* armature, int p) {
  using MatN = Eigen::Matrix<double, N, N>;
  if constexpr (N == 3)
    if (sys.ball[p] && std::abs(axes_volume(d.S[p])) < pivot_det &&
        (!armature || armature->template segment<3>(sys.q_index[p]).isZero(0.0)))
      return pivot_inertia(sys, d, p);
  const auto S = d.S[p].template leftCols<N>();
  const Eigen::Matrix<double, 6, N> U = d.IA[p] * S;
  MatN D = S.transpose() * U, Dinv;
  if (armature) D.diagonal() += armature->template segment<N>(sys.q_index[p]);
  if (!invert_fixed<N>(D, Dinv)) singular_articulated_inertia(sys, d, p);
  d.U6[p] = U;
  d.Dinv[p] = Dinv;
  // I^A −= W Uᵀ with W = U D⁻¹, written out column by column as 6-vector operations instead of Eigen's lazy
  // product (measured, C++ forward dynamics, least of 11: the 3-rotation cantilever 2.20-2.24 → 2.09 µs at m = 10
  // and 21.8 → 20.7-20.9 µs at m = 100; the strip 2.09-2.13 → 1.93-1.99 µs at m = 16, 8.08 → 7.79-7.97 at m = 64)
  const Eigen::Matrix<double, 6, N> W = U * Dinv;
  Mat6& IA = d.IA[p];
  for (int k = 0; k < 6; ++k) {
    Vec6 t = W.col(0) * U(k, 0);
    for (int j = 1; j < N; ++j) t += W.col(j) * U(k, j);
    IA.col(k) -= t;
  }
}

// ABA pass 2, inertia part (leaves to root): S the free axes, U = I^A S, D = Sᵀ U + diag(δ), and
// the parent gets I^a = I^A − U D⁻¹ Uᵀ, kept in d.IA[p] for the bias pass. δ = 0 without an armature.
// One to three free coordinates take the fixed-size path (fixed_inertia).
void articulated_inertias(const System& sys, Data& d, const VecX* armature) {
  d.IA = d.I;
  for (int p = sys.nbodies - 1; p >= 0; --p) {
    const int k0 = sys.q_index[p], nf = sys.nq_of[p];
    Subspace& S = d.S[p];
    S.resize(6, nf);
    for (int k = 0; k < nf; ++k) S.col(k) = d.axes[sys.q_use[k0 + k]];
    if (!fixed_size(nf, [&](auto N) { fixed_inertia<N>(sys, d, armature, p); })) {
      d.U6[p].noalias() = d.IA[p] * S;
      if (nf > 0) {
        SmallMat D = S.transpose() * d.U6[p];
        if (armature) D.diagonal() += armature->segment(k0, nf);
        if (!invert_spd(D, d.Dinv[p])) singular_articulated_inertia(sys, d, p);
        d.IA[p] -= d.U6[p] * d.Dinv[p] * d.U6[p].transpose();
      }
    }
    if (sys.parent[p] >= 0) d.IA[sys.parent[p]] += d.IA[p];
  }
}

// The fixed-size bias of fixed_inertia's body with the bias force pA: u = τ − Sᵀ p^A, and U D⁻¹ u added into the
// parent's p^a.
template <int N>
void fixed_bias(const System& sys, Data& d, const VecX& tau, int p, const Vec6& pA, Vec6& pa) {
  const Eigen::Matrix<double, N, N> Dinv = d.Dinv[p].template topLeftCorner<N, N>();
  const Eigen::Matrix<double, N, 1> u =
      tau.template segment<N>(sys.q_index[p]) - d.S[p].template leftCols<N>().transpose() * pA;
  d.u[p] = u;
  // U (D⁻¹ u) and, in fixed_acceleration, S q̈ as sums of columns (measured: 1 % off the forward dynamics of the
  // 3-rotation cantilever and of the strip at m = 64 against Eigen's products of blocks of dynamic matrices)
  const Eigen::Matrix<double, N, 1> y = Dinv * u;
  for (int j = 0; j < N; ++j) pa += d.U6[p].col(j) * y(j);
}

// The fixed-size accelerations of fixed_inertia's body: q̈ = D⁻¹ (u − Uᵀ a') into x, a' + S q̈ into a.
template <int N>
void fixed_acceleration(const System& sys, Data& d, int p, VecX& x, Vec6& a) {
  const Eigen::Matrix<double, N, N> Dinv = d.Dinv[p].template topLeftCorner<N, N>();
  const Eigen::Matrix<double, N, 1> qdd =
      Dinv * (d.u[p].template head<N>() - d.U6[p].template leftCols<N>().transpose() * a);
  x.template segment<N>(sys.q_index[p]) = qdd;
  for (int j = 0; j < N; ++j) a += d.S[p].col(j) * qdd(j);
}

// ABA pass 2, bias part, and pass 3, given the bias forces p^A (d.pA), joint biases c (d.c),
// the forces τ (nq) on the free coordinates and the base acceleration a_0:
//   u = τ − Sᵀ p^A, the parent gets p^a = p^A + I^a c + U D⁻¹ u (leaves to root);
//   a' = a_λ + c, q̈ = D⁻¹ (u − Uᵀ a'), a = a' + S q̈ (root to leaves), into x (nq).
// `at_rest` (M x = τ: the system at rest, a_0 = 0): the joint biases c are zero, and the terms I^a c and a' += c are
// left out (p^A holds only what the children hand on).
// τ is read only before x is written: they may be the same vector.
void articulated_accelerations(const System& sys, Data& d, const VecX& tau, const Vec6& a0, VecX& x, bool at_rest) {
  // A body's p^a goes to its parent through d.pA, but to the body just before it (a chain's parent, visited
  // next) in `carry`, and a' likewise in `a`: kept in registers, not stored and read straight back (measured: a
  // forward dynamics 11-16 % faster on the strip, the slider-crank and the Bricard).
  Vec6 carry = Vec6::Zero();
  for (int p = sys.nbodies - 1; p >= 0; --p) {
    const Vec6 pA = p + 1 < sys.nbodies && sys.parent[p + 1] == p ? Vec6(d.pA[p] + carry) : d.pA[p];
    Vec6 pa = at_rest ? pA : Vec6(pA + d.IA[p] * d.c[p]);
    const int k0 = sys.q_index[p], nf = sys.nq_of[p];
    if (!fixed_size(nf, [&](auto N) { fixed_bias<N>(sys, d, tau, p, pA, pa); }) && nf > 0) {
      d.u[p] = tau.segment(k0, nf) - d.S[p].transpose() * pA;
      pa += d.U6[p] * (d.Dinv[p] * d.u[p]);
    }
    if (sys.parent[p] == p - 1)
      carry = pa;
    else if (sys.parent[p] >= 0)
      d.pA[sys.parent[p]] += pa;
  }
  Vec6 a = a0;  // the previous body's acceleration: the parent's in a chain
  for (int p = 0; p < sys.nbodies; ++p) {
    if (sys.parent[p] != p - 1) a = parent_value(sys, d.a, p, a0);
    if (!at_rest) a += d.c[p];
    const int k0 = sys.q_index[p], nf = sys.nq_of[p];
    if (!fixed_size(nf, [&](auto N) { fixed_acceleration<N>(sys, d, p, x, a); }) && nf > 0) {
      const SmallVec qdd = d.Dinv[p] * (d.u[p] - d.U6[p].transpose() * a);
      x.segment(k0, nf) = qdd;
      for (int k = 0; k < nf; ++k) a += d.S[p].col(k) * qdd(k);
    }
    d.a[p] = a;
  }
}

}  // namespace

namespace {

// ABA pass 1: p^A = v ×* I v − f_ext; the joint bias c_p gains the prescribed q̈ (known); the passive
// forces τ of the free coordinates go into d.qdd, which pass 3 overwrites with q̈.
void bias_forces(const System& sys, Data& d) {
  for (int p = 0; p < sys.nbodies; ++p) {
    d.pA[p] = crossf(d.v[p], d.I[p] * d.v[p]) - d.fext[p];
    for (int u = sys.use_start[p]; u < sys.use_start[p + 1]; ++u) {
      const int i = sys.use_coord[u];
      if (sys.use_drive[u] >= 0) d.c[p] += d.axes[u] * d.qdda(i);
      if (sys.use_q[u] >= 0) d.qdd(sys.use_q[u]) = passive_force(sys, d, i, true);
    }
  }
}

// The state's spatial kinematics and pass 1, then passes 2 and 3 on the articulated inertias in d (factorised
// by the caller): q̈ into d.qdd and d.qdda.
void accelerations_on_factor(const System& sys, Data& d, bool factor) {
  require_tree(sys);
  check_gimbal_lock(sys, d);
  spatial_kinematics(sys, d);
  bias_forces(sys, d);
  if (factor) articulated_inertias(sys, d, nullptr);
  articulated_accelerations(sys, d, d.qdd, gravity_acceleration(sys, d), d.qdd, false);
  set_accelerations(sys, d, d.qdd);
  if (!d.qdd.allFinite()) throw SimulationError(d.t, "accelerations are NaN or inf");
}

}  // namespace

void aba(const System& sys, Data& d) { accelerations_on_factor(sys, d, true); }

void aba_on_factor(const System& sys, Data& d) { accelerations_on_factor(sys, d, false); }

void aba_factor(const System& sys, Data& d, const VecX& armature) {
  require_tree(sys);
  articulated_inertias(sys, d, &armature);
}

void aba_factor(const System& sys, Data& d) {
  require_tree(sys);
  articulated_inertias(sys, d, nullptr);
}

void aba_solve(const System& sys, Data& d, const VecX& b, VecX& x) {
  require_tree(sys);
  // M x = b is the forward dynamics of a system at rest, without gravity or loads, under b.
  for (int p = 0; p < sys.nbodies; ++p) d.pA[p].setZero();  // c is not read at rest
  if (&x != &b) x.resize(sys.nq);
  articulated_accelerations(sys, d, b, Vec6::Zero(), x, true);
}

void rnea_driving_forces(const System& sys, Data& d) {
  require_tree(sys);
  if (sys.np == 0) return;
  spatial_kinematics(sys, d);  // fresh joint biases (aba folded the prescribed q̈ into them)
  rnea_pass(sys, d);           // d.qdda holds every acceleration after aba
  // Row i of the full equations: s_iᵀ f̄_p = Q_i^passive + τ_i.
  for (int k = 0; k < sys.np; ++k) {
    const int i = sys.drive_coords[k];
    d.tau(k) = d.axes[own_use(sys, i)].dot(d.sf[sys.coords[i].body]) - passive_force(sys, d, i, true);
  }
}

}  // namespace rigidfem
