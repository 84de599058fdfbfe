#include "antpose/camera/camera_model.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace antpose::camera {

Mat3 CameraIntrinsics::K() const {
  Mat3 k;
  k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

bool CameraIntrinsics::has_distortion() const {
  for (double d : distortion)
    if (d != 0.0) return true;
  return false;
}

Vec2 CameraIntrinsics::distort(const Vec2& xy) const {
  const auto& [k1, k2, p1, p2, k3] = distortion;
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Vec2 CameraIntrinsics::undistort(const Vec2& xy_d) const {
  if (!has_distortion()) return xy_d;
  // Fixed point x = (x_d − tangential(x)) / radial(x); converges for the monotonic part of the
  // lens model, which is all of the image for phone lenses. Stop when the step is negligible.
  Vec2 xy = xy_d;
  for (int it = 0; it < 50; ++it) {
    const Vec2 step = xy_d - distort(xy);
    xy += step;
    if (step.squaredNorm() < 1e-24) break;
  }
  return xy;
}

std::optional<Vec2> CameraIntrinsics::project(const Vec3& p) const {
  if (!(p.z() > 0.0)) return std::nullopt;
  const Vec2 d = distort(Vec2(p.x() / p.z(), p.y() / p.z()));
  return Vec2(fx * d.x() + cx, fy * d.y() + cy);
}

std::optional<Vec2> CameraIntrinsics::project(const Vec3& p, Eigen::Matrix<double, 2, 3>& d_uv_d_p) const {
  if (!(p.z() > 0.0)) return std::nullopt;
  const auto& [k1, k2, p1, p2, k3] = distortion;
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double d_radial_d_r2 = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
  // d(x', y')/d(x, y) of the header's distortion, then d(x, y)/d(X, Y, Z) of the pinhole.
  Eigen::Matrix2d d_distorted;
  d_distorted << radial + 2.0 * x * x * d_radial_d_r2 + 2.0 * p1 * y + 6.0 * p2 * x,
      2.0 * x * y * d_radial_d_r2 + 2.0 * p1 * x + 2.0 * p2 * y,
      2.0 * x * y * d_radial_d_r2 + 2.0 * p1 * x + 2.0 * p2 * y,
      radial + 2.0 * y * y * d_radial_d_r2 + 6.0 * p1 * y + 2.0 * p2 * x;
  Eigen::Matrix<double, 2, 3> d_pinhole;
  d_pinhole << 1.0 / p.z(), 0.0, -x / p.z(), 0.0, 1.0 / p.z(), -y / p.z();
  d_uv_d_p = Eigen::DiagonalMatrix<double, 2>(fx, fy) * d_distorted * d_pinhole;
  const Vec2 d = distort(Vec2(x, y));
  return Vec2(fx * d.x() + cx, fy * d.y() + cy);
}

Vec3 CameraIntrinsics::ray(const Vec2& uv) const {
  const Vec2 xy = undistort(Vec2((uv.x() - cx) / fx, (uv.y() - cy) / fy));
  return Vec3(xy.x(), xy.y(), 1.0).normalized();
}

std::optional<std::string> CameraIntrinsics::invalid_reason() const {
  if (width <= 0 || height <= 0) return fmt::format("image size {}x{} px (expected positive)", width, height);
  for (double v : {fx, fy, cx, cy})
    if (!std::isfinite(v)) return std::string("a camera matrix entry is not a finite number");
  for (double d : distortion)
    if (!std::isfinite(d)) return std::string("a distortion coefficient is not a finite number");
  if (!(fx > 0.0) || !(fy > 0.0)) return fmt::format("focal length fx={} fy={} px (expected > 0)", fx, fy);
  if (cx < 0.0 || cx > width || cy < 0.0 || cy > height)
    return fmt::format("principal point ({}, {}) px outside the {}x{} image", cx, cy, width, height);
  return std::nullopt;
}

std::optional<CameraIntrinsics> rescaled_intrinsics(const CameraIntrinsics& in, int width, int height) {
  if (width <= 0 || height <= 0 || in.width <= 0 || in.height <= 0) return std::nullopt;
  const double sx = static_cast<double>(width) / in.width, sy = static_cast<double>(height) / in.height;
  // The same scale on both axes, up to the rounding of each new side to whole pixels (±½ px
  // each, the width's carried to the height by the aspect ratio).
  const double aspect = static_cast<double>(in.height) / in.width;
  const double tolerance = 0.5 * (std::max(aspect, 1.0 / aspect) + 1.0) + 1e-9;
  if (std::abs(sx * in.height - height) > tolerance || std::abs(sy * in.width - width) > tolerance) return std::nullopt;
  CameraIntrinsics out = in;
  out.width = width, out.height = height;
  out.fx = in.fx * sx, out.fy = in.fy * sy;
  out.cx = (in.cx + 0.5) * sx - 0.5, out.cy = (in.cy + 0.5) * sy - 0.5;
  return out;
}

Mat3 nominal_R_device_camera() { return Vec3(1.0, -1.0, -1.0).asDiagonal(); }

}  // namespace antpose::camera
