#include "antpose/geometry/rotation.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace antpose {

Mat3 rot_x(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 rot_y(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rot_z(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

double wrap_2pi(double a) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double r = std::fmod(a, two_pi);
  if (r < 0.0) r += two_pi;
  return r >= two_pi ? 0.0 : r;  // fmod of a tiny negative number can round up to 2π
}

double wrap_pi(double a) {
  double r = wrap_2pi(a);
  return r > std::numbers::pi ? r - 2.0 * std::numbers::pi : r;
}

double rotation_angle(const Mat3& R) { return log_so3(R).norm(); }

double rotation_distance(const Mat3& R_a, const Mat3& R_b) { return rotation_angle(R_a.transpose() * R_b); }

Mat3 nearest_rotation(const Mat3& M) {
  Eigen::JacobiSVD<Mat3> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Mat3 exp_so3(const Vec3& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Mat3::Identity() + skew(w);
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Vec3 log_so3(const Mat3& R) {
  // Via the quaternion: 2 atan2(|v|, w) keeps full precision near 0 and near π, where the
  // trace formula acos((tr R - 1)/2) loses half the digits.
  Quat q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double vn = q.vec().norm();
  if (vn < 1e-15) return 2.0 * q.vec();
  return (2.0 * std::atan2(vn, q.w()) / vn) * q.vec();
}

double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Mat3 chordal_mean(const std::vector<Mat3>& rotations) {
  if (rotations.empty()) return Mat3::Identity();
  Mat3 sum = Mat3::Zero();
  for (const auto& R : rotations) sum += R;
  return nearest_rotation(sum);
}

}  // namespace antpose
