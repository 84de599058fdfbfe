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

std::vector<LongEdgeLeftOut> check_long_edges(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                              const std::vector<SilhouetteView>& views,
                                              const camera::CameraIntrinsics& intrinsics,
                                              const SilhouetteOptions& polish, const Mat3& rotation_covariance_board,
                                              const LongEdgeCheckOptions& options) {
  throw_unless_ok(options.Check(), "LongEdgeCheckOptions");
  std::vector<LongEdgeLeftOut> out;
  if (!options.enabled) return out;
  const Mat3 covariance =
      rotation_covariance_board + options.sigma_floor_rad * options.sigma_floor_rad * Mat3::Identity();
  const Eigen::LDLT<Mat3> inverse(covariance);
  for (int edge = 0; edge < 4; ++edge) {
    auto without = polish;
    without.long_edges[static_cast<std::size_t>(edge)] = false;
    const auto refined = refine_by_silhouette(mesh_antenna, T_board_antenna, views, intrinsics, without);
    if (refined.views_used < options.min_views) continue;
    LongEdgeLeftOut& e = out.emplace_back();
    e.edge = edge;
    e.T_board_antenna = refined.T_board_antenna;
    const Vec3 turn = log_so3(refined.T_board_antenna.linear() * T_board_antenna.linear().transpose());
    e.turn_rad = turn.norm();
    e.distance = std::sqrt(std::max(0.0, turn.dot(inverse.solve(turn))));
    e.disagrees = e.distance > options.max_distance;
  }
  return out;
}

std::string long_edge_name(int edge) { return std::string(edge & 1 ? "+x" : "-x") + (edge & 2 ? "+y" : "-y"); }

}  // namespace antpose::registration
