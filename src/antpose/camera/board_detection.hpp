// Detection of a calibration board (board.hpp) in one photo, with OpenCV's detectors:
//   chessboard          cv::findChessboardCorners, then cv::cornerSubPix;
//   circles             cv::findCirclesGrid (CALIB_CB_SYMMETRIC_GRID);
//   asymmetric-circles  cv::findCirclesGrid (CALIB_CB_ASYMMETRIC_GRID);
//   charuco             cv::aruco::detectMarkers + cv::aruco::interpolateCornersCharuco, and a
//                       second, camera-aided interpolation pass when intrinsics are known (it
//                       projects the board with the pose of the found markers and so recovers
//                       corners next to markers that were missed).
// Pixel coordinates as OpenCV (origin at the centre of the top-left pixel, u right, v down);
// object points in the board frame of board.hpp, metres.
//
// A detection that is refused, or accepted but doubtful, carries a reason for the per-photo
// report ("no board found", "blurred (...)", "board partly out of view (...)", ...).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"

namespace antpose::camera {

struct DetectionOptions {
  // cv::findChessboardCorners flags (CALIB_CB_ADAPTIVE_THRESH, _NORMALIZE_IMAGE, _FAST_CHECK,
  // _FILTER_QUADS). The defaults are OpenCV's defaults.
  bool adaptive_threshold = true;
  bool normalize_image = true;
  bool fast_check = false;
  bool filter_quads = false;
  // cv::cornerSubPix: half-size of the search window (OpenCV's winSize, (11,11) in OpenCV's
  // samples), stop after this many iterations or when a corner moves less than epsilon px. On a
  // chessboard seen small the window shrinks below 0.6 of the corners' spacing (board_detection.cpp).
  int subpix_window = 11;
  int subpix_iterations = 30;
  double subpix_epsilon = 0.001;
  // Variance of the Laplacian of the greyscale image (Pech-Pacheco et al., "Diatom
  // autofocusing in brightfield microscopy", ICPR 2000) below which a photo is refused as
  // blurred. A sharp photo of a board is in the hundreds or thousands (OpenCV's 640x480
  // chessboard samples 600 to 850, the ChArUco tutorial photos 1600 to 3000); a Gaussian blur
  // of σ = 1 px brings left01.jpg from 745 to 90, σ = 2 px to 19, where corner positions lose
  // their sub-pixel accuracy. Larger photos are measured at 640 px (laplacian_variance), so
  // the threshold holds for any resolution. 0 disables the check.
  double min_laplacian_variance = 30.0;
  // A point closer than this to the image border counts as "at the border" (partial views).
  double border_margin_px = 3.0;
  // Chessboards in larger photos are found on a copy reduced to this size (findChessboardCorners'
  // quad search grows with the pixel count: seconds on 12 MP) and their corners then refined by
  // cornerSubPix on the full image. 0: always full size.
  int chessboard_search_max_side_px = 2000;
  // ChArUco: minimum number of interpolated corners for a usable view (a homography needs 4;
  // OpenCV's calibration asks for more than 3 per view; 6 gives some redundancy).
  int charuco_min_corners = 6;
  // ChArUco: camera-aided second interpolation pass when `intrinsics` is set.
  bool charuco_camera_pass = true;
  std::optional<CameraIntrinsics> intrinsics;
};

struct BoardDetection {
  bool found = false;
  /// Why the board was refused (found = false), or what makes an accepted detection doubtful
  /// (e.g. a ChArUco board partly out of view); empty for a clean detection.
  std::string reason;
  std::vector<Vec2> image_points;   // px
  std::vector<Vec3> object_points;  // board frame, m; same order as image_points
  /// Index of each point in BoardSpec::object_points() (= the ChArUco corner id).
  std::vector<int> ids;
  int markers = 0;                   // ChArUco: ArUco markers found
  double laplacian_variance = 0.0;   // sharpness, (grey levels)² (see laplacian_variance)
  int width = 0, height = 0;         // image size, px
};

/// Detects `board` in a greyscale or colour (BGR) 8-bit image.
BoardDetection detect_board(const cv::Mat& image, const BoardSpec& board, const DetectionOptions& options = {});

/// Variance of the Laplacian (3×3 aperture) of the greyscale image, in (grey levels)²; photos
/// whose longer side exceeds 800 px are first reduced to 640 px (area averaging) so that the
/// value does not depend on the resolution.
double laplacian_variance(const cv::Mat& grey);

}  // namespace antpose::camera
