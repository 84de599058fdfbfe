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
// covariance / N and the median's own from the photos' robust scatter (board_world.cpp).
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
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {

struct BoardPhoto {
  std::string name;                        // for messages, e.g. "shot 3 (images/img_03.jpg)"
  double t_shot = 0.0;                     // shots.csv t, s; IMU instant = t_shot + δt
  Mat3 R_camera_board = Mat3::Identity();  // PnP
  Vec3 t_camera_board = Vec3::Zero();      // m
  Mat3 cov_R_camera_board = Mat3::Zero();  // rad², camera frame
};

/// A magnetometer calibration (imu::ImuCalibration: m = A S (m_raw − b)) with the 1σ of its
/// parameters, each taken as independent.
struct CompassCalibration {
  Mat3 soft_iron = Mat3::Identity();  // S, det 1
  Mat3 alignment = Mat3::Identity();  // A = R_calibrated_magnetometer
  Vec3 hard_iron_sigma_uT = Vec3::Zero();
  Mat3 soft_iron_sigma = Mat3::Zero();      // per entry of S (symmetric)
  Vec3 alignment_sigma_rad = Vec3::Zero();  // per axis of A's rotation vector
};

/// The magnetometer part of an IMU calibration with its σ; nullopt where the calibration gives no
/// σ for one of its parameters (a magnetometer calibrated before they were recorded, or none).
std::optional<CompassCalibration> compass_calibration(const imu::ImuCalibration& calibration);

struct CameraImu {
  Mat3 R_device_camera = Mat3::Identity();
  Mat3 covariance = Mat3::Zero();  // rad², device frame
  double time_offset_s = 0.0;
  /// The compass's calibration and its σ; none: the profile does not say
  /// (CompassOptions::calibration_sigma_rad).
  std::optional<CompassCalibration> compass;
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
  /// The turn about the vertical (rad, counter-clockwise seen from above) that gave the board the
  /// compass's heading at the photos (heading_from_field); nullopt: the track's heading.
  std::optional<double> compass_turn_rad;
  std::vector<std::string> warnings;
};

/// MeasurementError when fewer than options.min_photos photos lie inside the track, or fewer
/// remain after outliers (naming them).
BoardWorldAttitude board_world_attitude(const std::vector<BoardPhoto>& photos,
                                        const orientation::OrientationTrack& track, const CameraImu& camera_imu,
                                        const BoardWorldOptions& options, Diagnostics& diagnostics);

struct CompassOptions {
  /// 1σ heading error of a magnetometer calibration whose profile holds no σ of its own (written
  /// by another tool, or before antpose wrote them), rad. On simulated typical phones the
  /// calibrated field at photo attitudes pointed about 0.15° RMS off magnetic north where the
  /// magnetometer's axes were not aligned to the accelerometer's (0.12° a phone, 0.11° more a
  /// site), 0.05° where they were.
  double calibration_sigma_rad = deg2rad(0.15);
  std::size_t min_photos = 2;
};

/// One photo's compass: the calibrated field in the world frame through that photo's attitude
/// from the board (field_at_photos, field_check.hpp), and that attitude.
struct CompassPhoto {
  Vec3 field_world_uT = Vec3::Zero();
  Mat3 R_world_device = Mat3::Identity();
};

/// The board's heading from the compass at the photos rather than from the orientation track.
/// Where the board's heading is right, each field's horizontal part points to magnetic north
/// (+y). The board is turned about the vertical by the median of the photos' horizontal field
/// directions. While walking, the track's heading carries its tilt errors through the dip (a 1°
/// tilt error turns a compass by tan(dip)°), and smoothing spreads them over the capture: on
/// simulated walks its heading at the photos was 0.2–1.4° off though the calibrated field there
/// pointed within 0.1° of north. Here each photo's tilt is the board's, so only the board's own
/// tilt error e reaches the heading:
///   e'_z = −tan(dip) (ĥ · e),   ĥ the field's horizontal direction (world),
/// and the covariance becomes A Σ Aᵀ + (σ_cal² + (π/2) s²/n) ẑẑᵀ, A mapping e to e' and s the
/// robust scale of the photos' field directions about their median. σ_cal is the magnetometer
/// calibration's, common to the photos: its errors (δb, δS, and A's turn δ, device frame) change
/// photo i's calibrated field m_i = R_iᵀ b_i by
///   δm_i = A (δS u_i − S δb) + δ × m_i,   u_i = S⁻¹ A⁻¹ m_i = m_raw − b,
/// and its heading ψ_i = atan2(b_x, b_y) by (b_y, −b_x, 0) / |b_h|² · R_i δm_i; σ_cal is the
/// spread of their median over the calibration's errors (sampled: the median is not linear in
/// them). Without the calibration's σ, options.calibration_sigma_rad. Fewer than
/// options.min_photos fields, or a field without a horizontal part: the board is returned unchanged.
BoardWorldAttitude heading_from_field(BoardWorldAttitude board, const std::vector<CompassPhoto>& photos,
                                      const std::optional<CompassCalibration>& calibration,
                                      const CompassOptions& options);

/// The geodesic L1 median of rotations (Weiszfeld), started from their chordal mean.
Mat3 l1_rotation_median(const std::vector<Mat3>& rotations, int max_iterations = 100);

}  // namespace antpose::measure
