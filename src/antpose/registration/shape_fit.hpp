// The model's unknown shape fitted with its pose. A datasheet box (width × depth × height) says
// nothing of how round the radome's vertical edges are, nor of the end caps moulded onto its ends,
// and both matter:
//  - A rounded box of corner radius r seen at θ from face-on has the outline width
//    (W − 2r)|cos θ| + (D − 2r)|sin θ| + 2r, so the outline's edges move by up to 2r(√2 − 1),
//    about 0.8 r, against the sharp box's; fitted with the wrong radius, the yaw that makes up for
//    it is off by degrees (a 0.21 m deep panel of 45 mm radius fitted as 20 mm: 3–6°).
//  - End caps standing a few millimetres out of the radome all round carry the whole outline of
//    each end. Seen from below, a panel's downtilt is read from where its ends lie across the line
//    of sight (its foreshortened length), and a rim of t shifts the end's outline by about
//    t · sin(elevation): on a 0.7 m panel an 8 mm rim reads as a degree of downtilt.
// The two trade against each other (caps widen the ends' outline as rounder edges narrow it), so
// the shape is profiled over both at once: the pose refined by its outline at full resolution
// (silhouette.hpp) with the panel's model at each cell of a grid of radii (sharp to half its depth)
// and rims (none to largest_rim_m), then at the vertex of the profile's parabolas through the best
// cell; the best shape is kept. The poses of the other shapes, each weighted by its likelihood
// relative to the best's (pose_evidence.hpp's paired test), are added to the covariance: the shape
// is a nuisance whose uncertainty the attitude must carry.
//
// Where the best radius is the largest tried, the profile is not bracketed: the photos' edges lie
// further inside the box than the outline of any rounding, which the radome's shape cannot do.
// A rounded radome shows it where its outline has little contrast (a pale radome before a bright
// sky): the edge seen is its shading's, where the surface turns from the light, some way in from
// its outline and alike in every photo. The paired test's noise, the photos' scatter about their
// mean, then misses that common error, and the photos count as one unit: the shapes are weighed
// against the scatter itself, and the attitude carries the poses of the shapes it allows.
#pragma once

#include <cstddef>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/registration/pose_evidence.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct ShapeOptions {
  bool enabled = true;
  std::size_t steps = 5;         // radii from 0 to the largest, evenly
  double largest_m = 0.06;       // and at most half the panel's smaller side less 5 mm
  std::size_t rim_steps = 3;     // end caps' rims from 0 to the largest, evenly; 0: no end caps
  double largest_rim_m = 0.009;  // moulded end caps stand up to about a centimetre out of the radome
  double cap_height_m = 0.04;    // their length (at most a quarter of the panel's height)
  OptionProblems Check() const;
};

struct ShapeFit {
  bool fitted = false;                 // false: not a parametric panel, or no shape refined to a usable outline
  bool bracketed = true;               // false: the best radius is the largest tried (the file comment)
  double radius_m = 0.0, rim_m = 0.0;  // the best edge radius and end caps' rim
  model::AntennaModel model;           // the panel of that shape
  SilhouetteResult outline;            // its refinement
  /// The shapes tried (edge radius, rim) and their outline scores: the grid, rim by rim, then the
  /// vertex of its parabolas through the best cell; `within`: those the photos do not rule out.
  std::vector<double> radii_m, rims_m, scores;
  std::vector<std::size_t> within;
  std::vector<double> likelihoods;   // per shape tried, relative to the best's (1): the spread's weights
  Mat3 spread_board = Mat3::Zero();  // rad², the shapes' rotations about the best's, likelihood-weighted
};

/// Profiles the edge radius and end caps' rim of `model` (a parametric panel; else nothing fitted)
/// at the box pose `T_board_antenna`, each shape refined with `polish` (its outline_box_m set to
/// that shape's model::outline_box), the shapes ruled out by `evidence`'s paired test. views,
/// intrinsics as refine_by_silhouette.
ShapeFit fit_shape(const model::AntennaModel& model, const Iso3& T_board_antenna,
                   const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                   const SilhouetteOptions& polish, const EvidenceOptions& evidence, const ShapeOptions& options);

/// The spread of the shapes `fit` allows (its `within`, weighed by their likelihoods), each the panel
/// `model` reshaped and refined with `polish` from `T_board_antenna`, about that pose (rad², board
/// frame): the profile's nuisance carried over to the answer refined otherwise than the profile
/// was (register_antenna.hpp's free_answer_width), `T_board_antenna` being its best shape's pose
/// so refined. Zero where `fit` was not fitted.
Mat3 spread_of_shapes(const ShapeFit& fit, const model::AntennaModel& model, const Iso3& T_board_antenna,
                      const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                      const SilhouetteOptions& polish, const ShapeOptions& options);

}  // namespace antpose::registration
