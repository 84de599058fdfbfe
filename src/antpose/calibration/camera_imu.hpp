// Camera–IMU calibration: the rotation R_device_camera (camera frame → Android device frame) and
// the camera–IMU time offset, from photos of a calibration board (docs/camera-imu.md).
//
// Input per photo: the shot time, the board placement, and the board attitude in the camera
// frame from PnP, R_camera_board, with its covariance (rad², camera frame: R_true = exp(δ) R_est).
// The phone's attitude comes from an orientation track (orientation/estimator.hpp), whose
// covariance is world-frame (δ_z heading, δ_x, δ_y tilt). With X = R_device_camera every photo
// i of placement p predicts the board's world attitude
//     R_world_board = R_world_device(t_i + δt) · X · R_camera_board_i.               (1)
//
// A. Thesis method (thesis §5.2–5.4): compare the angles of (1) with a level and a compass
//    (board_reference.csv: G = angle from straight down, N = clockwise from north of the
//    horizontal projection) and minimise Σ w² (predicted − measured)² over X (Levenberg–
//    Marquardt, Ceres). Weights: w1 for G lines, w2 for N lines, w3 for N lines of a "steep"
//    axis (within steep_axis_deg of the vertical), whose compass angle is ill-defined: its
//    horizontal projection is short, so small tilts swing its azimuth (thesis eq. 5.13/5.14).
//    w3 = 0 (default) drops those lines; a warning names a placement left without N line.
// B. Reference-free (antpose): the board does not move within a placement, so every photo of
//    placement p must show the same board attitude. The relative rotations of the phone between
//    its photos come from the gyroscope alone, integrated across the placement with a bias
//    correction estimated per placement (preintegration, orientation/gyro_integration.hpp):
//    a filter's absolute attitude leans into the linear accelerations of the walk around the
//    board, nearly constantly in the device frame, which would pass straight into X.
//    Unknowns: X, δt, and per placement the board attitude in the gyro frame and the bias; for a
//    gyroscope without its calibration also a correction I + G of its rates, common to all
//    placements, with the phone's scale and cross-axis tolerances as priors, so that σ(δt) and
//    the covariance carry what the photos leave unknown of them.
//    Start: hand–eye rotation A X = X B on all photo pairs of a placement (Park & Martin 1994,
//    rotation step, solved as an orthogonal Procrustes problem), board attitudes by chordal L2
//    averaging (Hartley et al. 2013), δt by a grid search; then Ceres refines the whitened
//    residuals log(ΔR_p(t_i+δt; b_p) X R_camera_board_i R_gyro_board_pᵀ) under a Huber loss,
//    flags outliers, and refits without them. The orientation track only places each board in
//    the world (and checks it against board_reference.csv when given).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "antpose/calibration/board_reference.hpp"
#include "antpose/camera/board_pose.hpp"
#include "antpose/core/check.hpp"
#include "antpose/core/error.hpp"
#include "antpose/orientation/estimator.hpp"
#include "antpose/store/device_profile.hpp"

