// The model's unknown shape fitted with its pose: a datasheet box (width × depth × height) says
// nothing of how round the radome's vertical edges are, and they matter. A rounded box of corner
// radius r seen at θ from face-on has the outline width (W − 2r)|cos θ| + (D − 2r)|sin θ| + 2r, so
// the outline's edges move by up to 2r(√2 − 1), about 0.8 r, against the sharp box's; fitted with
// the wrong radius, the yaw that makes up for it is off by degrees (a 0.21 m deep panel of 45 mm
// radius fitted as 20 mm: 3–6°). So the edge radius is profiled: the pose refined by its outline
// at full resolution (silhouette.hpp) with the panel's model at each radius of a grid from sharp to
// half its depth, the best-fitting radius kept, and the poses of every radius the photos do not
// rule out (pose_evidence.hpp's paired test) added to the covariance — the radius is a nuisance
// parameter whose uncertainty the attitude must carry (a profile likelihood).
#pragma once

#include <cstddef>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/registration/pose_evidence.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct EdgeRadiusOptions {
  bool enabled = true;
  std::size_t steps = 6;    // radii from 0 to the largest, evenly
  double largest_m = 0.06;  // and at most half the panel's smaller side less 5 mm
  OptionProblems Check() const;
};

struct EdgeRadiusFit {
  bool fitted = false;  // false: not a parametric panel, or no radius refined to a usable outline
  double radius_m = 0.0;
  model::AntennaModel model;            // the panel at that radius
  SilhouetteResult outline;             // its refinement
  std::vector<double> radii_m, scores;  // the profile
  std::vector<double> within_m;         // the radii the photos do not rule out
  Mat3 spread_board = Mat3::Zero();     // rad², the rotations of those radii about the best's
};

/// Profiles the edge radius of `model` (a parametric panel; else nothing fitted) at the box pose
/// `T_board_antenna`, each radius refined with `polish` (its outline_box_m set to the model's box),
/// the radii ruled out by `evidence`'s paired test. views, intrinsics as refine_by_silhouette.
EdgeRadiusFit fit_edge_radius(const model::AntennaModel& model, const Iso3& T_board_antenna,
                              const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                              const SilhouetteOptions& polish, const EvidenceOptions& evidence,
                              const EdgeRadiusOptions& options);

}  // namespace antpose::registration
