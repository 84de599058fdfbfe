#include "antpose/registration/global_start.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include <Eigen/Eigenvalues>
#include <tbb/parallel_for.h>

namespace antpose::registration {
namespace {

/// A rotation taking e_z to `up`.
Mat3 rotation_to_up(const Vec3& up) {
  const Vec3 z = Vec3::UnitZ();
  const Vec3 axis = z.cross(up);
  const double s = axis.norm(), c = z.dot(up);
  if (s < 1e-12) return c > 0 ? Mat3::Identity() : Mat3(Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitX()));
  return exp_so3(axis / s * std::atan2(s, c));
}

/// Where the model's centre starts (see the header): the centroid, and the centroids of the two
/// halves split at it across the direction of the points' largest horizontal spread.
std::vector<Vec3> start_centres(const std::vector<Vec3>& points, const Vec3& up, bool split) {
  const Vec3 c = centroid(points);
  if (!split) return {c};
  Mat3 spread = Mat3::Zero();
  for (const auto& p : points) {
    const Vec3 d = (p - c) - (p - c).dot(up) * up;
    spread += d * d.transpose();
  }
  const Vec3 across = Eigen::SelfAdjointEigenSolver<Mat3>(spread).eigenvectors().col(2);
  std::vector<Vec3> halves{Vec3::Zero(), Vec3::Zero()};
  std::size_t positive = 0;
  for (const auto& p : points) {
    const bool side = (p - c).dot(across) > 0.0;
    halves[side] += p;
    positive += side;
  }
  std::vector<Vec3> centres{c};
  if (positive > 0 && positive < points.size()) {
    centres.push_back(halves[1] / static_cast<double>(positive));
    centres.push_back(halves[0] / static_cast<double>(points.size() - positive));
  }
  return centres;
}

/// Which points a camera at `viewpoint` sees: those facing it that are nearest in their viewing
/// direction (a z-buffer of splatted points: bins of `bin_m` at the cloud's distance, a point
/// hidden when another in its bin is more than `depth_tolerance_m` nearer).
std::vector<bool> visible_from(const std::vector<Vec3>& points, const std::vector<Vec3>& normals, const Vec3& viewpoint,
                               double bin_m, double depth_tolerance_m) {
  const std::size_t n = points.size();
  std::vector<bool> visible(n, false);
  const Vec3 to_cloud = centroid(points) - viewpoint;
  const Vec3 axis = to_cloud.normalized();
  const Vec3 u = axis.unitOrthogonal(), v = axis.cross(u);
  const double bin_rad = bin_m / std::max(to_cloud.norm(), 1e-6);
  std::map<std::pair<long, long>, double> nearest;
  std::vector<std::pair<long, long>> key(n);
  std::vector<double> range(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 d = points[i] - viewpoint;
    range[i] = d.norm();
    if (normals[i].dot(-d) <= 0.0 || d.dot(axis) <= 0.0) continue;  // facing away, or behind the camera
    key[i] = {std::lround(d.dot(u) / d.dot(axis) / bin_rad), std::lround(d.dot(v) / d.dot(axis) / bin_rad)};
    auto [it, fresh] = nearest.emplace(key[i], range[i]);
    if (!fresh) it->second = std::min(it->second, range[i]);
    visible[i] = true;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (visible[i]) visible[i] = range[i] <= nearest[key[i]] + depth_tolerance_m;
  return visible;
}

/// The two score parts of a pose (see the header).
std::pair<double, double> score(const PreparedCloud& scene, const PreparedCloud& model, const Iso3& T_model_scene,
                                const GlobalStartOptions& o) {
  const double tau2 = o.truncation_m * o.truncation_m;
  double residual = 0.0;
  for (const auto& p : scene.cloud.points) {
    std::size_t j;
    double d2;
    residual += model.tree.nearest(T_model_scene * p, j, d2, tau2) ? d2 / tau2 : 1.0;
  }
  residual /= static_cast<double>(scene.cloud.size());
  if (o.viewpoints_scene.empty()) return {residual, 0.0};
  // The model in the scene frame, and which of its samples some camera would have seen.
  const Iso3 T_scene_model = T_model_scene.inverse();
  const PointCloud m = transformed(model.cloud, T_scene_model);
  std::vector<bool> seen(m.size(), false);
  for (const auto& viewpoint : o.viewpoints_scene) {
    const auto v = visible_from(m.points, m.normals, viewpoint, 2.0 * o.truncation_m, 2.0 * o.truncation_m);
    for (std::size_t i = 0; i < m.size(); ++i) seen[i] = seen[i] || v[i];
  }
  std::size_t facing = 0, missing = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (!seen[i]) continue;
    ++facing;
    std::size_t j;
    double d2;
    if (!scene.tree.nearest(m.points[i], j, d2, tau2)) ++missing;
  }
  return {residual, facing ? static_cast<double>(missing) / static_cast<double>(facing) : 0.0};
}

/// At most `max_points` of the cloud, every n-th (the voxel cloud is in spatial order).
PointCloud every_nth(const PointCloud& cloud, std::size_t max_points) {
  if (cloud.size() <= max_points) return cloud;
  const std::size_t step = (cloud.size() + max_points - 1) / max_points;
  PointCloud out;
  for (std::size_t i = 0; i < cloud.size(); i += step) {
    out.points.push_back(cloud.points[i]);
    if (cloud.has_normals()) out.normals.push_back(cloud.normals[i]);
  }
  return out;
}

}  // namespace

