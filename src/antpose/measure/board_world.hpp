// The calibration board's attitude in the world, from every photo that shows it:
//   R_world_board_i = R_world_device(t_i + δt) · R_device_camera · R_camera_board_i,
// then averaged robustly: the geodesic L1 median on SO(3) by Weiszfeld iterations (Hartley,
// Aftab & Trumpf, "L1 rotation averaging using the Weiszfeld algorithm", CVPR 2011), started
// from the chordal mean. A photo whose phone heading was disturbed (steel near the mast) pulls
// the median far less than the mean.
//
// Uncertainty (world frame, rad², R_true = exp(δ) R_est). What is common to the photos does not
// average out: the orientation track's error (its heading is correlated over the whole capture)
// and R_device_camera's calibration error are taken at their mean over the photos; what differs
// between photos (PnP noise, short-term track noise) is the larger of the propagated PnP
// covariance / N and the photos' scatter / N.
//
// Warnings: photos whose attitude is far from the median (outliers, named); heading scatter
// between photos beyond `heading_scatter_warn_deg` (magnetic disturbance); camera positions
// spanning less than `min_view_spread_deg` seen from the board (all photos from one place).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/error.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {

struct BoardPhoto {
  std::string name;                        // for messages, e.g. "shot 3 (images/img_03.jpg)"
  double t_shot = 0.0;                     // shots.csv t, s; IMU instant = t_shot + δt
  Mat3 R_camera_board = Mat3::Identity();  // PnP
  Vec3 t_camera_board = Vec3::Zero();      // m
  Mat3 cov_R_camera_board = Mat3::Zero();  // rad², camera frame
};

struct CameraImu {
  Mat3 R_device_camera = Mat3::Identity();
  Mat3 covariance = Mat3::Zero();  // rad², device frame
  double time_offset_s = 0.0;
};

struct BoardWorldOptions {
  double outlier_deg = 2.0;               // a photo this far from the median is left out
  double heading_scatter_warn_deg = 1.5;  // RMS heading difference between photos
  double min_view_spread_deg = 15.0;      // largest angle between two viewing directions
  std::size_t min_photos = 2;
  int max_iterations = 100;
  /// (tilt per axis, heading) 1σ of the orientation error common to a capture, rad, replacing
  /// the track's covariance (e.g. when that is a weighting heuristic rather than calibrated).
  std::optional<Vec2> common_sigma_rad;
};

struct BoardPhotoResidual {
  std::string name;
  double angle_deg = 0.0, tilt_deg = 0.0, heading_deg = 0.0;  // of its attitude against the median
  bool outlier = false;
};

struct BoardWorldAttitude {
  Mat3 R_world_board = Mat3::Identity();
  Mat3 covariance = Mat3::Zero();          // rad², world frame
  std::vector<BoardPhotoResidual> photos;  // one per input photo, in order
  std::size_t used = 0;
  double heading_scatter_deg = 0.0;  // RMS over the photos used
  double view_spread_deg = 0.0;      // largest angle between viewing directions (board frame)
  std::vector<std::string> warnings;
};

/// MeasurementError when fewer than options.min_photos photos lie inside the track, or fewer
/// remain after outliers (naming them).
BoardWorldAttitude board_world_attitude(const std::vector<BoardPhoto>& photos,
                                        const orientation::OrientationTrack& track, const CameraImu& camera_imu,
                                        const BoardWorldOptions& options, Diagnostics& diagnostics);

/// The geodesic L1 median of rotations (Weiszfeld), started from their chordal mean.
Mat3 l1_rotation_median(const std::vector<Mat3>& rotations, int max_iterations = 100);

}  // namespace antpose::measure
