// The antenna's 3-D points from photos that also show the calibration board (thesis ch. 6.2).
//
// Two stages, both in the board frame (metric, because the board's points are known in metres):
//   1. refine_camera_poses: every photo's PnP pose (camera/board_pose.hpp), refined jointly with
//      the scene points that features tie between the photos (bundle adjustment with Ceres,
//      intrinsics fixed, the board's points fixed: they carry the metric frame).
//   2. reconstruct_region: the user's rectangle in one photo is carried into the others through
//      the geometry (the depth range of the features triangulated inside it), and the region is
//      reconstructed by semi-global matching on rectified pairs (Hirschmüller 2008) with a
//      sub-pixel and texture check, plus the features' points; filtered (multi-view
//      consistency, statistical outlier removal, Rusu 2008), downsampled and given normals.
//      Plain grey radomes give points on edges and details only (region_coverage, a warning);
//      see docs/reconstruction.md for the method and measured accuracy.
// Frames: p_camera = R_camera_board p_board + t_camera_board (camera frame of the conventions).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"
#include "antpose/core/error.hpp"
#include "antpose/geometry/point_cloud.hpp"

namespace antpose::reconstruction {

/// One photo with the board detected in it and its PnP pose.
struct PosedView {
  std::string name;  // for messages, e.g. "shot 3 (images/img_03.jpg)"
  cv::Mat image;     // CV_8UC1, as taken (distorted)
  Mat3 R_camera_board = Mat3::Identity();
  Vec3 t_camera_board = Vec3::Zero();  // m
  std::vector<Vec2> board_image_px;    // detected board points (distorted px)
  std::vector<Vec3> board_points_m;    // the same points on the board, board frame
};

/// A rectangle in one image, px: columns [x, x + width), rows [y, y + height).
struct Roi {
  int x = 0, y = 0, width = 0, height = 0;
};

/// Called with (stage name, done, total) as long stages advance, never concurrently. Stages:
/// "features", "matching", "triangulation", "bundle adjustment" (refine_camera_poses);
/// "region features", "dense stereo", "filtering" (reconstruct_region).
using Progress = std::function<void(const std::string&, int, int)>;

struct PoseRefinementOptions {
  int max_features_per_view = 4000;
  double ratio_test = 0.8;           // Lowe's ratio
  double max_epipolar_px = 2.0;      // matches farther from the PnP epipolar line are dropped
  double huber_px = 1.0;             // robust loss on the scene points' reprojections
  double max_reprojection_px = 3.0;  // observations beyond this after a first solve are removed
  int max_iterations = 50;
  /// The scene's tracks are rejected, and the poses rest on the board alone, where with them the
  /// board's reprojection RMS exceeds this many times its RMS at the board-only poses (or at
  /// board_rms_floor_px, the corners' usual sub-pixel accuracy, where that is larger).
  double max_board_rms_growth = 2.0;
  double board_rms_floor_px = 0.05;
};

struct RefinedPoses {
  std::vector<Mat3> R_camera_board;  // one per view, in order
  std::vector<Vec3> t_camera_board;
  /// Of (rotation vector δ with R_true = exp(δ) R_est in the camera frame, rad; t, m), from the
  /// bundle adjustment's Jacobian at the solution.
  std::vector<Eigen::Matrix<double, 6, 6>> covariance;
  double board_rms_px = 0.0, scene_rms_px = 0.0;  // reprojection RMS after refinement
  std::size_t tracks = 0, observations = 0;       // scene points used
  std::vector<std::string> warnings;
};

/// Where the features pull the board's corners off their fit (max_board_rms_growth), they are
/// dropped with a warning and the poses are the board's alone (docs/reconstruction.md §1).
/// MeasurementError for fewer than 2 views or views of different sizes than the intrinsics.
RefinedPoses refine_camera_poses(const std::vector<PosedView>& views, const camera::CameraIntrinsics& intrinsics,
                                 const PoseRefinementOptions& options, const Progress& progress = {});

struct RegionOptions {
  double voxel_m = 0.01;         // output spacing
  int sor_neighbours = 16;       // statistical outlier removal: k
  double sor_std_ratio = 2.0;    // and the threshold in standard deviations
  double max_depth_m = 60.0;     // ignore points farther from every camera
  std::size_t min_points = 200;  // fewer: MeasurementError (e.g. an ROI on no antenna)
  /// The object is sought among points farther than this from the region's camera (along its
  /// axis): 0 takes the nearest; a previous result's depth_far_m takes the object behind it.
  double beyond_m = 0.0;
  /// Where an object gives too few points, the next one beyond it is tried, up to this many
  /// objects in all (reconstruct_region).
  int max_objects = 3;
  /// Points inside this board-frame box (min, max corner) are not the object: the calibration
  /// board itself when the rectangle overlaps it (nearer, and far better textured, it would
  /// otherwise be taken for the object).
  std::optional<std::pair<Vec3, Vec3>> exclude_board;
  /// The depth range (near, far along the region camera's axis, m) where the caller expects the
  /// object, e.g. from the model's size against the rectangle's: used where the features give no
  /// object's depth (a plain radome has a handful).
  std::optional<std::pair<double, double>> expected_depth_m;
  /// Where no object gives min_points, the nearest object's few points are returned with a
  /// warning instead of an error: a model's outline may still place the antenna.
  bool allow_few_points = false;
  /// Below this region_coverage the object shows little texture (a warning).
  double min_coverage = 0.6;
};

struct RegionReconstruction {
  PointCloud cloud_board;                // board frame, with normals oriented towards the cameras
  std::vector<std::optional<Roi>> rois;  // the region in each view (nullopt: out of view)
  std::size_t views_used = 0;            // views that contributed points
  std::string method;                    // "dense", "dense+features" or "features", for the report
  /// The object's depth range along the region camera's axis (m): its sparse points' cluster.
  double depth_near_m = 0.0, depth_far_m = 0.0;
  /// Fraction of the object's outline in views[roi_view] (cells of ≥ 8 px and ≥ 1.5 voxels inside the convex hull
  /// of the points' projections) that holds points: ~0.9 on a textured or weathered radome, low
  /// on a plain one (only edges and details carry texture; below RegionOptions::min_coverage a
  /// warning).
  double region_coverage = 0.0;
  std::vector<std::string> warnings;
};

/// The points of the object inside `roi` of views[roi_view], with the refined poses of
/// refine_camera_poses (same order as views). MeasurementError when the ROI lies outside the
/// image, the region is seen in fewer than 2 views, or fewer than options.min_points points
/// remain (the message says which, e.g. "no texture or object in the region"). The object is the
/// nearest one in the rectangle; where its surface gives too few points (the roof's edge reaching
/// into the rectangle, or false matches between an antenna's two equal brackets), the object
/// beyond it, and so on up to options.max_objects, with a warning; where none gives enough, the
/// nearest object's few points with a warning (options.allow_few_points) or MeasurementError.
RegionReconstruction reconstruct_region(const std::vector<PosedView>& views, const RefinedPoses& poses,
                                        std::size_t roi_view, const Roi& roi,
                                        const camera::CameraIntrinsics& intrinsics, const RegionOptions& options,
                                        const Progress& progress = {});

}  // namespace antpose::reconstruction
