// A strategy from the candidates themselves: the best ones slid along their long axis to where
// their outline scores best.
//
// The outline's descent (silhouette.hpp) follows the edges its samples find; a sample that finds
// none pulls nowhere. Along a panel's long axis z_a only its two ends' edges hold it, and on a
// plain radome seen from below, or an end cap as pale as the sky behind it, those are few and
// faint: from a start some centimetres off, the long edges fit, the ends' samples find nothing
// or clutter, and the descent stops there. The outline's score does see it (a sample without an
// edge costs as much as one far from its edge): at one end the outline overhangs the panel, at
// the other it falls short. So the pose is moved along z_a in steps over a reach, the outline
// scored at each without a descent (evaluate_outlines), and the best offset, where it scores
// better than the pose itself by min_gain, is a start that register_antenna refines and judges
// like any other proposal.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct AxisSlideOptions {
  std::size_t of_best = 6;  // the best candidates (by their outline) slid; 0: none
  double reach_m = 0.15;    // either way along z_a
  double step_m = 0.025;
  double min_gain = 0.01;  // in the outline's score (0 .. 1)
  OptionProblems Check() const;
};

/// `T_board_antenna` moved along its own z axis to the offset (a multiple of step_m within
/// ±reach_m) where the outline of `mesh_antenna` scores best (evaluate_outlines with `outline`),
/// or nullopt where none scores better than no offset by min_gain.
std::optional<Iso3> slide_along_axis(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                     const std::vector<SilhouetteView>& views,
                                     const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& outline,
                                     const AxisSlideOptions& options);

}  // namespace antpose::registration