PointCloud voxel_downsample(const PointCloud& cloud, double voxel_m) {
  if (!(voxel_m > 0.0)) throw std::invalid_argument("voxel_downsample: the voxel size must be positive");
  struct Cell {
    Vec3 p = Vec3::Zero(), n = Vec3::Zero();
    int count = 0;
  };
  std::map<std::tuple<long, long, long>, Cell> cells;
  const bool normals = cloud.has_normals();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    auto& c = cells[{std::lround(std::floor(p.x() / voxel_m)), std::lround(std::floor(p.y() / voxel_m)),
                     std::lround(std::floor(p.z() / voxel_m))}];
    c.p += p;
    if (normals) c.n += cloud.normals[i];
    ++c.count;
  }
  PointCloud out;
  for (const auto& [key, c] : cells) {
    out.points.push_back(c.p / c.count);
    if (normals) out.normals.push_back(c.n.norm() > 0 ? Vec3(c.n.normalized()) : Vec3::UnitZ());
  }
  return out;
}

GlobalStartResult global_align(const PreparedCloud& scene, const PreparedCloud& model, const Vec3& up_scene,
                               const GlobalStartOptions& o) {
  if (scene.cloud.empty() || model.cloud.empty()) throw std::invalid_argument("global_align: empty cloud");
  if (!model.cloud.has_normals()) throw std::invalid_argument("global_align: the model needs outward normals");
  if (!(up_scene.norm() > 0.0)) throw std::invalid_argument("global_align: zero up vector");
  if (!(o.yaw_step_deg > 0.0) || o.downtilt_deg.empty())
    throw std::invalid_argument("global_align: empty hypothesis grid");
  if (o.coarse_max_points < 6) throw std::invalid_argument("global_align: coarse_max_points must be at least 6");
  const Mat3 R_scene_upright = rotation_to_up(up_scene.normalized());
  const Vec3 c_model = centroid(model.cloud.points);
  const PreparedCloud scene_coarse = prepare(voxel_downsample(scene.cloud, o.coarse_voxel_m), o.coarse);
  const PreparedCloud model_coarse = prepare(voxel_downsample(model.cloud, o.coarse_voxel_m), o.coarse);
  const PreparedCloud scene_sparse = prepare(every_nth(scene_coarse.cloud, o.coarse_max_points), o.coarse);
  IcpOptions medium = o.coarse;
  medium.max_correspondence_distance_m = std::max(o.fine.max_correspondence_distance_m, 2.0 * o.coarse_voxel_m);

  std::vector<Hypothesis> hypotheses;
  const int yaws = static_cast<int>(std::ceil(360.0 / o.yaw_step_deg - 1e-9));
  for (const Vec3& centre : start_centres(scene.cloud.points, up_scene.normalized(), o.split_starts))
    for (double tilt : o.downtilt_deg)
      for (int k = 0; k < yaws; ++k) {
        Hypothesis h;
        h.yaw_rad = deg2rad(k * o.yaw_step_deg);
        h.downtilt_rad = deg2rad(tilt);
        h.centre_start_scene = centre;
        hypotheses.push_back(h);
      }
  // The hypotheses are independent: refine them in parallel (ICP itself is parallel too; TBB
  // nests the two without oversubscribing). The ICPs move the sparse points; the score weighs
  // them all.
  tbb::parallel_for(std::size_t{0}, hypotheses.size(), [&](std::size_t i) {
    auto& h = hypotheses[i];
    // R_scene_model: upright, turned by yaw about up, tilted down about the model's x axis.
    const Mat3 R_scene_model =
        R_scene_upright * exp_so3(Vec3::UnitZ() * h.yaw_rad) * exp_so3(Vec3::UnitX() * -h.downtilt_rad);
    Iso3 T_model_scene = Iso3::Identity();
    T_model_scene.linear() = R_scene_model.transpose();
    T_model_scene.translation() = c_model - R_scene_model.transpose() * h.centre_start_scene;
    T_model_scene = align(scene_sparse, model_coarse, T_model_scene, o.coarse).T_target_source;
    h.T_model_scene = align(scene_sparse, model_coarse, T_model_scene, medium).T_target_source;
    std::tie(h.residual, h.unseen) = score(scene_coarse, model_coarse, h.T_model_scene, o);
  });
  std::sort(hypotheses.begin(), hypotheses.end(),
            [](const Hypothesis& a, const Hypothesis& b) { return a.score() < b.score(); });

  // The best hypothesis and its best rival facing the other way, on the full clouds.
  auto refine = [&](Hypothesis h) {
    h.T_model_scene = align(scene, model, h.T_model_scene, o.fine).T_target_source;
    std::tie(h.residual, h.unseen) = score(scene, model, h.T_model_scene, o);
    return h;
  };
  auto boresight = [](const Hypothesis& h) { return Vec3(h.T_model_scene.linear().transpose() * Vec3::UnitY()); };
  GlobalStartResult out;
  out.winner = refine(hypotheses.front());
  const auto rival = std::find_if(hypotheses.begin(), hypotheses.end(), [&](const Hypothesis& h) {
    return boresight(h).dot(boresight(hypotheses.front())) < 0.0;
  });
  out.rival.residual = std::numeric_limits<double>::infinity();
  if (rival != hypotheses.end()) out.rival = refine(*rival);
  if (out.rival.score() < out.winner.score()) std::swap(out.winner, out.rival);
  out.fit = align(scene, model, out.winner.T_model_scene, o.fine);
  out.front_back_margin = out.rival.score() - out.winner.score();
  out.front_back_ambiguous = out.front_back_margin < o.ambiguity_margin;
  out.hypotheses = std::move(hypotheses);
  return out;
}

}  // namespace antpose::registration