namespace antpose::calibration {

/// One photo of the board.
struct PhotoObservation {
  double t_shot = 0.0;          // shots.csv t, s (capture clock); IMU instant = t_shot + δt
  std::string placement;
  Mat3 R_camera_board = Mat3::Identity();
  Mat3 cov_R_camera_board = Mat3::Zero();  // rad², camera frame (R_true = exp(δ) R_est)
  std::string name;             // for messages, e.g. "shot 7 (images/img_07.jpg)"
};

/// Observations from the board poses of a capture (camera::board_poses): placement from the
/// shots' `placement` column (InputError as shot_placements), name "shot <index> (<image>)",
/// covariance = the rotation block of the pose covariance. Shots without a pose are skipped
/// (board_poses has warned about them).
std::vector<PhotoObservation> photo_observations(const Capture& capture,
                                                 const std::vector<camera::PhotoBoardPose>& poses);

/// Predicted reference angle (rad) of a board axis for a board attitude R_world_board (world
/// ENU-magnetic): G = angle from straight down in [0, π]; N = clockwise from north of the
/// horizontal projection in [0, 2π) (NaN for an exactly vertical axis).
double reference_angle(const Mat3& R_world_board, BoardAxis axis, AngleReference ref);

// ---- A. thesis method ------------------------------------------------------------------------

struct ThesisOptions {
  enum class Start { kNominal, kIdentity, kGiven };
  Start start = Start::kNominal;            // camera::nominal_R_device_camera(), I, or R_start
  Mat3 R_start = Mat3::Identity();
  double w1 = 1.0;    // G lines
  double w2 = 0.2;    // N lines (≈ σ_G / σ_N of a level at ±0.2° and a compass at ±1.5°, plus heading noise)
  double w3 = 0.0;    // N lines of steep axes (ill-defined azimuth)
  double steep_axis_deg = 30.0;  // an axis within this angle of the vertical is steep
  double time_offset_s = 0.0;    // IMU instant = t_shot + time_offset_s
  int max_iterations = 100;
};

/// Mean absolute angle errors per placement (the thesis's tables): over every photo × line.
struct AngleErrorRow {
  std::string placement;
  std::size_t photos = 0;
  std::size_t g_lines = 0, n_lines = 0;   // lines used (photo × line counts are photos × these)
  std::size_t n_lines_steep = 0;          // N lines left out (steep axis, weight 0)
  double downtilt_error_deg = std::numeric_limits<double>::quiet_NaN();  // mean |ΔG|, NaN without G line
  double azimuth_error_deg = std::numeric_limits<double>::quiet_NaN();   // mean |ΔN| (wrapped), NaN without N line
};

struct AngleErrorTable {
  std::string method;   // orientation method (track.method)
  std::string matrix;   // which R_device_camera: "optimised", "nominal", "reference-free", ...
  std::vector<AngleErrorRow> placements;
  AngleErrorRow overall;  // placement "all"
};

/// Angle errors of the reference lines predicted by (1) with the given X and δt. Photos of
/// placements without lines are ignored; N lines whose weight is 0 (steep, w3 = 0) are counted
/// in n_lines_steep and left out of the means.
AngleErrorTable reference_angle_errors(const std::vector<PhotoObservation>& photos, const BoardReference& reference,
                                       const orientation::OrientationTrack& track, const Mat3& R_device_camera,
                                       double time_offset_s, const ThesisOptions& options, std::string matrix_label);

struct ThesisCalibration {
  std::string method;                     // orientation method of the track
  Mat3 R_device_camera = Mat3::Identity();
  Mat3 covariance = Mat3::Zero();         // rad², device frame; cluster-robust over placements (≥ 4)
  double rms_weighted_deg = 0.0;          // RMS of the weighted angle residuals
  std::size_t residuals = 0;              // photo × line terms
  int iterations = 0;
  bool converged = false;
  AngleErrorTable optimised;              // with R_device_camera
  AngleErrorTable nominal;                // with camera::nominal_R_device_camera()
  std::vector<std::string> warnings;
};

/// Method A on one orientation track. MeasurementError when no photo has a reference line or
/// every weight is 0; photos outside the track are left out with a warning naming them.
ThesisCalibration calibrate_thesis(const std::vector<PhotoObservation>& photos, const BoardReference& reference,
                                   const orientation::OrientationTrack& track, const ThesisOptions& options,
                                   Diagnostics& diagnostics);

/// The thesis's tables as text: per orientation method, mean |downtilt| and |azimuth| errors
/// per placement and overall, with the optimised and the nominal matrix.
std::string format_thesis_tables(const std::vector<ThesisCalibration>& results);
/// One table (used by format_thesis_tables and for the reference check of method B).
std::string format_angle_error_table(const AngleErrorTable& table);

// ---- B. reference-free method ----------------------------------------------------------------

/// Closed-form hand–eye rotation X = R_device_camera from photo pairs (i, j) of the same group
/// (placement): A = R_world_device_i^T R_world_device_j, B = R_camera_board_i R_camera_board_j^T
/// satisfy A X = X B, hence log(A) = X log(B) (Park & Martin, IEEE T-RA 10(5), 1994, eq. 10);
/// X is the rotation minimising Σ ‖log A − X log B‖² over all pairs (Kabsch/Umeyama SVD), the
/// pair weight being implicitly its rotation angle. OpenCV's calibrateHandEye solves the same
/// for ONE fixed target; here pairs of several placements are pooled.
Mat3 hand_eye_rotation(const std::vector<Mat3>& R_world_device, const std::vector<Mat3>& R_camera_board,
                       const std::vector<std::size_t>& group);


struct ReferenceFreeOptions {
  std::optional<Mat3> R_start;              // skip the closed-form start (still refined)
  bool estimate_time_offset = true;
  double time_offset_start_s = 0.0;         // used when δt is not estimated or unobservable
  double time_offset_min_s = -0.2, time_offset_max_s = 0.2;  // grid-search bracket
  double time_offset_step_s = 0.005;
  double max_time_offset_sigma_s = 0.02;    // larger σ(δt): unobservable, δt fixed with a warning
  double min_rate_deg_s = 0.5;              // every shot slower than this: δt not attempted
  std::size_t min_photos_per_placement = 3;
  double min_view_change_deg = 3.0;         // a placement whose photos differ less is "one pose"
  double min_axis_spread_deg = 2.0;         // RMS relative rotation off the dominant axis
  /// Gyroscope sample convention of the estimators (OrientationOptions::gyro_trapezoid): δt then
  /// includes the same lag as the orientation track used for measurements.
  bool gyro_trapezoid = false;
  double gyro_noise_density = 3e-4;         // rad/s/√Hz, angle random walk of the integration
  double gyro_bias_sigma_rad_s = 0.0175;    // prior σ of each placement's bias correction (1°/s)
  /// A gyroscope without its calibration (`antpose calibrate imu`): 1σ of its scale-factor errors
  /// and of its cross-axis (misalignment) terms, dimensionless. Both 0 (the default): the rates
  /// are taken as calibrated. Both positive: a correction ω ← (I + G) ω common to all placements
  /// is estimated with these priors, so the covariance and σ(δt) carry what the photos leave
  /// unknown of it (assume_uncalibrated_gyroscope() sets a phone's budget).
  double gyro_scale_sigma = 0.0;
  double gyro_cross_axis_sigma = 0.0;
  double max_gyro_gap_s = 0.1;              // a longer gyroscope gap leaves the placement out
  /// 1σ of the rotation error that the intrinsics give every board pose alike (rad, about the
  /// camera's x and y axes): a principal point off by δ turns each PnP pose by about δ/f, which
  /// passes unseen into X. Added to the covariance; from principal_point_rotation_sigma().
  Vec2 camera_rotation_sigma_rad = Vec2::Zero();
  double default_pnp_sigma_deg = 0.1;       // photo without (positive definite) covariance
  double sigma_floor_deg = 0.02;            // added in quadrature to every photo's noise
  double huber_k = 3.0;                     // Huber threshold on the whitened residual norm
  double outlier_chi2 = 16.27;              // χ²₃(0.999) on the robustly normalised residual
  double min_outlier_deg = 0.1;             // and a residual angle above this (noise-free data)
  /// χ²/dof of the inliers' whitened residuals (the variance factor) beyond this, the fit is
  /// refused: residuals five times the photos' expected noise say the model does not describe
  /// them (a fixed time offset far from the true one, a board moved within a placement), and a
  /// covariance scaled by such a misfit would still understate the error.
  double max_variance_factor = 25.0;
  /// A time offset given as fixed (estimate_time_offset false) that the photos, refitted with it
  /// free, put further away than this many σ is refused (where the phone moved at the shots).
  double max_fixed_offset_z = 5.0;
  int max_iterations = 100;

