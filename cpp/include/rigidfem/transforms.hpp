/// Homogeneous transformations (book ch. 2.1) and the spatial-vector algebra of the recursive engine.
///
/// A pose is T = [[R, r], [0 0 0 1]]. Rotations about x, y, z are R1(φ1), R2(φ2),
/// R3(φ3); Euler angles ZYX give R = R3(φ3) R2(φ2) R1(φ1) (book eq. 2.7).
/// Spatial vectors are expressed in ground coordinates at the global origin: motion
/// m = (ω, v_O), force f = (n_O, F) (Featherstone's notation).
#pragma once

#include <Eigen/Dense>
#include <cmath>

namespace rigidfem {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
/// Row-major (N, n) arrays: one state per row, as numpy stores a trajectory.
using RowMatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

namespace detail {

// sin and cos of r + r_lo, |r| ≤ π/4, r_lo a correction of r's last bits (left out where there is none):
// Taylor (the next terms r¹⁹/19! and r¹⁸/18! are below 1e-19), in z = r² by Estrin's scheme:
// sin r = r + r z P(z), P = −1/3! + z/5! − ... + z⁷/17!; cos r = 1 − z/2 + z² Q(z), Q = 1/4! − z/6! + ... + z⁶/16!
// (the factorials are exact doubles, so each coefficient is the quotient correctly rounded)
template <bool with_lo>
inline void sin_cos_reduced(double r, double r_lo, double& s, double& c) {
  constexpr double s3 = -1.0 / 6, s5 = 1.0 / 120, s7 = -1.0 / 5040, s9 = 1.0 / 362880, s11 = -1.0 / 39916800,
                   s13 = 1.0 / 6227020800.0, s15 = -1.0 / 1307674368000.0, s17 = 1.0 / 355687428096000.0;
  constexpr double c4 = 1.0 / 24, c6 = -1.0 / 720, c8 = 1.0 / 40320, c10 = -1.0 / 3628800, c12 = 1.0 / 479001600,
                   c14 = -1.0 / 87178291200.0, c16 = 1.0 / 20922789888000.0;
  const double z = r * r, z2 = z * z, z4 = z2 * z2;
  const double P = (s3 + z * s5) + z2 * (s7 + z * s9) + z4 * ((s11 + z * s13) + z2 * (s15 + z * s17));
  const double Q = (c4 + z * c6) + z2 * (c8 + z * c10) + z4 * ((c12 + z * c14) + z2 * c16);
  // with r_lo: sin(r + r_lo) ≈ sin r + r_lo cos r, cos(r + r_lo) ≈ cos r − r_lo r; 1 − z/2 as w plus its
  // rounding error (1 − w) − z/2 (Kahan)
  const double hz = 0.5 * z, w = 1.0 - hz;
  if constexpr (with_lo) {
    s = r + (r * z * P + r_lo * w);
    c = w + (((1.0 - w) - hz) + (z2 * Q - r * r_lo));
  } else {
    s = r + r * z * P;
    c = w + (((1.0 - w) - hz) + z2 * Q);
  }
}

}  // namespace detail

/// sin x and cos x of one angle (rad), each within 0.9 ulp of the exact value (glibc's sincos: 0.5 ulp), without
/// libm's save and restore of the rounding mode in every call (measured: 7.5 % of a 3-rotation chain's forward
/// dynamics). Alone, as the core is built (no FMA contraction), 8.8 ns a call against libm's 9.7-10.0 in the
/// x86-64-v3 build and 10.1-10.8 against 9.9-10.5 in the portable one; in that forward dynamics 2-3 % less time
/// in both. Beyond |x| = 2^17 rad, and for inf or NaN, the library's.
inline void sin_cos(double x, double& s, double& c) {
  // |x| < 0.78 < π/4 (the angles of deformations and most joints): no reduction, which stood in the chain of
  // dependent operations (the values are those of the reduction with k = 0, r = x, r_lo = 0).
  if (std::abs(x) < 0.78) return detail::sin_cos_reduced<false>(x, 0.0, s, c);
  // x = k π/2 + r, |r| ≤ π/4, with π/2 = p1 + p2 + p3 (p1 and p2 of 33 bits, from π to 300 bits): x − k p1 and
  // k p2 are exact for |k| < 2^20, and x − k π/2 = r + r_lo by a two-sum. k by the shift 1.5·2^52, which rounds
  // |y| < 2^51 to the nearest integer.
  constexpr double two_over_pi = 0.6366197723675814, shift = 0x1.8p52;
  constexpr double p1 = 0x1.921fb54400000p+0, p2 = 0x1.0b4611a600000p-34, p3 = 0x1.3198a2e037073p-69;
  if (!(std::abs(x) <= 0x1p17)) {
    s = std::sin(x), c = std::cos(x);
    return;
  }
  const double k = (x * two_over_pi + shift) - shift;
  const double r1 = x - k * p1, t = -k * p2, r = r1 + t, t1 = r - r1;
  const double r_lo = ((r1 - (r - t1)) + (t - t1)) - k * p3;
  double sr, cr;
  detail::sin_cos_reduced<true>(r, r_lo, sr, cr);
  switch (static_cast<long long>(k) & 3) {  // the quadrant
    case 0: s = sr, c = cr; break;
    case 1: s = cr, c = -sr; break;
    case 2: s = -sr, c = -cr; break;
    default: s = -cr, c = sr;
  }
}

Mat3 R1(double phi1);  ///< rotation about x
Mat3 R2(double phi2);  ///< rotation about y
Mat3 R3(double phi3);  ///< rotation about z
/// R3(φ3) R2(φ2) R1(φ1), book eq. (2.7).
Mat3 euler_zyx(double phi3, double phi2, double phi1);
/// Skew-symmetric matrix S(w) with S(w) x = w × x.
Mat3 skew(const Vec3& w);

/// [[R, r], [0, 1]].
Mat4 homogeneous(const Mat3& R, const Vec3& r);
/// Trans(r) = [[I, r], [0, 1]].
Mat4 translation(const Vec3& r);
/// T⁻¹ = [[Rᵀ, −Rᵀ r], [0, 1]] (no general matrix inverse needed).
Mat4 inverse(const Mat4& T);
/// Inverse of an affine [[M, r], [0, 1]] whose M need not be a rotation (linear model):
/// [[M⁻¹, −M⁻¹ r], [0, 1]].
Mat4 affine_inverse(const Mat4& T);

/// A B of two affine [[M, r], [0, 1]]: [[M_A M_B, M_A r_B + r_A], [0, 1]] (36 multiplications, not a 4 × 4
/// product's 64).
inline void compose(const Mat4& A, const Mat4& B, Mat4& AB) {
  AB.topLeftCorner<3, 3>().noalias() = A.topLeftCorner<3, 3>() * B.topLeftCorner<3, 3>();
  AB.topRightCorner<3, 1>().noalias() = A.topLeftCorner<3, 3>() * B.topRightCorner<3, 1>();
  AB.topRightCorner<3, 1>() += A.topRightCorner<3, 1>();
  AB.row(3) << 0.0, 0.0, 0.0, 1.0;
}

/// m ×m s, the motion cross product (Featherstone's crm): (ω × s_ω, ω × s_v + v × s_ω) for m = (ω, v), written
/// out by components so that the compiler inlines it (Eigen's comma initialiser kept GCC from doing so).
inline Vec6 crossm(const Vec6& m, const Vec6& s) {
  Vec6 r;
  r(0) = m(1) * s(2) - m(2) * s(1);
  r(1) = m(2) * s(0) - m(0) * s(2);
  r(2) = m(0) * s(1) - m(1) * s(0);
  r(3) = m(1) * s(5) - m(2) * s(4) + m(4) * s(2) - m(5) * s(1);
  r(4) = m(2) * s(3) - m(0) * s(5) + m(5) * s(0) - m(3) * s(2);
  r(5) = m(0) * s(4) - m(1) * s(3) + m(3) * s(1) - m(4) * s(0);
  return r;
}
/// v ×* f, the force cross product (Featherstone's crf): (ω × f_τ + v × f_F, ω × f_F) for v = (ω, v), f = (τ, F),
/// by components as crossm.
inline Vec6 crossf(const Vec6& v, const Vec6& f) {
  Vec6 r;
  r(0) = v(1) * f(2) - v(2) * f(1) + v(4) * f(5) - v(5) * f(4);
  r(1) = v(2) * f(0) - v(0) * f(2) + v(5) * f(3) - v(3) * f(5);
  r(2) = v(0) * f(1) - v(1) * f(0) + v(3) * f(4) - v(4) * f(3);
  r(3) = v(1) * f(5) - v(2) * f(4);
  r(4) = v(2) * f(3) - v(0) * f(5);
  r(5) = v(0) * f(4) - v(1) * f(3);
  return r;
}

}  // namespace rigidfem
