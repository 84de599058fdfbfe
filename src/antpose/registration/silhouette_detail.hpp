// The outline's samples for the silhouette refinement (silhouette.hpp; not part of the public
// API): the model welded into edges, the photos prepared as gradient pyramids around it, and per
// photo the outer contour's samples with their edge measurements.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/registration/silhouette.hpp"

namespace antpose::registration::detail {

// The mesh welded by position (files and parametric panels may repeat vertices along creases),
// with each edge's two triangles: contour generators are edges whose triangles face opposite ways.
struct EdgeMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Vec3> normals;  // by winding, not normalised
  struct Edge {
    std::uint32_t a, b;
    std::vector<std::uint32_t> faces;
  };
  std::vector<Edge> edges;
  bool closed = false;  // every edge between two triangles or more: the mesh bounds a solid
  /// The triangles as convex planar polygons (coplanar neighbours merged), which cover the
  /// projection with few fills; every triangle lies in one.
  struct Facet {
    std::vector<std::uint32_t> loop;  // boundary vertices, wound as its triangles
    std::uint32_t triangle = 0;       // one of them (all face the same way)
  };
  std::vector<Facet> facets;
};

EdgeMesh weld(const model::Mesh& mesh);

struct Pose {
  Mat3 R = Mat3::Identity();  // R_board_antenna
  Vec3 t = Vec3::Zero();      // p_board_antenna
  Iso3 T() const {
    Iso3 T_board_antenna = Iso3::Identity();
    T_board_antenna.linear() = R;
    T_board_antenna.translation() = t;
    return T_board_antenna;
  }
};

// One photo cropped around the antenna: gradient images of a Gaussian pyramid.
struct PreparedView {
  bool usable = false;
  Mat3 R_cb = Mat3::Identity();
  Vec3 t_cb = Vec3::Zero();
  Vec2 offset = Vec2::Zero();  // crop origin, full-resolution px
  cv::Size size;
  std::vector<cv::Mat> gx, gy;  // CV_32F per level, 0 where masked
  // Per level (empty without occluders or background edges): 255 where the antenna's outline
  // cannot be seen — on a nearer object, on a known object's edge, or within the edge's blur.
  std::vector<cv::Mat> mask;
};

struct Sample {
  Vec2 normal;                    // outward, image
  double r = 0;                   // measured edge − projection along the normal, full-resolution px
  Eigen::Matrix<double, 1, 6> J;  // d(projection · normal)/d(δ, δt)
  std::uint32_t edge = 0;         // the mesh edge it lies on (correlated errors, see covariance)
  double px_per_m = 0;            // f / depth: image size of a model shape error
  bool on_long_edge = false;      // on one of the model's long edges: the outline's width
};

// Outline points of one view, counted: those on the model's box (candidates, of which some fall
// outside the crop) and those on its attachments (options.outline_box_m), whose edge costs (as in
// score()) are summed but which are not samples of the fit.
struct OutlineCounts {
  std::size_t candidates = 0, outside = 0, attachment_candidates = 0;
  double attachment_cost = 0;
  bool reached_middle = false;  // some search line behind the outline reached the projection's middle
  OutlineCounts& operator+=(const OutlineCounts& c) {
    candidates += c.candidates, outside += c.outside, attachment_candidates += c.attachment_candidates;
    attachment_cost += c.attachment_cost;
    reached_middle = reached_middle || c.reached_middle;
    return *this;
  }
};

// A sample's cost in score(): its squared distance truncated at score_cutoff_px, 1 without an edge.
double edge_cost(std::optional<double> r_px, const SilhouetteOptions& o);

// What a gathering measures besides each sample's edge: its Jacobian (for the normal equations
// and the covariance; a score needs only the edges) and the attachments' outline.
struct GatherWhat {
  bool jacobians = true;
  bool attachments = false;
};

// Every photo's outer-contour samples at `level` with their edges found within ±`search_px`, and
// the outline points counted; the attachments' outline measured only `what.attachments`. Without
// `what.jacobians` the samples' J is left zero.
struct Gathered {
  std::vector<std::vector<Sample>> per_view;
  std::vector<OutlineCounts> per_view_counts;
  OutlineCounts counts;
  std::size_t views_with_samples = 0;
};

Gathered gather_all(const EdgeMesh& m, const Pose& pose, const std::vector<PreparedView>& views,
                    const camera::CameraIntrinsics& K, int level, double search_px, const SilhouetteOptions& o,
                    GatherWhat what = {});

// The photos prepared for the outline of the model at `poses` (one or more close together): each
// cropped (its ROI, or the union of the model's projected boxes plus a margin), as gradient
// pyramids in linear intensity (edges are located there: in encoded values the outline's width,
// and so the yaw, would be biased), masked where known objects are. `top`: the coarsest level,
// where the narrowest side of that union is still min_coarse_width_px wide (at most `max_level`).
struct PreparedViews {
  std::vector<PreparedView> views;
  int top = 0;
};

PreparedViews prepare_views(const EdgeMesh& m, const std::vector<Pose>& poses, const std::vector<SilhouetteView>& views,
                            const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options, int max_level,
                            std::vector<std::string>& warnings);

}  // namespace antpose::registration::detail
