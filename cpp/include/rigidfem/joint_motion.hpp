/// The motion of a joint (book ch. 2.1): the one place that knows the elementary motions and
/// the joint types built from them.
///
/// A joint's motion is T̃(q) = Π_k E_{a_k}(q_k) over its active elementary motions a_k, always in
/// the book's order x, y, z, φ3, φ2, φ1: E_a(q) = Trans(q e_a) for a translation, R_a(q) for a
/// rotation, with the constant generator Q_a, dE_a/dq = E_a Q_a. The book's linear model replaces
/// the product by T̃ = 1 + Σ_k G_k q_k, first order in the coordinates.
#pragma once

#include <string>
#include <vector>

#include "rigidfem/transforms.hpp"

namespace rigidfem {

/// The six elementary motions of a joint, in the book's order x, y, z, φ3, φ2, φ1.
enum class Axis : int { X = 0, Y = 1, Z = 2, RZ = 3, RY = 4, RX = 5 };

inline bool is_rotation(Axis a) { return static_cast<int>(a) >= 3; }
/// 0, 1, 2 for the axis x, y, z a motion translates along or turns about.
inline int axis_index(Axis a) { return is_rotation(a) ? 5 - static_cast<int>(a) : static_cast<int>(a); }
/// Unit vector of the axis an elementary motion translates along or turns about.
Vec3 axis_direction(Axis a);
/// "x", "y", "z", "rz", "ry", "rx".
const char* axis_name(Axis a);
/// Parses "x", "y", "z" (a translation or, for rotations, the axis) into an Axis.
Axis parse_axis(const std::string& name, bool rotation, const std::string& argument);
/// Parses "x", "y", "z", "rz", "ry", "rx" (also "phi3", "phi2", "phi1").
Axis parse_coordinate(const std::string& name, const std::string& argument);

/// Elementary transform E_a(q): Trans(q e_a) for a translation, the rotation R_a(q) otherwise.
Mat4 elementary(Axis a, double q);
/// Its generator Q_a, constant: dE_a/dq = E_a Q_a.
Mat4 generator(Axis a);
/// G ← G E_a(q), the factor applied to the columns of the frame G (no 4x4 product).
void apply_elementary(Mat4& G, Axis a, double q);
/// The axis s = (ω, v_O) of the motion a in the frame G (ground coordinates), into s: (e, o × e) for a
/// rotation about the unit vector e through the origin o of G, (0, e) for a translation along e.
void motion_axis(const Mat4& G, Axis a, Vec6& s);

/// Joint transform T̃(q) = Π_k E_{axes[k]}(q_k) (4x4); axes must be in the book's order.
Mat4 joint_transform(const std::vector<Axis>& axes, const VecX& q);
/// ∂T̃/∂q_i (4x4): the i-th factor E_i replaced by E_i Q_i.
Mat4 joint_transform_derivative(const std::vector<Axis>& axes, const VecX& q, int i);
/// ∂²T̃/∂q_i∂q_j (4x4): factors i and j replaced (E_i Q_i Q_i when i == j).
Mat4 joint_transform_second_derivative(const std::vector<Axis>& axes, const VecX& q, int i, int j);

/// The coordinates that move one joint ("uses"), in the order of its factors: for an exact
/// joint its own coordinates; for a linear joint also the coordinates of earlier joints coupled
/// to it (the linear beam model).
struct JointUses {
  int n = 0;                   ///< number of uses
  const int* coord = nullptr;  ///< (n) index into the all-coordinate vectors qa, qda, qdda
  const Axis* axis = nullptr;  ///< (n) the elementary motion of each use (exact joints)
  const Mat4* G = nullptr;     ///< (n) generator of each use in the joint frame
  bool linear = false;         ///< T̃ = 1 + Σ G q instead of Π E(q)
};

/// jcalc: the joint's motion T̃ and, if `rates`, Ṫ̃ and T̃̈ at the coordinates (qa, qda, qdda) (all
/// coordinates), and the local twists X_k = (∂T̃/∂q_k) T̃⁻¹ of its uses, X (n).
void joint_motion(const JointUses& j, const VecX& qa, const VecX& qda, const VecX& qdda, bool rates, Mat4& T,
                  Mat4& Td, Mat4& Tdd, Mat4* X);
/// G ← G T̃(q) factor by factor for an exact joint, writing the axis s_k of each use (ground
/// coordinates, `motion_axis`) into axes (n).
void joint_frames(const JointUses& j, const VecX& qa, Mat4& G, Vec6* axes);

}  // namespace rigidfem
