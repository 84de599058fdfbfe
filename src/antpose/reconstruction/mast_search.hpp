// A mast found by its outline alone: the vertical pole (or pipe) a panel hangs on, where the
// region's points cannot give it (a plain steel pole has no texture for stereo). A vertical
// cylinder's outline in a photo is the pair of lines where the lines of sight graze it; for
// every cylinder of a grid of axes around the panel (outside its box) and radii, those lines are
// scored by chamfer matching (registration/edge_distance.hpp) over stretches below and above the
// panel, where a mast stands clear of it, with the panel and other known objects masked; the
// best-scoring cylinders are refined and confirmed by their outline in the photos as the points'
// masts are (mast.hpp confirm_mast). The first one confirmed is the mast.
#pragma once

#include <optional>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/registration/edge_distance.hpp"

namespace antpose::reconstruction {

struct MastSearchOptions {
  double reach_m = 1.2;  // axes within this horizontal distance of the panel's centre
  double step_m = 0.06;  // of the grid of axes
  /// Spaced by at most twice the chamfer's truncation at the panel (truncation_px over the map's
  /// scale: 0.03 m), so that every pole's outline lies within reach of some grid radius.
  std::vector<double> radii_m{0.03, 0.05, 0.07, 0.09, 0.12, 0.15, 0.19, 0.23, 0.28, 0.33, 0.39, 0.45};
  double below_m = 1.5;            // the stretch below the panel's bottom searched
  double above_m = 0.5;            // and above its top
  double gap_m = 0.05;             // clear of the panel's ends
  double hand_height_m = 1.2;      // the stretch ends this far below the lowest photo (the ground)
  double min_diameter_map_px = 3;  // the maps' scale: the thinnest mast this wide at the panel
  double truncation_px = 1.5;      // map px
  std::size_t min_views = 3;
  std::size_t confirm = 4;       // the best cylinders handed to confirm_mast, or refined on each side
  int refine_evaluations = 400;  // of a cylinder's cost, at most, in its refinement
  registration::EdgeDistanceOptions edges;
  /// confirm_mast's. Over the stretch beside the panel too, crossed by arms, clamps and frames,
  /// and against backgrounds of every brightness, a pole's outline meets fewer edges than below it
  /// alone: shares of 0.45–0.7 on simulated masts and pipes, in every photo, at 0.4–0.5 px RMS.
  MastOptions confirmation = [] {
    MastOptions o;
    o.min_edge_fraction = 0.4;
    return o;
  }();
  OptionProblems Check() const;
};

/// The mast beside a panel at `T_board_panel` (box `panel_size_m`, board frame) whose outline the
/// photos show, `occluders[i]` (image polygons, px) masked in photo i — the panel itself and other
/// known objects; nullopt where none is confirmed.
std::optional<Mast> find_mast_by_outline(const std::vector<PosedView>& views,
                                         const camera::CameraIntrinsics& intrinsics, const Vec3& up_board,
                                         const Iso3& T_board_panel, const Vec3& panel_size_m,
                                         const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                                         const MastSearchOptions& options);

/// The vertical structure on each side of a panel: of the grid's cylinders (file comment, scored
/// beside the panel too, the panel masked: a mount's pipe may be shorter than the panel it holds,
/// and is then seen only beside it, from oblique views), each side's best few places refined off
/// the grid by a pattern search, the one whose outline fits best behind the panel's back plate
/// (against its boresight y_a at `T_board_panel`) and the one before its front, each with its cost
/// photo by photo (NaN where a photo shows too little of it).
/// A panel hangs on a mast, pipe or frame behind it and faces open space: the side whose best
/// cylinder the photos support better is its back (registration's front and back,
/// pose_evidence.hpp).
struct MountCylinder {
  Mast cylinder;
  double cost = 1.0;
  std::vector<double> view_costs;
};
struct MountSides {
  std::optional<MountCylinder> behind, before;
};
MountSides search_mount_sides(const std::vector<PosedView>& views, const camera::CameraIntrinsics& intrinsics,
                              const Vec3& up_board, const Iso3& T_board_panel, const Vec3& panel_size_m,
                              const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                              const MastSearchOptions& options);

}  // namespace antpose::reconstruction
