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

/// m ×m s, the motion cross product (Featherstone's crm).
inline Vec6 crossm(const Vec6& m, const Vec6& s) {
  Vec6 r;
  r << m.head<3>().cross(s.head<3>()), m.head<3>().cross(s.tail<3>()) + m.tail<3>().cross(s.head<3>());
  return r;
}
/// v ×* f, the force cross product (Featherstone's crf).
inline Vec6 crossf(const Vec6& v, const Vec6& f) {
  Vec6 r;
  r << v.head<3>().cross(f.head<3>()) + v.tail<3>().cross(f.tail<3>()), v.head<3>().cross(f.tail<3>());
  return r;
}

}  // namespace rigidfem
