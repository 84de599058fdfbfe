#include "antpose/geometry/attitude.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace antpose {

Mat3 rotation_from_attitude(double azimuth, double downtilt, double roll) {
  return rot_z(-azimuth) * rot_x(-downtilt) * rot_y(roll);
}

AntennaAttitude attitude_from_rotation(const Mat3& R_world_antenna, double vertical_limit) {
  const Vec3 b = R_world_antenna.col(1);
  const double horizontal = std::hypot(b.x(), b.y());
  AntennaAttitude out;
  // atan2 keeps full precision near ±90°, where -asin(b_up) does not.
  out.downtilt = std::atan2(-b.z(), horizontal);
  if (std::abs(out.downtilt) > std::numbers::pi / 2 - vertical_limit) return out;
  const double azimuth = wrap_2pi(std::atan2(b.x(), b.y()));
  // Undo azimuth and downtilt: what is left is Ry(roll).
  const Mat3 R_roll = rot_x(out.downtilt) * rot_z(azimuth) * R_world_antenna;
  out.azimuth = azimuth;
  out.roll = std::atan2(R_roll(0, 2), R_roll(0, 0));
  return out;
}

AttitudeSigma attitude_sigma(const Mat3& R_world_antenna, const Mat3& covariance_world, double vertical_limit) {
  const AntennaAttitude a0 = attitude_from_rotation(R_world_antenna, vertical_limit);
  // Angles as a vector (azimuth, downtilt, roll); differences wrapped, so 359.9° vs 0.1° is 0.2°.
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  const double h = 1e-6;
  bool defined = a0.azimuth.has_value();
  for (int k = 0; k < 3; ++k) {
    const Vec3 d = Vec3::Unit(k) * h;
    const AntennaAttitude p = attitude_from_rotation(exp_so3(d) * R_world_antenna, vertical_limit);
    const AntennaAttitude m = attitude_from_rotation(exp_so3(-d) * R_world_antenna, vertical_limit);
    J(1, k) = (p.downtilt - m.downtilt) / (2 * h);
    if (defined && p.azimuth && m.azimuth && p.roll && m.roll) {
      J(0, k) = wrap_pi(*p.azimuth - *m.azimuth) / (2 * h);
      J(2, k) = wrap_pi(*p.roll - *m.roll) / (2 * h);
    } else {
      defined = false;
    }
  }
  const Mat3 S = J * covariance_world * J.transpose();
  AttitudeSigma out;
  out.downtilt = std::sqrt(std::max(0.0, S(1, 1)));
  if (defined) {
    out.azimuth = std::sqrt(std::max(0.0, S(0, 0)));
    out.roll = std::sqrt(std::max(0.0, S(2, 2)));
  }
  return out;
}

double angle_from_down(const Vec3& v_world) { return angle_between(v_world, -Vec3::UnitZ()); }

std::optional<double> heading_from_north(const Vec3& v_world, double vertical_limit) {
  if (angle_between(v_world, Vec3::UnitZ()) < vertical_limit || angle_between(v_world, -Vec3::UnitZ()) < vertical_limit)
    return std::nullopt;
  return wrap_2pi(std::atan2(v_world.x(), v_world.y()));
}

Mat3 contact_rotation(ContactPlacement placement) {
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  Mat3 R_device_antenna;
  switch (placement) {
    case ContactPlacement::kTopUp: R_device_antenna << ex, -ez, ey; break;
    case ContactPlacement::kTopDown: R_device_antenna << -ex, -ez, -ey; break;
    case ContactPlacement::kTopRight: R_device_antenna << ey, -ez, -ex; break;
    case ContactPlacement::kTopLeft: R_device_antenna << -ey, -ez, ex; break;
  }
  return R_device_antenna;
}

ContactPlacement parse_contact_placement(std::string_view name) {
  if (name == "top-up") return ContactPlacement::kTopUp;
  if (name == "top-down") return ContactPlacement::kTopDown;
  if (name == "top-right") return ContactPlacement::kTopRight;
  if (name == "top-left") return ContactPlacement::kTopLeft;
  throw std::invalid_argument("unknown contact placement '" + std::string(name) +
                              "'; expected one of top-up, top-down, top-right, top-left");
}

std::string_view to_string(ContactPlacement placement) {
  switch (placement) {
    case ContactPlacement::kTopUp: return "top-up";
    case ContactPlacement::kTopDown: return "top-down";
    case ContactPlacement::kTopRight: return "top-right";
    case ContactPlacement::kTopLeft: return "top-left";
  }
  return "?";
}

}  // namespace antpose
