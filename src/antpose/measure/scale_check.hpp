// Checks of the measurement's scale. Every length antpose measures is in units of the board's
// printed size (board.yaml's square_m): a wrong value scales the whole scene, which the photos
// cannot tell, while the reconstruction's searches (depth ranges, the model's size) are in metres.
// What fails then is named as the region or the registration failing, so the scale is checked
// against two things the photos do not set:
// - the walk: the camera centres of consecutive photos over the time between them give the speed
//   the phone was carried at; a person framing photos moves at walking pace (about 1.4 m/s,
//   stops included: less), so a median over 3 m/s says the lengths are too long;
// - the model: where the registration fails, the extent of the region's points along their main
//   axis against the model's length says by what factor the lengths are off.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/core/check.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/measure/camera_poses.hpp"
#include "antpose/model/antenna_model.hpp"

namespace antpose::measure {

struct ScaleCheckOptions {
  /// Over this median speed between consecutive photos (m/s) the board's size is in doubt: a
  /// jogging pace, more than twice a person's walk.
  double max_median_speed_m_s = 3.0;
  /// Pairs of photos closer in time than this (s) are left out: their speed is mostly noise.
  double min_interval_s = 0.5;
  /// The region's points spanning more than this factor times the model's length, or less than
  /// its inverse, name the scale as a likely cause of a failed registration. Loose: points
  /// cover only part of a plain radome and may reach a bracket beyond it.
  double max_extent_ratio = 1.8;
  OptionProblems Check() const;
};

/// What the walk says of the scale.
struct WalkScale {
  std::optional<double> median_speed_m_s;  // nullopt with fewer than two usable intervals
  std::optional<std::string> warning;      // set where the speed says the lengths are too long
};

/// The median speed of the camera between consecutive posed photos, in board metres per second
/// of the capture clock, and a warning naming square_m where it is beyond a person's walk.
WalkScale check_walk_scale(const Capture& capture, const CameraPoses& poses, const camera::BoardSpec& board,
                           const ScaleCheckOptions& options = {});

/// Where the region's points (board frame) span a length that differs from the model's by more
/// than options.max_extent_ratio, the sentence that says so and names square_m; else nullopt.
std::optional<std::string> model_scale_hint(const std::vector<Vec3>& points_board, const model::AntennaModel& model,
                                            const camera::BoardSpec& board, const ScaleCheckOptions& options = {});

}  // namespace antpose::measure
