// Intrinsic camera calibration from photos of a board (Zhang, "A flexible new technique for
// camera calibration", PAMI 2000, as implemented by cv::calibrateCamera with standard deviations —
// Python's calibrateCameraExtended), with the
// settings of OpenCV's camera-calibration tutorial sample (the thesis's XML settings file,
// §7.4.4, fig. 7.9) or of our own YAML config, a per-photo report and a robust second pass.
//
// Pixels as OpenCV (origin at the centre of the top-left pixel); lens model of
// camera_model.hpp (k1, k2, p1, p2, k3); extrinsics map the board frame (board.hpp, m) into the
// camera frame (x right, y down, z forward).
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/camera/board_detection.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::camera {

struct CalibrationSettings {
  /// Board given by the config; it wins over the capture's board.yaml (a disagreement is a
  /// warning), because the user chose the config for this run.
  std::optional<BoardSpec> board;
  std::filesystem::path board_source;  // the config file, for messages

  // cv::calibrateCamera flags.
  bool fix_aspect_ratio = false;       // CALIB_FIX_ASPECT_RATIO, fx/fy = aspect_ratio (or the guess's ratio)
  double aspect_ratio = 1.0;           // fx/fy
  bool zero_tangent = false;           // CALIB_ZERO_TANGENT_DIST (p1 = p2 = 0)
  bool fix_principal_point = false;    // CALIB_FIX_PRINCIPAL_POINT (image centre, or the guess's)
  /// Number of estimated coefficients in OpenCV order [k1, k2, p1, p2, k3]: 5 (all), 4 (k3 = 0),
  /// 2 (k1, k2; p1 = p2 = k3 = 0) or 1 (k1 only). The others are fixed at zero (or at the guess).
  int distortion_coefficients = 5;
  /// Fix k1, k2, k3 individually (the tutorial's Fix_K1..Fix_K3): CALIB_FIX_K1..3.
  std::array<bool, 3> fix_k{};
  /// CALIB_USE_INTRINSIC_GUESS: start from (and, with the fix flags, keep) these intrinsics.
  std::optional<CameraIntrinsics> intrinsics_guess;

  /// Flip every photo around the horizontal axis before detection (the tutorial sample's
  /// Input_FlipAroundHorizontalAxis; cv::flip(image, image, 0)).
  bool flip_vertical = false;
  /// Use at most this many usable photos, in shot order (Calibrate_NrOfFrameToUse); 0 = all.
  int max_images = 0;

  DetectionOptions detection;

  // Robust pass: a photo whose RMS is above outlier_factor × the median per-photo RMS AND
  // above outlier_min_px is refused and the calibration re-run. Both conditions: good photos
  // of one set spread by a factor of up to ~6 (OpenCV's sample set: 0.16 to 1.22 px, the worst
  // a steep, strongly distorted view that is still correct), whereas a blunder (corners of a
  // wrong board or ordering, motion smear) errs by whole pixels; the pixel floor keeps a sharp
  // set with a tiny median from shedding correct photos at sub-pixel differences.
  double outlier_factor = 5.0;
  double outlier_min_px = 2.0;
  int min_images = 3;  // fewer usable photos: MeasurementError
};

/// Reads a settings file: the OpenCV tutorial sample's XML/YAML FileStorage file
/// (<opencv_storage><Settings> with BoardSize_Width, BoardSize_Height, Square_Size,
/// Marker_Size, Calibrate_Pattern, ArUco_Dict_Name, Input_FlipAroundHorizontalAxis,
/// Calibrate_NrOfFrameToUse, Calibrate_FixAspectRatio, Calibrate_AssumeZeroTangentialDistortion,
/// Calibrate_FixPrincipalPointAtTheCenter, Fix_K1..Fix_K5; Input, Input_Delay,
/// Write_DetectedFeaturePoints, Write_extrinsicParameters, Write_gridPoints,
/// Write_outputFileName, Show_UndistortedImage, Calibrate_UseFisheyeModel are checked and
/// otherwise ignored: the capture supplies the photos and -o the output), or our YAML config
/// (all keys optional; unknown keys are errors):
///   board: {type, cols, rows, square_m, marker_m, dictionary}   as board.yaml
///   fix_aspect_ratio: true | <fx/fy>       zero_tangent_distortion: bool
///   fix_principal_point: bool              distortion_coefficients: 5 | 4 | 2 | 1
///   intrinsics_guess: camera.yaml          (relative to the config file)
///   flip_vertical: bool                    max_images: N (0 = all)
///   detection: {adaptive_threshold, normalize_image, fast_check, filter_quads, subpix_window,
///               subpix_iterations, subpix_epsilon, min_laplacian_variance, border_margin_px,
///               charuco_min_corners, charuco_camera_pass}     (DetectionOptions)
///   robust: {outlier_factor, outlier_min_px, min_images}
/// A file is read as OpenCV FileStorage when it contains <opencv_storage> or starts with
/// "<?xml" or "%YAML". Square_Size (and Marker_Size) above 1 are read as millimetres (the
/// tutorial's unit-free defaults are 50 and 25), with a warning. InputError naming the file,
/// the element (or key and line) and what was expected for every bad value.
CalibrationSettings read_calibration_settings(const std::filesystem::path& file, Diagnostics& diagnostics);

/// One view for the solver: matching pixels and board points.
struct CalibrationView {
  std::string name;  // image, for messages
  std::vector<Vec2> image_points;
  std::vector<Vec3> object_points;
};

struct CalibrationImage {
  std::size_t shot_index = 0;
  std::string image;           // path relative to the capture
  bool used = false;           // in the final calibration
  std::size_t points = 0;      // detected points (0 when not found)
  std::optional<double> rms_px;  // per-photo RMS in the last calibration it took part in
  std::string reason;          // why refused; or a note on a usable photo (e.g. partly out of view)
  Vec3 rvec = Vec3::Zero();    // board → camera, Rodrigues (rad), for used photos
  Vec3 tvec = Vec3::Zero();    // m
};

struct IntrinsicsSigma {  // 1σ from calibrateCameraExtended; 0 for fixed parameters
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};
};

