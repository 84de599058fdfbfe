// Stage 2 of the non-contact measurement (docs/non-contact.md): the board frame in the world.
//
//   orientation track ─► the capture's time offset (time_offset.hpp)
//        └──────────────► the board's attitude: L1 median over the photos of
//                         R_world_device(t_i + δt) R_device_camera R_camera_board_i (board_world.hpp)
//                         ─► its heading from the compass at the photos (heading_from_field)
//                         ─► the field along the walk against WMM and itself (field_check.hpp);
//                            a disturbed compass widens the heading's σ
// Every antenna registered in the board frame shares this attitude (R_world_antenna =
// R_world_board R_board_antenna), so its errors are common to them all.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/core/error.hpp"
#include "antpose/geomag/wmm.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/measure/board_world.hpp"
#include "antpose/measure/camera_poses.hpp"
#include "antpose/measure/field_check.hpp"
#include "antpose/measure/time_offset.hpp"

namespace antpose::measure {

struct WorldAlignmentOptions {
  std::string orientation = "antpose-smoother";  // orientation::make_estimator's name
  TimeOffsetOptions time_offset;
  /// The antpose filter's covariance weights its corrections (a steady state near 2° tilt and 7°
  /// heading) and is not a calibrated uncertainty, so the orientation error common to a capture
  /// is modelled: tilt 0.1° per axis, heading 0.6° (a calibrated typical phone's board attitude
  /// errors over whole walks).
  BoardWorldOptions board_world = [] {
    BoardWorldOptions o;
    o.common_sigma_rad = Vec2(deg2rad(0.1), deg2rad(0.6));
    return o;
  }();
  /// The board's heading from the compass at the photos, each photo's tilt from the board
  /// (heading_from_field); false: from the orientation track at the photos.
  bool heading_from_compass = true;
  CompassOptions compass;
  FieldCheckOptions field;
  OptionProblems Check() const;
};

struct WorldAlignment {
  BoardWorldAttitude board;               // R_world_board (ENU, magnetic north) and its covariance
  std::optional<geomag::SiteField> site;  // WMM at the capture's site, when it has one
  FieldCheck field;                       // the magnetometer at the photos
  TimeOffsetCheck time_offset;
  std::vector<std::string> warnings;  // also carried in board.warnings where they concern every antenna
};

/// MeasurementError where the board's world attitude cannot be formed (board_world_attitude).
WorldAlignment align_to_world(const Capture& capture, const CameraPoses& poses, const CameraImu& camera_imu,
                              const WorldAlignmentOptions& options, Diagnostics& diagnostics,
                              const reconstruction::Progress& progress = {});

}  // namespace antpose::measure
