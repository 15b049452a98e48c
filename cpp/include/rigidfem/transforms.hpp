/// Homogeneous transformations (book ch. 2.1) and the spatial-vector algebra of the recursive engine.
///
/// A pose is T = [[R, r], [0 0 0 1]]. Rotations about x, y, z are R1(φ1), R2(φ2),
/// R3(φ3); Euler angles ZYX give R = R3(φ3) R2(φ2) R1(φ1) (book eq. 2.7).
/// Spatial vectors are expressed in ground coordinates at the global origin: motion
/// m = (ω, v_O), force f = (n_O, F) (Featherstone's notation).
#pragma once

#include <Eigen/Dense>

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