  /// The error budget of an uncalibrated phone gyroscope, 1σ: scale 0.5 %, each cross-axis term
  /// 0.3 %. It is the spread of the simulator's seed-001 error model (sim::PhoneModel::random:
  /// scale 1 + N(0, 0.005), off-diagonal misalignment N(0, 0.003)), which sim/imu_simulator.hpp
  /// draws within the ST LSM6DS3 datasheet's tolerances (sensitivity and cross-axis ≈ 1 %, partly
  /// trimmed by the factory calibration). A phone whose gyroscope is worse needs `calibrate imu`.
  void assume_uncalibrated_gyroscope() {
    gyro_scale_sigma = 0.005;
    gyro_cross_axis_sigma = 0.003;
  }
  bool gyro_uncalibrated() const { return gyro_scale_sigma > 0.0 || gyro_cross_axis_sigma > 0.0; }

  /// What is wrong with the options: every value finite and in its range, the start (or fixed)
  /// time offset inside the grid-search bracket, the gyroscope's error priors both 0 or both
  /// positive.
  OptionProblems Check() const;
};

struct PhotoResidual {
  std::size_t photo = 0;          // index into the input photos
  std::string name, placement;
  double angle_deg = 0.0;         // fit residual |log(ΔR X R_camera_board R_gyro_boardᵀ)|
  // The photo's board attitude through the orientation track against the placement's mean
  // (world frame): the track's error at this photo, horizontal (tilt) and vertical (heading, signed).
  double tilt_deg = 0.0;
  double heading_deg = 0.0;
  double normalised = 0.0;        // whitened squared norm / variance factor (≈ χ²₃ for an inlier)
  bool outlier = false;
};

struct PlacementAttitude {
  std::string placement;
  Mat3 R_world_board = Mat3::Identity();  // world frame of the track (ENU-magnetic by default)
  std::size_t photos = 0;                 // used in the fit (outliers excluded)
  double rms_deg = 0.0;                   // RMS fit residual angle of those photos
  Vec3 gyro_bias_rad_s = Vec3::Zero();    // bias correction estimated over this placement
};

struct ReferenceFreeCalibration {
  Mat3 R_device_camera = Mat3::Identity();
  Mat3 covariance = Mat3::Zero();         // rad², device frame (R_true = exp(δ) R_est)
  Mat3 R_device_camera_closed_form = Mat3::Identity();
  double time_offset_s = 0.0;
  double time_offset_sigma_s = std::numeric_limits<double>::quiet_NaN();  // NaN when not estimated
  bool time_offset_estimated = false;
  double time_offset_grid_s = 0.0;        // the grid-search start
  /// σ(δt) with the gyroscope correction held at its estimate: what the photos and the
  /// gyroscope's noise alone allow (= time_offset_sigma_s for a calibrated gyroscope).
  double time_offset_sigma_fit_s = std::numeric_limits<double>::quiet_NaN();
  /// Uncalibrated gyroscope (ReferenceFreeOptions::gyro_scale_sigma): the estimated correction
  /// I + G (ω_corrected = (I + G) ω_measured, before the bias) and the 1σ of G's elements.
  bool gyro_correction_estimated = false;
  Mat3 gyro_correction = Mat3::Identity();
  Mat3 gyro_correction_sigma = Mat3::Zero();
  double variance_factor = 1.0;           // χ²/dof of the whitened residuals (scales the
                                          // covariance where above 1)
  std::vector<PhotoResidual> residuals;   // one per photo used (outliers included, flagged)
  std::vector<std::size_t> outliers;      // indexes into the input photos
  std::vector<PlacementAttitude> boards;
  std::optional<AngleErrorTable> reference_check;  // when a board reference is given
  std::vector<std::string> warnings;

