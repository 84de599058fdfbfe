// Pose of a calibration board in the camera frame from one photo (perspective-n-point) with
// calibrated intrinsics: cv::solvePnP with SOLVEPNP_IPPE for a planar board (Collins &
// Bartoli, "Infinitesimal Plane-Based Pose Estimation", IJCV 2014), SOLVEPNP_SQPNP otherwise,
// then Levenberg–Marquardt refinement of the reprojection error (cv::solvePnPRefineLM).
//
// Frames: board frame of board.hpp (metres), camera frame of the conventions (x right, y down,
// z forward); p_camera = R_camera_board p_board + t_camera_board.
//
// Covariance (Gauss–Newton, e.g. Hartley & Zisserman 2nd ed. §5.2.3): with the residual
// r_i = π(exp(δ) R p_i + t) − u_i (2 per point), J = ∂r/∂(δ, t) at the estimate and the
// residual variance σ² = Σ|r_i|² / (2N − 6), cov(δ, t) = σ² (JᵀJ)⁻¹. δ is the rotation vector
// of the left perturbation R_true = exp(δ) R_est in the camera frame (rad), t in metres.
// It describes the pixel noise seen in this photo only (not intrinsics errors).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "antpose/camera/board.hpp"
#include "antpose/camera/board_detection.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::camera {

struct BoardPose {
  Mat3 R_camera_board = Mat3::Identity();  // rotates board-frame vectors into the camera frame
  Vec3 t_camera_board = Vec3::Zero();      // m, board origin in the camera frame
  double rms_px = 0;                       // reprojection RMS of this photo
  std::size_t points = 0;
  /// Of (rotation vector δ with R_true = exp(δ) R_est, camera frame, rad; t m), from the PnP
  /// Jacobian and the residual variance.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

/// Board pose from matching pixels (px, distorted, as detected) and board points (m).
/// MeasurementError if fewer than 4 points, sizes differ, the board points are (nearly)
/// collinear, or the pose is not determined (singular Jacobian, board behind the camera).
/// `intrinsics` must be valid (CameraIntrinsics::invalid_reason empty; antpose::Error otherwise).
BoardPose estimate_board_pose(const std::vector<Vec2>& image_points_px, const std::vector<Vec3>& board_points_m,
                              const CameraIntrinsics& intrinsics);

struct PhotoBoardPose {
  std::size_t shot_index;  // position in Capture::shots
  double t;                // shot time, capture clock, s
  std::string image;       // path relative to the capture
  std::optional<BoardPose> pose;
  std::string reason;              // empty when pose
  std::vector<std::string> extra;  // the shot's extra columns, e.g. placement
  std::vector<Vec2> image_points_px;  // the detection the pose rests on (empty without a pose)
  std::vector<Vec3> board_points_m;
};

/// Detects the board in every photo of the capture and estimates its pose: one entry per shot,
/// in shot order. A photo that is unreadable, of another size than the intrinsics, without a
/// usable board or with a degenerate pose gets a reason (and a warning naming the image);
/// a doubtful but usable detection (e.g. a ChArUco board partly out of view) gets a warning.
std::vector<PhotoBoardPose> board_poses(const Capture& capture, const BoardSpec& board,
                                        const CameraIntrinsics& intrinsics, Diagnostics& diagnostics);
/// The same with explicit detector settings (options.intrinsics is set from `intrinsics`).
std::vector<PhotoBoardPose> board_poses(const Capture& capture, const BoardSpec& board,
                                        const CameraIntrinsics& intrinsics, Diagnostics& diagnostics,
                                        const DetectionOptions& options);

/// The camera's optical centre in the board frame, m: −R_camera_boardᵀ t_camera_board.
inline Vec3 camera_centre(const Mat3& R_camera_board, const Vec3& t_camera_board) {
  return -R_camera_board.transpose() * t_camera_board;
}

/// Reprojection residuals (px) of board points with a pose: π(R p + t) − u, for each point.
std::vector<Vec2> reprojection_residuals(const std::vector<Vec2>& image_points_px,
                                         const std::vector<Vec3>& board_points_m, const CameraIntrinsics& intrinsics,
                                         const Mat3& R_camera_board, const Vec3& t_camera_board);

/// "" when the image size matches the intrinsics, else the reason (e.g. a portrait photo for
/// landscape intrinsics).
std::string image_size_mismatch(int width, int height, const CameraIntrinsics& intrinsics);

}  // namespace antpose::camera
