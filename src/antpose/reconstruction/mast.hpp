// The mast an antenna hangs on, as a vertical cylinder in the board frame.
//
// From the ground a panel is seen against its mast or behind it: the mast's edges run beside the
// panel's outline, and a mast in front hides part of it. Both mislead the outline's edge search
// (registration/silhouette.hpp), which then needs to know where the mast is.
//
// Two stages:
//  1. the region's 3-D points that the antenna does not explain (the caller's selection) are
//     projected along the vertical, and a circle is fitted by RANSAC (Fischler & Bolles 1981;
//     three points, radius within limits) and refitted to its inliers by linear least squares
//     (Kåsa 1976). From 20–30 m the points scatter by centimetres in depth, so the radius and
//     the axis are only roughly fixed;
//  2. the cylinder is refined by its outline in the photos, over a stretch of the mast the caller
//     names (below the antenna, where the mast stands alone against the sky: beside the panel its
//     edges run next to the panel's and the brackets'). Each photo sees two generator lines,
//     where the line of sight grazes the cylinder; an edge found along such a line's normal
//     (camera/edge_search.hpp) back-projects to a ray tangent to the cylinder, so the ray's
//     distance from the axis equals the radius. The axis (2 parameters) and the radius are fitted
//     to these tangencies with Ceres (Cauchy loss, residuals in pixels), in rounds with a
//     shrinking search range, the first as wide as stage 1's uncertainty. A cylinder that its
//     outline does not confirm (too few views or samples on an edge, either line without its
//     share of them, a large RMS) is not a mast.
// The axis is the board frame's up (the board's attitude from gravity: masts stand within a
// fraction of a degree of vertical).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"
#include "antpose/geometry/point_cloud.hpp"
#include "antpose/reconstruction/reconstruct.hpp"

namespace antpose::reconstruction {

struct Mast {
  Vec3 axis_point_board = Vec3::Zero();  // on the axis (board frame, m)
  Vec3 up_board = Vec3::UnitZ();         // the axis' direction, unit
  double radius_m = 0.0;
  double low_m = 0.0, high_m = 0.0;  // its extent along up_board from axis_point_board
  std::size_t points = 0;            // 3-D points on it (stage 1)
  std::size_t views = 0;             // photos in which its outline was found (stage 2)
  std::size_t edge_samples = 0;      // outline samples on an edge within 2 loss scales
  double edge_rms_px = 0.0;          // of those
};

struct MastOptions {
  double min_radius_m = 0.02, max_radius_m = 0.75;
  double point_tolerance_m = 0.04;  // stage 1 inlier distance from the circle
  std::size_t min_points = 150;
  double min_height_m = 0.3;  // the inliers' extent along the axis
  int ransac_iterations = 500;
  std::uint64_t seed = 1;
  double first_search_m = 0.25;                   // stage 2: ± edge search of the first round, at the mast
  std::vector<double> search_px{12.0, 6.0, 3.0};  // then ± px per round (the first at least this)
  double sample_spacing_px = 6.0;
  double extend_m = 0.3;  // the mast reaches this far beyond the points' extent
  double gamma = 2.2;     // as the silhouette's edge search
  double smoothing_sigma_px = 1.0;
  double min_edge_gradient = 3.0;
  double loss_px = 1.0;  // Cauchy scale
  std::size_t min_views = 3;
  double min_edge_fraction = 0.7;  // of the samples on an edge within 2 loss scales; of each line, half that
  double max_rms_px = 1.5;
};

/// The mast (file comment) from `points_board` (the region's points the antenna does not explain)
/// and its outline in the photos between the heights `outline_low_m` and `outline_high_m` (along
/// up_board, board frame); nullopt when no cylinder fits the points or its outline does not
/// confirm it. The mast returned reaches from the outline's stretch to the points' top.
std::optional<Mast> fit_mast(const PointCloud& points_board, const Vec3& up_board, const std::vector<PosedView>& views,
                             const camera::CameraIntrinsics& intrinsics, double outline_low_m, double outline_high_m,
                             const MastOptions& options);

/// Stage 2 alone from a cylinder found some other way (mast_search.hpp): its outline refined and
/// confirmed in the photos as fit_mast's, between the heights `outline_low_m` and `outline_high_m`
/// (along up_board from the board frame's origin, as fit_mast's), with `occluders[i]` (image polygons, px) masked in photo i — the antenna itself, whose vertical
/// edges would pass for the mast's. nullopt when the outline does not confirm it.
std::optional<Mast> confirm_mast(const Mast& start, const std::vector<PosedView>& views,
                                 const camera::CameraIntrinsics& intrinsics, double outline_low_m,
                                 double outline_high_m,
                                 const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                                 const MastOptions& options);

/// Stage 1 alone: the vertical cylinder that most of `points_board` lie on, over their height
/// range, unconfirmed by the photos (views 0); nullopt where none holds options.min_points over
/// options.min_height_m. From afar its radius is rough (the points scatter in depth).
std::optional<Mast> mast_from_points(const PointCloud& points_board, const Vec3& up_board, const MastOptions& options);

/// The mast's two outline lines in a photo (px, as taken), each a polyline from its low end to
/// its high end in `segments` pieces; both empty when the camera is inside the cylinder or a
/// point lies behind it.
std::array<std::vector<cv::Point2f>, 2> mast_outline(const Mast& mast, const camera::CameraIntrinsics& intrinsics,
                                                     const Mat3& R_camera_board, const Vec3& t_camera_board,
                                                     int segments = 16);

/// The distance of `p_board` from the mast's axis, across it (m).
double distance_from_axis(const Mast& mast, const Vec3& p_board);

/// Whether `b` is the mast `a` found again: their axes within `tolerance_m` of each other at
/// `p_board`'s height and over a metre along them, their radii and both ends within `tolerance_m`.
bool same_mast(const Mast& a, const Mast& b, const Vec3& p_board, double tolerance_m);

/// The horizontal distance of `p_board` from the mast's surface (m, ≥ 0; inside it too).
double distance_from_surface(const Mast& mast, const Vec3& p_board);

/// Whether `p_board` lies on the mast or inside it: within `clearance_m` of its surface
/// (horizontally) and of its extent along the axis.
bool on_mast(const Mast& mast, const Vec3& p_board, double clearance_m);

/// Whether the mast's axis lies nearer to the camera than `p_board` (horizontal distances): what
/// lies behind it there is hidden by it.
bool mast_in_front(const Mast& mast, const Vec3& camera_centre_board, const Vec3& p_board);

}  // namespace antpose::reconstruction
