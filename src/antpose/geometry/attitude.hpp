// Antenna attitude angles (../shared/notes/antenna-model.md, docs/conventions.md).
//
// Antenna frame a: y_a boresight (outward normal of the radome), z_a up the long axis,
// x_a = y_a × z_a (right for a person behind the antenna). World frame: ENU.
// With b = R_world_antenna e_y:
//   azimuth  = atan2(b_east, b_north) in [0, 2π), clockwise from north;
//   downtilt = -asin(b_up) in [-π/2, π/2], positive when the boresight points below the horizon;
//   roll     = rotation about the boresight, positive clockwise seen from behind (right side down);
//   R_world_antenna = Rz(-azimuth) · Rx(-downtilt) · Ry(roll).
// The thesis (§2.2, §5.4.6) states downtilt as 90° minus the angle between the normal and
// "gravity" while writing gravity as +z; the definitions here resolve that sign clash.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "antpose/geometry/rotation.hpp"

namespace antpose {

/// Below this angle between boresight and the vertical, azimuth and roll are undefined.
inline constexpr double kDefaultVerticalLimit = deg2rad(1.0);

struct AntennaAttitude {
  std::optional<double> azimuth;  // rad, [0, 2π); empty when the boresight is near vertical
  double downtilt = 0.0;          // rad
  std::optional<double> roll;     // rad, (-π, π]; empty when the boresight is near vertical
};

/// Rz(-azimuth) · Rx(-downtilt) · Ry(roll).
Mat3 rotation_from_attitude(double azimuth, double downtilt, double roll);

/// Inverse of rotation_from_attitude. When the boresight is within `vertical_limit` of the
/// vertical, azimuth and roll are left empty: only their sum/difference is observable there.
AntennaAttitude attitude_from_rotation(const Mat3& R_world_antenna, double vertical_limit = kDefaultVerticalLimit);

/// One independent source of an attitude's uncertainty: its rotation covariance (rad², left
/// perturbation, R_true = exp(δ) R_est, in the frame its owner names). Independent sources' covariances
/// add, so a list of them is the uncertainty's budget.
struct UncertaintySource {
  std::string source;  // as reports name it, e.g. "camera poses"
  Mat3 covariance = Mat3::Zero();
};

/// 1σ of the attitude angles (rad) when R_world_antenna is uncertain by a world-frame rotation
/// vector δ (R_true = exp(δ) R_est) of covariance `covariance_world` (rad²): first-order
/// propagation through attitude_from_rotation, J Σ Jᵀ, with J by central differences. Azimuth
/// and roll are empty where attitude_from_rotation leaves them empty.
struct AttitudeSigma {
  std::optional<double> azimuth;
  double downtilt = 0.0;
  std::optional<double> roll;
};
AttitudeSigma attitude_sigma(const Mat3& R_world_antenna, const Mat3& covariance_world,
                             double vertical_limit = kDefaultVerticalLimit);

/// Thesis gra(): angle between a world vector and gravity (straight down), in [0, π].
double angle_from_down(const Vec3& v_world);
/// Thesis nor(): clockwise angle from north of the horizontal projection of a world vector,
/// in [0, 2π). Empty when the vector is within `vertical_limit` of vertical.
std::optional<double> heading_from_north(const Vec3& v_world, double vertical_limit = kDefaultVerticalLimit);

/// How the phone lies on the antenna's back plate in contact mode. In every placement the
/// back of the phone touches the plate and the screen faces the person behind the antenna,
/// so z_device = -y_a.
enum class ContactPlacement {
  kTopUp,     // phone's top points up the panel (default): x_d = x_a, y_d = z_a
  kTopDown,   // upside down: x_d = -x_a, y_d = -z_a
  kTopRight,  // across the panel, top towards the antenna's right: y_d = x_a, x_d = -z_a
  kTopLeft,   // across the panel, top towards the antenna's left: y_d = -x_a, x_d = z_a
};

/// R_device_antenna for a placement; kTopUp has columns (e_x, -e_z, e_y).
Mat3 contact_rotation(ContactPlacement placement);
/// Parses "top-up", "top-down", "top-right", "top-left"; throws std::invalid_argument
/// naming the accepted values.
ContactPlacement parse_contact_placement(std::string_view name);
std::string_view to_string(ContactPlacement placement);

}  // namespace antpose
