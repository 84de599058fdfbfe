#include "antpose/registration/long_edge_check.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "antpose/geometry/rotation.hpp"

namespace antpose::registration {

OptionProblems LongEdgeCheckOptions::Check() const {
  OptionProblems p;
  p.require(max_distance > 0, "max_distance", "positive");
  p.require(sigma_floor_rad >= 0, "sigma_floor_rad", "≥ 0");
  p.require(min_views >= 1, "min_views", "at least 1");
  return p;
}

namespace {

// √(δᵀ (Σ_without + Σ_whole + floor² I)⁻¹ δ) (the header's comment).
double distance(const Vec3& turn, const Mat3& without, const Mat3& whole, double floor) {
  const Mat3 covariance = without + whole + floor * floor * Mat3::Identity();
  return std::sqrt(std::max(0.0, turn.dot(covariance.ldlt().solve(turn))));
}

}  // namespace

std::vector<LongEdgeLeftOut> check_long_edges(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                              const std::vector<SilhouetteView>& views,
                                              const camera::CameraIntrinsics& intrinsics,
                                              const SilhouetteOptions& polish, const LongEdgeCheckOptions& options) {
  throw_unless_ok(options.Check(), "LongEdgeCheckOptions");
  std::vector<LongEdgeLeftOut> out;
  if (!options.enabled) return out;
  const auto whole = refine_by_silhouette(mesh_antenna, T_board_antenna, views, intrinsics, polish);
  if (whole.views_used < options.min_views) return out;
  const Mat3 R_whole = whole.T_board_antenna.linear();
  // The four from one start: the photos are prepared once (refine_by_silhouette_runs); which long
  // edge is left out only changes the samples gathered.
  std::vector<SilhouetteOptions> runs(4, polish);
  for (std::size_t edge = 0; edge < runs.size(); ++edge) runs[edge].long_edges[edge] = false;
  const auto without = refine_by_silhouette_runs(mesh_antenna, whole.T_board_antenna, views, intrinsics, runs);
  for (int edge = 0; edge < 4; ++edge) {
    const SilhouetteResult& refined = without[static_cast<std::size_t>(edge)];
    if (refined.views_used < options.min_views) continue;
    LongEdgeLeftOut& e = out.emplace_back();
    e.edge = edge;
    e.T_board_antenna = refined.T_board_antenna;
    const Vec3 turn = log_so3(refined.T_board_antenna.linear() * R_whole.transpose());
    e.turn_rad = turn.norm();
    e.distance = distance(turn, refined.covariance.topLeftCorner<3, 3>(), whole.covariance.topLeftCorner<3, 3>(),
                          options.sigma_floor_rad);
    e.disagrees = e.distance > options.max_distance;
    e.samples = refined.samples;
    e.whole_samples = whole.samples;
  }
  return out;
}

bool leaves_another_pose(const std::vector<LongEdgeLeftOut>& left_out, double min_turn_rad) {
  return std::any_of(left_out.begin(), left_out.end(),
                     [&](const LongEdgeLeftOut& e) { return e.disagrees && e.turn_rad > min_turn_rad; });
}

std::string long_edge_name(int edge) { return std::string(edge & 1 ? "+x" : "-x") + (edge & 2 ? "+y" : "-y"); }

}  // namespace antpose::registration
