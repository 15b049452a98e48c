#include "rigidfem/transforms.hpp"

#include <cmath>

namespace rigidfem {

Mat3 R1(double phi1) {
  double s, c;
  sin_cos(phi1, s, c);
  Mat3 R;
  R << 1, 0, 0, 0, c, -s, 0, s, c;
  return R;
}

Mat3 R2(double phi2) {
  double s, c;
  sin_cos(phi2, s, c);
  Mat3 R;
  R << c, 0, s, 0, 1, 0, -s, 0, c;
  return R;
}

Mat3 R3(double phi3) {
  double s, c;
  sin_cos(phi3, s, c);
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

}  // namespace rigidfem
