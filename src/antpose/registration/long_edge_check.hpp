// The pose against each of the panel's long edges left out in turn.
//
// Near its outline a rounded radome edge is seen at grazing incidence. Where the rounding's shading
// matches the background's brightness over part of it (a white radome before a bright sky, a low
// sun), the edge found there is the shading's, inside the outline by up to the rounding's projected
// radius (a few pixels where the panel is some tens of pixels wide), along the whole long edge.
// The sun makes it much the same in every photo, so it does not average out, and nothing in that
// edge's samples tells a shading edge from an outline: the pose takes it up (a turn about the long
// axis, the rounding profiled with it, shape_fit.hpp), the residuals stay small and the σ, built
// on them, narrow.
// The other edges tell. Refined with one long edge left out (SilhouetteOptions::long_edges), the
// pose agrees with the whole outline's where every edge is an outline; where it does not, that one
// edge decides the pose against all the others, and the pose without it is one the σ must cover.
// Agreement: where every edge is sound, the whole outline's pose is the efficient one and the pose
// without an edge a consistent one, so their difference δ has the covariance Σ_without − Σ_whole
// (Hausman, Econometrica 46(6), 1978). That difference of two estimated covariances is too
// fragile to divide by: the outline's covariance is itself estimated from its residuals, and the
// arms, brackets and clamps a model lacks make sound edges differ by about their own σ. So δ is
// measured against the bound Σ_without + Σ_whole (the two as if independent) and an edge taken for
// a wrong one only where its absence moves the pose well beyond both σ: a sound outline's σ is not
// counted twice, nor is an edge whose absence only leaves the pose loosely held (one long edge left
// in view) taken for a wrong one.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/model/mesh.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct LongEdgeCheckOptions {
  bool enabled = true;
  /// A pose without one long edge whose rotation lies further than this from the whole outline's
  /// (the distance of the file comment, √χ² with three degrees of freedom: 3 is beyond its 97th
  /// percentile) disagrees with it.
  double max_distance = 3.0;
  /// This σ on each axis (rad) is added to the bound: turns of a few hundredths of a degree are no
  /// disagreement whatever σ the outline claims.
  double sigma_floor_rad = deg2rad(0.05);
  std::size_t min_views = 3;  // a pose without the edge refined in fewer photos says nothing
  OptionProblems Check() const;
};

struct LongEdgeLeftOut {
  int edge = 0;                             // long_edge_of's index
  Iso3 T_board_antenna = Iso3::Identity();  // the pose refined without it
  double turn_rad = 0.0;                    // its rotation from the whole outline's pose
  double distance = 0.0;                    // the distance of the file comment
  bool disagrees = false;                   // beyond max_distance
  std::size_t samples = 0;                  // outline samples the pose without it used
  std::size_t whole_samples = 0;            // and the whole outline's pose
};

/// The pose `T_board_antenna` of `mesh_antenna` refined with `polish` (its outline_box_m set), whole
/// and with each long edge left out in turn, the two compared (file comment). Long edges
/// without which fewer than min_views photos hold the outline are not listed. Views and
/// intrinsics as refine_by_silhouette.
std::vector<LongEdgeLeftOut> check_long_edges(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                              const std::vector<SilhouetteView>& views,
                                              const camera::CameraIntrinsics& intrinsics,
                                              const SilhouetteOptions& polish, const LongEdgeCheckOptions& options);

/// Whether a long edge that disagrees turns the pose by more than `min_turn_rad` when left out:
/// the other edges then hold a second pose, as far from the whole outline's as a rival
/// (pose_selection.hpp's rival_min_deg), and the answer is as ambiguous as with a rival.
bool leaves_another_pose(const std::vector<LongEdgeLeftOut>& left_out, double min_turn_rad);

/// "+x+y" and so on: the faces, in the antenna frame, that meet at long edge `edge`.
std::string long_edge_name(int edge);

}  // namespace antpose::registration
