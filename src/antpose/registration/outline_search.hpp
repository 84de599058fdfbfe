// A global search for an antenna's box by its outline in every photo: the registration's
// strategy that needs neither texture nor a good start.
//
// A box is convex, so its outline in a photo is the convex hull of its eight projected corners;
// a pose is scored by chamfer matching (edge_distance.hpp): the hull's edges are sampled about one
// map pixel apart and each sample's distance to the nearest edge running its way, truncated at
// `truncation_px`, costs min(d, τ)²/τ². A photo's cost is the mean over its samples that are
// measured (not on a known nearer object), samples outside the mapped region costing 1; the pose's
// cost is the mean over the photos where enough of the outline is measured.
//
// Orientations are those a panel can hang in (docs/non-contact.md, *Physical priors*): the
// long axis tilted from the vertical by a downtilt in `tilt_deg` and a roll in `roll_deg`, turned
// about the vertical by every `yaw_step_deg` over 180° (a box turned by 180° about its long axis
// has the same outline: front and back are decided later, by what differs). For each
// orientation the box's centre is searched from each start position (and from the best depth at
// which the box fills the rectangle as a user may draw it) by a compass search (Kolda, Lewis &
// Torczon, SIAM Review 45(3), 2003) along the region photo's image axes and its line of sight,
// among the poses that fit the user's rectangle (their box fills it and is centred in it: it was
// drawn around this antenna, not its neighbour). The best poses, each at least `separation_deg`
// in orientation or a box width in position from every better one, are then polished by the same
// compass search over all six degrees of freedom (turns about the box's own axes), so that the
// refinement by the outline's edges (silhouette.hpp) starts within its narrow basin.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"
#include "antpose/core/check.hpp"
#include "antpose/registration/edge_distance.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct OutlineSearchOptions {
  double map_width_px = 24;  // the box's expected width in the maps: the resize of each photo's region
  double yaw_step_deg = 5;
  std::vector<double> tilt_deg{-9, -3, 3, 9, 15};  // about the box's x axis (a downtilt's)
  std::vector<double> roll_deg{-3, 0, 3};          // about its boresight
  double truncation_px = 2.0;                      // map px
  double min_measured_share = 0.3;                 // of a photo's outline samples; fewer: the photo does not count
  std::size_t min_views = 2;
  double separation_deg = 8;  // between the orientations of two results (modulo the 180° turn)
  std::size_t max_candidates = 8;
  std::size_t max_depth_starts = 24;  // depths tried along the rectangle's centre ray, per orientation
  double min_step_map_px = 0.5;       // the compass search's last step, as image motion in the maps
  double min_turn_deg = 0.25;         // the last turn of the candidates' polish over all six degrees
  EdgeDistanceOptions edges;
  OptionProblems Check() const;
};

/// What the search needs to know of the antenna and the photos.
struct OutlineSearchInput {
  Vec3 box_size_m = Vec3::Zero();                      // width (x_a), depth (y_a), height (z_a)
  const std::vector<SilhouetteView>* views = nullptr;  // photos, poses, known occluders
  std::vector<std::optional<cv::Rect>> areas;          // per view: where the antenna may be (px); none: unused
  std::size_t region_view = 0;   // the photo the rectangle was drawn in: its axes orient the position search
  double expected_width_px = 0;  // the box's width in that photo at full resolution (sets the maps' scale)
  Vec3 up_board = Vec3::UnitZ();
  std::vector<Vec3> starts_board;  // box centres to search from (board frame)
  /// The user's rectangle in the region view: a pose whose projected box spans less than
  /// `min_roi_span` of its larger side, or whose centre lies outside it, is not this antenna
  /// (cost 1; rectangle_fit).
  std::optional<cv::Rect> roi;
  double min_roi_span = 0.55;
};

/// How a box's projection (its corners' bounding box, px) stands in the user's rectangle: the
/// share of the rectangle's larger side that it spans inside the rectangle, and whether its centre
/// lies in it. The larger side, not the area: a user's margin goes with the antenna's length, so a
/// thin panel drawn with a loose rectangle fills little of its area (60 px wide and 450 px long,
/// with margins of 15 % of the length: 27 %) but most of its length.
struct RectangleFit {
  double span = 0.0;
  bool centred = false;
};
RectangleFit rectangle_fit(const Eigen::AlignedBox2d& projected_px, const cv::Rect& roi);

/// rectangle_fit of the box of `size_m` (width, depth, height) at `T_board_antenna`, projected into
/// `view`; {0, false} where a corner is behind the camera.
RectangleFit roi_span(const Vec3& size_m, const Iso3& T_board_antenna, const SilhouetteView& view,
                      const camera::CameraIntrinsics& intrinsics, const cv::Rect& roi);

struct OutlineCandidate {
  Iso3 T_board_antenna = Iso3::Identity();  // the box's pose (which way round is not decided)
  double cost = 1.0;                        // 0 (every sample on an edge) .. 1
  std::size_t views = 0;                    // photos that counted
};

struct OutlineSearchResult {
  std::vector<OutlineCandidate> candidates;  // best first
  std::size_t evaluations = 0;
};

/// std::invalid_argument for a non-positive box, no views, or a region view out of range.
OutlineSearchResult search_box_outline(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                                       const OutlineSearchOptions& options);

/// Each start's centre searched at the start's own orientation, from the start's centre, by the
/// search's compass search, then polished over all six degrees of freedom like the search's
/// candidates: the outline's own placement of poses another strategy proposes by their
/// orientation (their centres may belong to another orientation's basin). Best first.
OutlineSearchResult place_box_outlines(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                                       const OutlineSearchOptions& options, const std::vector<Iso3>& starts);

/// The chamfer cost of one box pose against prepared maps (for tests and reports): as the search
/// scores it.
class BoxOutlineCost {
 public:
  BoxOutlineCost(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                 const OutlineSearchOptions& options);
  /// The cost (0..1) and the number of photos that counted; 1 and 0 where fewer than min_views did.
  std::pair<double, std::size_t> operator()(const Iso3& T_board_antenna) const;
  const std::vector<EdgeDistance>& maps() const { return maps_; }
  double map_scale() const { return scale_; }  // map px per photo px

 private:
  double view_cost(std::size_t v, const std::array<Vec3, 8>& corners_board, bool& counted) const;
  bool fits_rectangle(const Iso3& T_board_antenna) const;
  const OutlineSearchInput& input_;
  const camera::CameraIntrinsics& intrinsics_;
  const OutlineSearchOptions& options_;
  std::vector<EdgeDistance> maps_;
  double scale_ = 1.0;
};

}  // namespace antpose::registration