struct CameraCalibrationResult {
  CameraIntrinsics intrinsics;
  double rms_px = 0;  // over all points of the used photos (value of calibrateCamera)
  IntrinsicsSigma sigma;
  std::vector<CalibrationImage> images;  // one per shot (or per view), in order
  int flags = 0;                         // cv::calibrateCamera flags used
  std::vector<std::string> flag_names;   // e.g. CALIB_FIX_ASPECT_RATIO
  BoardSpec board;
  int rounds = 1;                        // calibrations run (1 + robust re-runs)

  std::size_t used_count() const;
  /// (image, reason) of every refused photo.
  std::vector<std::pair<std::string, std::string>> rejected() const;
};

/// Calibration from detected views (the solver part; also for tests on stored corners).
/// `images` receives one CalibrationImage per view (detection-refused views can be passed with
/// their reason and no points). MeasurementError naming the reasons when fewer than
/// settings.min_images views remain.
CameraCalibrationResult calibrate_views(const std::vector<CalibrationView>& views, int width, int height,
                                        const CalibrationSettings& settings,
                                        std::vector<CalibrationImage> images = {});

using CalibrationProgress = std::function<void(const CalibrationImage& image, std::size_t done, std::size_t total)>;

/// Calibration over a capture with shots.csv, images and a board (board.yaml, or the
/// settings' board). Every photo is read (cv::imread), optionally flipped, detected; refused
/// photos keep their reason (also as a warning naming the image). All photos must have one
/// size (others are refused). `progress` is called after each photo's detection.
CameraCalibrationResult calibrate_camera(const Capture& capture, const CalibrationSettings& settings,
                                         Diagnostics& diagnostics, const CalibrationProgress& progress = {});
/// Reads the capture folder first.
CameraCalibrationResult calibrate_camera(const std::filesystem::path& capture_folder,
                                         const CalibrationSettings& settings, Diagnostics& diagnostics,
                                         const CalibrationProgress& progress = {});

/// OpenCV FileStorage YAML as the tutorial sample writes it (calibration_time, nr_of_frames,
/// image_width, image_height, board_width, board_height, square_size, fix_aspect_ratio, flags,
/// camera_matrix, distortion_coefficients, avg_reprojection_error,
/// per_view_reprojection_errors, extrinsic_parameters), plus our per-image names and σ.
std::string format_camera_file(const CameraCalibrationResult& result);
/// Writes it atomically (temporary file + rename). An existing file is kept (InputError) unless
/// `force`.
void write_camera_file(const std::filesystem::path& file, const CameraCalibrationResult& result, bool force);

struct CameraFile {
  CameraIntrinsics intrinsics;
  std::optional<double> rms_px;                   // avg_reprojection_error
  std::optional<Vec2> principal_point_sigma_px;   // 1σ of cx, cy (camera_matrix_std_dev), when written
};
/// Reads a camera file of the tutorial sample / OpenCV samples / ours (camera_matrix,
/// distortion_coefficients with 4, 5 or more entries — beyond 5 must be zero —, image_width,
/// image_height). InputError naming the file and the element.
CameraFile read_camera_file(const std::filesystem::path& file);

/// The intrinsics and RMS for a device profile (store/device_profile.hpp's camera section).
struct ProfileCamera {
  CameraIntrinsics intrinsics;
  double rms_px = 0;
  Vec2 principal_point_sigma_px = Vec2::Zero();  // 1σ of cx, cy
};
ProfileCamera profile_camera(const CameraCalibrationResult& result);

/// Multi-line text: per-image table (image, points, RMS px or the reason), the result with 1σ.
std::string describe(const CameraCalibrationResult& result);

}  // namespace antpose::camera
