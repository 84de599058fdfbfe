// The antenna's attitude from the non-contact chain: the board's attitude in the world
// (board_world.hpp, ENU with magnetic north, as the orientation track) and the antenna's in the
// board frame (registration of the model to the reconstructed points, board frame):
//   R_world_antenna = R_world_board · R_board_antenna.
// Covariance (world frame, rad², R_true = exp(δ) R_est): the board's plus the registration's
// carried into the world, Σ = Σ_board + R_world_board Σ_reg R_world_boardᵀ (independent). The
// angles' σ follow by first-order propagation (geometry/attitude.hpp attitude_sigma). True
// azimuth = magnetic + declination, its σ adding WMM's declination σ in quadrature.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "antpose/geometry/attitude.hpp"
#include "antpose/geomag/wmm.hpp"
#include "antpose/measure/board_world.hpp"

namespace antpose::measure {

/// The σ one source of uncertainty alone gives each angle (rad). The sources are independent and the
/// propagation linear, so each angle's σ² is the sum of its shares' squares: the budget says what
/// limits a measurement (the compass, the outline, the camera poses, a rival pose).
/// The budget's share of the board's attitude in the world (the compass and the tilt).
inline constexpr const char* kBoardAttitudeSource = "board attitude in the world";

struct SigmaShare {
  std::string source;
  AttitudeSigma sigma;
};

struct AntennaAttitudeResult {
  Mat3 R_world_antenna = Mat3::Identity();  // world = ENU, magnetic north
  Mat3 covariance = Mat3::Zero();           // rad², world frame
  AntennaAttitude magnetic;                 // azimuth is magnetic
  AttitudeSigma sigma;
  /// sigma by source (magnetic angles): the board's attitude in the world first, then each of the
  /// registration's sources, then any widening for rival poses.
  std::vector<SigmaShare> budget;
  std::optional<double> azimuth_true;        // rad, with a site
  std::optional<double> azimuth_true_sigma;  // rad
  std::vector<std::string> warnings;
};

/// `R_board_antenna` with the covariance of its independent `sources` (rad², board frame, left
/// perturbation; none: the board's alone); `site` gives the declination (none: no true azimuth).
AntennaAttitudeResult antenna_attitude(const BoardWorldAttitude& board, const Mat3& R_board_antenna,
                                       const std::vector<UncertaintySource>& sources_board,
                                       const std::optional<geomag::SiteField>& site);

/// Widens `result`'s σ (of R_board_antenna) for poses that fit about as well (`rivals_board`):
/// each angle's σ to half its difference from each rival's (the spread of a two-way mixture).
/// A rival at another yaw says the yaw is uncertain by that much, not about which axis: the
/// truth may lie as far round the panel's own long axis, and about a tilted axis a yaw moves
/// the roll by about yaw · sin(downtilt) and the downtilt by downtilt · (1 − cos yaw). So each
/// angle takes the larger of its differences to the rival and to R_board_antenna turned by the
/// rival's boresight angle about its own z (a panel 3.9° down, 13.8° off about its own axis,
/// reads as −0.99° of roll, where a rival 30° round about the vertical would leave the roll's σ
/// at 0.18°). The widening joins the budget as `source`. Returns the largest angle between the
/// rivals' boresights and the result's (rad).
double widen_for_rivals(AntennaAttitudeResult& result, const Mat3& R_board_antenna,
                        const std::vector<Mat3>& rivals_board, const BoardWorldAttitude& board,
                        const std::string& source = "rival poses");

}  // namespace antpose::measure
