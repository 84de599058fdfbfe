// Internal to reconstruction: sparse features and their geometry with known camera poses.
//
//   detect       SIFT (Lowe, IJCV 2004) in an image area, optionally downscaled, keypoints in
//                full-resolution px and undistorted normalised coordinates;
//   match        Lowe's ratio test, then the epipolar constraint of the known relative pose
//                (symmetric distance to the epipolar lines in undistorted coordinates); or
//                guided: the ratio test among the candidates on the epipolar lines only;
//   tracks       pairwise matches chained by union-find; a track with two features of one view
//                is dropped (an ambiguous chain);
//   triangulate  linear multi-view DLT (Hartley & Zisserman 2nd ed. §12.2) in normalised
//                coordinates, then checks: positive depth, triangulation angle, reprojection.
// Frames: board frame (m); poses p_camera = R p_board + t.
#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"

namespace antpose::reconstruction::detail {

struct ViewFeatures {
  std::vector<Vec2> px;  // full-resolution distorted pixels
  std::vector<Vec2> xy;  // undistorted normalised coordinates (x/z, y/z)
  cv::Mat descriptors;   // CV_32F, one row per feature
  double scale = 1.0;    // the detection ran on the image resized by this factor
};

/// SIFT features in `area` of `image` (CV_8UC1), where `mask` (same size, may be empty) is
/// non-zero. The area is resized so that its longer side is at most `max_side` px, or enlarged
/// up to `max_upscale` times towards it (SIFT finds more stable features on a small crop seen
/// larger, Lowe 2004 §3.3). `contrast_threshold` is SIFT's (0.04 by default; lower finds the
/// weak texture of a weathered radome).
ViewFeatures detect_features(const cv::Mat& image, const cv::Mat& mask, const cv::Rect& area, int max_features,
                             int max_side, const camera::CameraIntrinsics& intrinsics, double max_upscale = 1.0,
                             double contrast_threshold = 0.04);

/// Index pairs (feature in a, feature in b) passing Lowe's ratio test, by exhaustive search: FLANN's
/// randomised k-d trees drew from a shared generator in parallel and gave other matches each run.
std::vector<std::pair<int, int>> ratio_matches(const ViewFeatures& a, const ViewFeatures& b, double ratio);

/// The candidates within `max_epipolar_px` of the epipolar lines of p_b = R_b_a p_a + t_b_a, a
/// feature of b claimed by two features of a dropped.
std::vector<std::pair<int, int>> epipolar_filter(const ViewFeatures& a, const ViewFeatures& b,
                                                 const std::vector<std::pair<int, int>>& candidates, const Mat3& R_b_a,
                                                 const Vec3& t_b_a, double max_epipolar_px, double focal_px);

/// Guided matching with a known relative pose p_b = R_b_a p_a + t_b_a (Hartley & Zisserman 2nd
/// ed. §11.6, algorithm 11.4 step v): a feature's candidates are only the features of b within
/// `max_epipolar_px` (converted with the focal length) of its epipolar lines, and Lowe's ratio
/// test compares its two nearest descriptors among those, so that a weak feature of a plain
/// radome is not outvoted by look-alikes elsewhere in the image (the board's corners, the
/// ground). A match must be mutual (each the other's nearest candidate); a lone candidate passes
/// the ratio test but must lie within `max_descriptor_angle_rad` of the feature (angle between
/// descriptors).
std::vector<std::pair<int, int>> guided_matches(const ViewFeatures& a, const ViewFeatures& b, const Mat3& R_b_a,
                                                const Vec3& t_b_a, double ratio, double max_epipolar_px,
                                                double focal_px, double max_descriptor_angle_rad = 0.7);

/// One observation: (view, feature index).
using Observation = std::pair<int, int>;

struct PairMatches {
  int view_a = 0, view_b = 0;
  std::vector<std::pair<int, int>> matches;  // (feature in view_a, feature in view_b)
};

/// Union-find chaining of pairwise matches into tracks of ≥ 2 views, one feature per view.
std::vector<std::vector<Observation>> build_tracks(const std::vector<std::size_t>& features_per_view,
                                                   const std::vector<PairMatches>& pairs);

struct TriangulationChecks {
  double min_angle_rad = 0.0175;  // largest angle between two rays of the track
  double max_reprojection_px = 3.0;
  double max_depth_m = 1e9;
};

/// Board-frame point of a track, or nullopt when it fails the checks. Observations with a
/// reprojection error beyond the limit are removed from `track` and the point is re-solved.
std::optional<Vec3> triangulate_track(std::vector<Observation>& track, const std::vector<ViewFeatures>& features,
                                      const std::vector<Mat3>& R_camera_board, const std::vector<Vec3>& t_camera_board,
                                      const camera::CameraIntrinsics& intrinsics, const TriangulationChecks& checks);

/// Convex hull of `points` px, as a CV_8UC1 mask of `size` with the hull (grown by `grow_px`)
/// set to 0 and everything else 255.
cv::Mat mask_outside_hull(const cv::Size& size, const std::vector<Vec2>& points, double grow_px);

/// A region's depth range along a camera's axis (depths z = (R p + t).z, m).
struct DepthRange {
  double near = 0, far = 0;
  std::size_t support = 0;           // points in the window
  Vec3 centre_board = Vec3::Zero();  // their mean
};

/// Any window of this many points is an object, however full the fullest window is.
inline constexpr std::size_t kObjectSupport = 20;

/// The nearest window of depths (max(1.5 m, 10 % of the depth) wide) holding at least
/// `min_support` points and a fifth of the fullest window's or kObjectSupport, shifted within
/// its width to the position that holds most points, widened by 0.15 m + 3 %. When no window
/// qualifies, only `support` is set: the fullest window's count. nullopt for no points.
std::optional<DepthRange> nearest_depth_cluster(const std::vector<Vec3>& points_board, const Mat3& R, const Vec3& t,
                                                std::size_t min_support);

}  // namespace antpose::reconstruction::detail