  /// 1σ per device axis (deg) from the covariance diagonal.
  Vec3 rotation_sigma_deg() const;
  /// The result as stored in a device profile (method "reference-free").
  store::CameraImuCalibration to_profile() const;
};

/// (σ(cy)/fy, σ(cx)/fx): the rotation about the camera's x and y axes that a principal-point
/// error gives every board pose (ReferenceFreeOptions::camera_rotation_sigma_rad).
Vec2 principal_point_rotation_sigma(const camera::CameraIntrinsics& intrinsics, const Vec2& principal_point_sigma_px);

/// Method B. `gyroscope`: the device-frame rates (rad/s) the track was estimated from, with the
/// device's IMU calibration applied (or, without one, options.assume_uncalibrated_gyroscope()).
/// Warnings (also in `diagnostics`) for photos outside the track (named), placements with too
/// few photos, taken from one pose or broken by a gyroscope gap (left out), outliers, an
/// unobservable time offset (phone still at every shot) and an uncalibrated gyroscope.
/// MeasurementError when no usable placement remains, the relative rotations are all about one
/// axis (R_device_camera not observable), or the uncalibrated gyroscope's errors alone push σ(δt)
/// past max_time_offset_sigma_s (the message says to run `antpose calibrate imu`). `reference`,
/// when given, only checks the result (AngleErrorTable "reference-free").
ReferenceFreeCalibration calibrate_reference_free(const std::vector<PhotoObservation>& photos,
                                                  const orientation::SensorSeries& gyroscope,
                                                  const orientation::OrientationTrack& track,
                                                  const ReferenceFreeOptions& options, Diagnostics& diagnostics,
                                                  const BoardReference* reference = nullptr);

}  // namespace antpose::calibration
