/// Homogeneous transformations (book ch. 2.1).
///
/// A pose is T = [[R, r], [0 0 0 1]]. Rotations about x, y, z are R1(φ1), R2(φ2),
/// R3(φ3); Euler angles ZYX give R = R3(φ3) R2(φ2) R1(φ1) (book eq. 2.7).
/// A joint's motion is T̃(q) = Trans(x, y, z) R3(φ3) R2(φ2) R1(φ1) restricted to
/// its active coordinates, always in this (the book's) order.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace rigidfem {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

/// The six elementary motions of a joint, in the book's order x, y, z, φ3, φ2, φ1.
enum class Axis : int { X = 0, Y = 1, Z = 2, RZ = 3, RY = 4, RX = 5 };

inline bool is_rotation(Axis a) { return static_cast<int>(a) >= 3; }
/// 0, 1, 2 for the axis x, y, z a motion translates along or turns about.
inline int axis_index(Axis a) { return is_rotation(a) ? 5 - static_cast<int>(a) : static_cast<int>(a); }
/// Unit vector of the axis an elementary motion translates along or turns about.
Vec3 axis_direction(Axis a);
/// "x", "y", "z", "rz", "ry", "rx".
const char* axis_name(Axis a);

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

/// Elementary transform E_a(q): Trans(q e_a) for a translation, the rotation R_a(q) otherwise.
Mat4 elementary(Axis a, double q);
/// Its generator Q_a, constant: dE_a/dq = E_a Q_a.
Mat4 generator(Axis a);

/// Joint transform T̃(q) = Π_k E_{axes[k]}(q_k) (4x4); axes must be in the book's order.
Mat4 joint_transform(const std::vector<Axis>& axes, const VecX& q);
/// ∂T̃/∂q_i (4x4): the i-th factor E_i replaced by E_i Q_i.
Mat4 joint_transform_derivative(const std::vector<Axis>& axes, const VecX& q, int i);
/// ∂²T̃/∂q_i∂q_j (4x4): factors i and j replaced (E_i Q_i Q_i when i == j).
Mat4 joint_transform_second_derivative(const std::vector<Axis>& axes, const VecX& q, int i, int j);

}  // namespace rigidfem
