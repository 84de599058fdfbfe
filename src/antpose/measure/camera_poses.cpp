#include "antpose/measure/camera_poses.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/io/photo_file.hpp"

namespace antpose::measure {
namespace {

// The intrinsics of the capture's photos: the calibration's, or rescaled to the photos' common
// size where that is the same sensor at another resolution.
camera::CameraIntrinsics photo_intrinsics(const Capture& capture, const camera::CameraIntrinsics& calibrated,
                                          std::vector<std::string>& warnings) {
  const auto size = io::common_photo_size(io::read_photo_headers(capture));
  if (!size) return calibrated;  // each photo then gets its own reason
  const int width = size->width, height = size->height;
  if (width == calibrated.width && height == calibrated.height) return calibrated;
  const auto rescaled = camera::rescaled_intrinsics(calibrated, width, height);
  if (!rescaled) return calibrated;  // each photo then gets the size mismatch as its reason
  warnings.push_back(fmt::format(
      "the photos are {}×{} px and the camera was calibrated at {}×{} px: its intrinsics are scaled by {:.4f} "
      "(the same sensor read at a lower resolution); calibrate at this resolution if the phone crops instead",
      width, height, calibrated.width, calibrated.height, static_cast<double>(width) / calibrated.width));
  return *rescaled;
}

}  // namespace

OptionProblems CameraPoseOptions::Check() const {
  OptionProblems p;
  p.require(min_photos >= 2, "min_photos", "at least 2 (two views fix a point)");
  p.require(refinement.max_features_per_view > 0, "refinement.max_features_per_view", "positive");
  p.require(refinement.ratio_test > 0 && refinement.ratio_test < 1, "refinement.ratio_test", "in (0, 1)");
  p.require(refinement.max_board_rms_growth >= 1, "refinement.max_board_rms_growth", "at least 1");
  return p;
}

std::optional<std::size_t> CameraPoses::view_of_shot(std::size_t shot) const {
  const auto at = std::find(shot_of_view.begin(), shot_of_view.end(), shot);
  if (at == shot_of_view.end()) return std::nullopt;
  return static_cast<std::size_t>(at - shot_of_view.begin());
}

CameraPoses estimate_camera_poses(const Capture& capture, const camera::BoardSpec& board,
                                  const camera::CameraIntrinsics& calibrated, const CameraPoseOptions& options,
                                  Diagnostics& diagnostics, const reconstruction::Progress& progress) {
  throw_unless_ok(options.Check(), "CameraPoseOptions");
  if (capture.shots.empty()) throw InputError(capture.root / "shots.csv", "the capture has no photos");
  CameraPoses out;
  out.intrinsics = photo_intrinsics(capture, calibrated, out.warnings);
  if (progress) progress("board poses", 0, 1);
  for (const auto& p : camera::board_poses(capture, board, out.intrinsics, diagnostics)) {
    if (!p.pose) {
      out.skipped.push_back(p.image + ": " + p.reason);
      continue;
    }
    reconstruction::PosedView v;
    v.name = fmt::format("shot {} ({})", p.shot_index, p.image);
    v.image = io::read_photo(capture.root / p.image, cv::IMREAD_GRAYSCALE).image;
    v.R_camera_board = p.pose->R_camera_board;
    v.t_camera_board = p.pose->t_camera_board;
    v.board_image_px = p.image_points_px;
    v.board_points_m = p.board_points_m;
    out.views.push_back(std::move(v));
    out.shot_of_view.push_back(p.shot_index);
  }
  if (progress) progress("board poses", 1, 1);
  if (out.views.size() < options.min_photos) {
    std::string why;
    for (const auto& s : out.skipped) why += "\n  " + s;
    throw MeasurementError(fmt::format("the board was found in {} of {} photos; at least {} are needed{}",
                                       out.views.size(), capture.shots.size(), options.min_photos, why));
  }
  out.refined = reconstruction::refine_camera_poses(out.views, out.intrinsics, options.refinement, progress);
  for (std::size_t i = 0; i < out.views.size(); ++i) {
    out.views[i].R_camera_board = out.refined.R_camera_board[i];
    out.views[i].t_camera_board = out.refined.t_camera_board[i];
  }
  out.warnings.insert(out.warnings.end(), out.refined.warnings.begin(), out.refined.warnings.end());
  return out;
}

void share_edge_images(CameraPoses& poses, const registration::EdgePyramidSettings& settings) {
  poses.edges.clear();
  for (const auto& v : poses.views)
    poses.edges.push_back(std::make_shared<registration::EdgePyramid>(v.image, settings));
}

}  // namespace antpose::measure
