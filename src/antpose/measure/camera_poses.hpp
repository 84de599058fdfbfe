// Stage 1 of the non-contact measurement (docs/non-contact.md): every photo's camera pose in the
// board frame. The board is detected in each photo and its pose found by PnP
// (camera/board_pose.hpp); the poses are then refined jointly with the scene's features by bundle
// adjustment, the board's points fixed because they carry the metric frame
// (reconstruction/reconstruct.hpp).
//
// Photos taken at another resolution than the calibration's, with the same aspect ratio, are the
// same sensor read binned or resized: the intrinsics are rescaled to them
// (camera::rescaled_intrinsics) with a warning. Any other size is a per-photo reason.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/check.hpp"
#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/edge_pyramid.hpp"

namespace antpose::measure {

struct CameraPoseOptions {
  reconstruction::PoseRefinementOptions refinement;
  std::size_t min_photos = 2;  // with a board pose; fewer: MeasurementError
  OptionProblems Check() const;
};

struct CameraPoses {
  /// The photos' intrinsics: the calibration's, rescaled where the photos are of another size.
  camera::CameraIntrinsics intrinsics;
  std::vector<reconstruction::PosedView> views;  // the photos with a board pose, refined, in shot order
  std::vector<std::size_t> shot_of_view;         // capture.shots index of each view
  std::vector<std::string> skipped;              // "image: reason" for every photo without a pose
  reconstruction::RefinedPoses refined;          // of `views`, in the same order
  std::vector<std::string> warnings;
  /// Per view (or empty): the photo's edge images, shared by every registration's outline
  /// refinements in it (registration/edge_pyramid.hpp); see share_edge_images.
  std::vector<std::shared_ptr<registration::EdgePyramid>> edges;

  /// The view showing capture.shots[shot], if it has a pose.
  std::optional<std::size_t> view_of_shot(std::size_t shot) const;
};

/// MeasurementError when fewer than options.min_photos photos have a board pose (naming every
/// photo left out and why); InputError for a capture without photos.
CameraPoses estimate_camera_poses(const Capture& capture, const camera::BoardSpec& board,
                                  const camera::CameraIntrinsics& calibrated, const CameraPoseOptions& options,
                                  Diagnostics& diagnostics, const reconstruction::Progress& progress = {});

/// Gives every view of `poses` one shared edge-image cache prepared as `settings` say (the
/// registration's gamma and smoothing).
void share_edge_images(CameraPoses& poses, const registration::EdgePyramidSettings& settings);

}  // namespace antpose::measure
