#include "rigidfem/transforms.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rigidfem {

Vec3 axis_direction(Axis a) {
  const int k = static_cast<int>(a);  // x y z -> e_x e_y e_z; rz ry rx -> e_z e_y e_x
  return Vec3::Unit(k < 3 ? k : 5 - k);
}

const char* axis_name(Axis a) {
  static const char* names[6] = {"x", "y", "z", "rz", "ry", "rx"};
  return names[static_cast<int>(a)];
}

Mat3 R1(double phi1) {
  const double c = std::cos(phi1), s = std::sin(phi1);
  Mat3 R;
  R << 1, 0, 0, 0, c, -s, 0, s, c;
  return R;
}

Mat3 R2(double phi2) {
  const double c = std::cos(phi2), s = std::sin(phi2);
  Mat3 R;
  R << c, 0, s, 0, 1, 0, -s, 0, c;
  return R;
}

Mat3 R3(double phi3) {
  const double c = std::cos(phi3), s = std::sin(phi3);
  Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}

Mat3 euler_zyx(double phi3, double phi2, double phi1) { return R3(phi3) * R2(phi2) * R1(phi1); }

Mat3 skew(const Vec3& w) {
  Mat3 S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

Mat4 homogeneous(const Mat3& R, const Vec3& r) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = r;
  return T;
}

Mat4 translation(const Vec3& r) { return homogeneous(Mat3::Identity(), r); }

Mat4 inverse(const Mat4& T) {
  const Mat3 Rt = T.topLeftCorner<3, 3>().transpose();
  return homogeneous(Rt, -Rt * T.topRightCorner<3, 1>());
}

Mat4 affine_inverse(const Mat4& T) {
  const Mat3 Mi = T.topLeftCorner<3, 3>().inverse();
  return homogeneous(Mi, -Mi * T.topRightCorner<3, 1>());
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

namespace {
void check_size(const std::vector<Axis>& axes, const VecX& q) {
  if (q.size() != static_cast<int>(axes.size()))
    throw std::invalid_argument("q: expected size " + std::to_string(axes.size()) + " (joint coordinates), got " +
                                std::to_string(q.size()));
}

void check_index(const std::vector<Axis>& axes, int i, const char* name) {
  if (i < 0 || i >= static_cast<int>(axes.size()))
    throw std::invalid_argument(std::string(name) + ": expected a coordinate index 0.." +
                                std::to_string(static_cast<int>(axes.size()) - 1) + ", got " + std::to_string(i));
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

}  // namespace rigidfem
