// The camera–IMU time offset of one capture, checked against its own photos.
//
// The device profile's offset (calibrate joint) holds for the clock path it was calibrated on; a
// capture whose photo stamps take another path (a browser, another app, a restarted camera
// session) can be off by a tenth of a second or more. Photos are taken in holds, so a wrong offset
// puts a photo's IMU instant into the walk before or after its hold, and its board attitude in the
// world, R_world_board_i(δ) = R_world_device(t_i + δ) R_device_camera R_camera_board_i, turns by
// what the phone turned meanwhile. Where δ is right the photos agree on the board, so their spread
// about the L1 median (RMS angle) is profiled over δ: the offsets whose spread lies within a
// tolerance of the least are the consistent ones. Even at the right offset the photos disagree by
// the orientation track's own errors while walking (tenths of a degree), so the tolerance is a
// share of the least spread with a floor; a photo pushed into a turn moves by degrees. The profile's
// offset stands where it is consistent (it was measured on moving photos, finer than any hold);
// otherwise the middle of the consistent range containing the least spread is used, with a
// warning. The same principle as the joint calibration's time offset (calibration/camera_imu.hpp),
// on the one capture.
#pragma once

#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/measure/board_world.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {

struct TimeOffsetOptions {
  bool enabled = true;
  double search_s = 0.5;  // the profile spans the device's offset ± this
  double step_s = 0.005;
  /// Consistent: spread ≤ least + max(tolerance_floor_rad, tolerance_share × least).
  double tolerance_floor_rad = deg2rad(0.1);
  double tolerance_share = 0.5;
  std::size_t min_photos = 3;  // fewer photos inside the track: no check
  OptionProblems Check() const;
};

struct TimeOffsetCheck {
  double device_s = 0.0;  // the profile's
  double used_s = 0.0;    // the one the measurement uses
  bool checked = false;   // false: too few photos, or disabled; used = device
  bool device_consistent = true;
  double consistent_low_s = 0.0, consistent_high_s = 0.0;  // the range containing the least spread
  double spread_at_device_rad = 0.0, least_spread_rad = 0.0;
  std::vector<std::string> warnings;
};

/// `photos` with their shot times (t_shot) and board poses; `camera_imu` carries the device's
/// offset and R_device_camera.
TimeOffsetCheck check_time_offset(const std::vector<BoardPhoto>& photos, const orientation::OrientationTrack& track,
                                  const CameraImu& camera_imu, const TimeOffsetOptions& options);

}  // namespace antpose::measure
