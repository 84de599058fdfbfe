#include "antpose/registration/axis_slide.hpp"

#include <cmath>

namespace antpose::registration {

OptionProblems AxisSlideOptions::Check() const {
  OptionProblems p;
  p.require(step_m > 0 && reach_m >= step_m, "step_m, reach_m", "0 < step_m ≤ reach_m");
  p.require(min_gain >= 0, "min_gain", "≥ 0");
  return p;
}

std::optional<Iso3> slide_along_axis(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                     const std::vector<SilhouetteView>& views,
                                     const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& outline,
                                     const AxisSlideOptions& o) {
  throw_unless_ok(o.Check(), "AxisSlideOptions");
  const Vec3 axis = T_board_antenna.linear().col(2);
  const auto steps = static_cast<int>(std::floor(o.reach_m / o.step_m + 1e-9));
  std::vector<Iso3> poses{T_board_antenna};  // no offset first
  for (int k = -steps; k <= steps; ++k) {
    if (k == 0) continue;
    Iso3 T = T_board_antenna;
    T.translation() += k * o.step_m * axis;
    poses.push_back(T);
  }
  const auto scores = evaluate_outlines(mesh_antenna, poses, views, intrinsics, outline);
  std::size_t best = 0;
  for (std::size_t i = 1; i < scores.size(); ++i)
    if (scores[i].score < scores[best].score) best = i;
  if (best == 0 || scores[best].score > scores[0].score - o.min_gain) return std::nullopt;
  return poses[best];
}

}  // namespace antpose::registration
