#include "rigidfem/joint_motion.hpp"

#include <cmath>
#include <stdexcept>

#include "rigidfem/errors.hpp"

namespace rigidfem {

Vec3 axis_direction(Axis a) { return Vec3::Unit(axis_index(a)); }

const char* axis_name(Axis a) {
  static const char* names[6] = {"x", "y", "z", "rz", "ry", "rx"};
  return names[static_cast<int>(a)];
}

Axis parse_axis(const std::string& name, bool rotation, const std::string& argument) {
  if (name == "x") return rotation ? Axis::RX : Axis::X;
  if (name == "y") return rotation ? Axis::RY : Axis::Y;
  if (name == "z") return rotation ? Axis::RZ : Axis::Z;
  bad(argument, "'x', 'y' or 'z'", "'" + name + "'");
}

Axis parse_coordinate(const std::string& name, const std::string& argument) {
  static const char* names[6][2] = {{"x", "x"}, {"y", "y"}, {"z", "z"}, {"rz", "phi3"}, {"ry", "phi2"}, {"rx", "phi1"}};
  for (int k = 0; k < 6; ++k)
    if (name == names[k][0] || name == names[k][1]) return static_cast<Axis>(k);
  bad(argument, "one of 'x', 'y', 'z', 'rz', 'ry', 'rx' (or 'phi3', 'phi2', 'phi1')", "'" + name + "'");
}

Mat4 elementary(Axis a, double q) {
  switch (a) {
    case Axis::X: return translation(Vec3(q, 0, 0));
    case Axis::Y: return translation(Vec3(0, q, 0));
    case Axis::Z: return translation(Vec3(0, 0, q));
    case Axis::RZ: return homogeneous(R3(q), Vec3::Zero());
    case Axis::RY: return homogeneous(R2(q), Vec3::Zero());
    case Axis::RX: return homogeneous(R1(q), Vec3::Zero());
  }
  throw std::logic_error("elementary: unknown axis");
}

Mat4 generator(Axis a) {
  // Translation along e: Q = [[0, e], [0, 0]]; rotation about e: Q = [[S(e), 0], [0, 0]].
  Mat4 Q = Mat4::Zero();
  if (is_rotation(a))
    Q.topLeftCorner<3, 3>() = skew(axis_direction(a));
  else
    Q.topRightCorner<3, 1>() = axis_direction(a);
  return Q;
}

void apply_elementary(Mat4& G, Axis a, double q) {
  // A translation moves the origin along column a; a rotation turns the two other columns
  // (the right-handed pair (y, z) about x, (z, x) about y, (x, y) about z).
  const int k = axis_index(a);
  if (!is_rotation(a)) {
    G.col(3).head<3>() += q * G.col(k).head<3>();
    return;
  }
  const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
  double s, c;
  sin_cos(q, s, c);
  const Vec4 c1 = G.col(k1), c2 = G.col(k2);
  G.col(k1) = c * c1 + s * c2;
  G.col(k2) = -s * c1 + c * c2;
}

void motion_axis(const Mat4& G, Axis a, Vec6& s) {
  // Written into its place component by component: a 6-vector built on the stack and copied out was read back as
  // pairs just after its single components were stored, a stall on every axis (measured: 7 % of a 3-rotation chain's forward dynamics).
  const Vec3 e = G.col(axis_index(a)).head<3>();
  const Vec3 v = is_rotation(a) ? Vec3(G.col(3).head<3>().cross(e)) : e;
  const Vec3 w = is_rotation(a) ? e : Vec3::Zero();
  for (int i = 0; i < 3; ++i) s(i) = w(i), s(3 + i) = v(i);
}

namespace {

void check_size(const std::vector<Axis>& axes, const VecX& q) {
  if (q.size() != static_cast<int>(axes.size()))
    bad("q", std::to_string(axes.size()) + " (joint coordinates) values", std::to_string(q.size()));
}

void check_index(const std::vector<Axis>& axes, int i, const char* name) {
  if (i < 0 || i >= static_cast<int>(axes.size()))
    bad(name, "a coordinate index 0.." + std::to_string(static_cast<int>(axes.size()) - 1), std::to_string(i));
}

// Π_k E_k(q_k), with the factors i and j (−1: none) multiplied on the right by their generators.
Mat4 product_with_generators(const std::vector<Axis>& axes, const VecX& q, int i, int j) {
  check_size(axes, q);
  Mat4 T = Mat4::Identity();
  for (int k = 0; k < static_cast<int>(axes.size()); ++k) {
    Mat4 E = elementary(axes[k], q(k));
    if (k == i) E = E * generator(axes[k]);
    if (k == j) E = E * generator(axes[k]);
    T = T * E;
  }
  return T;
}

}  // namespace

Mat4 joint_transform(const std::vector<Axis>& axes, const VecX& q) { return product_with_generators(axes, q, -1, -1); }

Mat4 joint_transform_derivative(const std::vector<Axis>& axes, const VecX& q, int i) {
  check_index(axes, i, "i");
  return product_with_generators(axes, q, i, -1);
}

Mat4 joint_transform_second_derivative(const std::vector<Axis>& axes, const VecX& q, int i, int j) {
  check_index(axes, i, "i");
  check_index(axes, j, "j");
  return product_with_generators(axes, q, i, j);
}

void joint_motion(const JointUses& j, const VecX& qa, const VecX& qda, const VecX& qdda, bool rates, Mat4& T,
                  Mat4& Td, Mat4& Tdd, Mat4* X) {
  if (j.linear) {
    // T̃ = 1 + Σ_u G_u q_u: Ṫ̃ = Σ G_u q̇_u, T̃̈ = Σ G_u q̈_u, ∂T̃/∂q_u = G_u.
    T.setIdentity();
    Td.setZero();
    Tdd.setZero();
    for (int k = 0; k < j.n; ++k) {
      const int i = j.coord[k];
      T += j.G[k] * qa(i);
      Td += j.G[k] * qda(i);
      Tdd += j.G[k] * qdda(i);
    }
    const Mat4 Ti = affine_inverse(T);
    for (int k = 0; k < j.n; ++k) X[k].noalias() = j.G[k] * Ti;
    return;
  }
  // Exact: T̃ = Π_k E_k(q_k); multiply in the elementary factors with the product rule
  // in time, Ė = E Q q̇, Ë = E (Q q̈ + Q² q̇²), (P E)¨ = P̈ E + 2 Ṗ Ė + P Ë.
  Mat4 P = Mat4::Identity(), Pd = Mat4::Zero(), Pdd = Mat4::Zero();
  for (int k = 0; k < j.n; ++k) {
    const int i = j.coord[k];
    const Mat4& Q = j.G[k];
    const Mat4 E = elementary(j.axis[k], qa(i));
    if (rates) {
      const Mat4 EQ = E * Q;
      const double qd = qda(i);
      const Mat4 Ed = EQ * qd, Edd = EQ * qdda(i) + EQ * Q * (qd * qd);
      Pdd = Pdd * E + 2.0 * Pd * Ed + P * Edd;
      Pd = Pd * E + P * Ed;
    }
    P = P * E;
    // ∂T̃/∂q_k = P_k Q_k (E_{k+1} ...) = (P_k Q_k P_k⁻¹) T̃ with P_k = E_1 ... E_k rigid.
    X[k].noalias() = P * Q * inverse(P);
  }
  T = P;
  Td = Pd;
  Tdd = Pdd;
}

void joint_frames(const JointUses& j, const VecX& qa, Mat4& G, Vec6* axes) {
  for (int k = 0; k < j.n; ++k) {
    apply_elementary(G, j.axis[k], qa(j.coord[k]));
    motion_axis(G, j.axis[k], axes[k]);
  }
}

}  // namespace rigidfem
