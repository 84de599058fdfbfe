#include "antpose/registration/global_start.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

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

Vec3 centroid(const std::vector<Vec3>& points) {
  Vec3 c = Vec3::Zero();
  for (const auto& p : points) c += p;
  return c / static_cast<double>(points.size());
}

/// The two score parts of a pose (see the header).
std::pair<double, double> score(const PreparedCloud& scene, const PreparedCloud& model, const Iso3& T_model_scene,
                                const GlobalStartOptions& o) {
  const double tau2 = o.truncation_m * o.truncation_m;
  double residual = 0.0;
  for (const auto& p : scene.cloud.points) {
    std::size_t j;
    double d2;
    model.tree.nearest(T_model_scene * p, j, d2);
    residual += std::min(d2, tau2) / tau2;
  }
  residual /= static_cast<double>(scene.cloud.size());
  if (o.viewpoints_scene.empty()) return {residual, 0.0};
  const Iso3 T_scene_model = T_model_scene.inverse();
  std::size_t facing = 0, missing = 0;
  for (std::size_t i = 0; i < model.cloud.size(); ++i) {
    const Vec3 p = T_scene_model * model.cloud.points[i];
    const Vec3 n = T_scene_model.linear() * model.cloud.normals[i];
    const bool seen = std::any_of(o.viewpoints_scene.begin(), o.viewpoints_scene.end(),
                                  [&](const Vec3& v) { return n.dot((v - p).normalized()) > 0.2; });
    if (!seen) continue;
    ++facing;
    std::size_t j;
    double d2;
    if (!scene.tree.nearest(p, j, d2) || d2 > tau2) ++missing;
  }
  return {residual, facing ? static_cast<double>(missing) / static_cast<double>(facing) : 0.0};
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
  const Mat3 R_scene_upright = rotation_to_up(up_scene.normalized());
  const Vec3 c_scene = centroid(scene.cloud.points), c_model = centroid(model.cloud.points);

  std::vector<Hypothesis> hypotheses;
  const int yaws = static_cast<int>(std::ceil(360.0 / o.yaw_step_deg - 1e-9));
  for (double tilt : o.downtilt_deg)
    for (int k = 0; k < yaws; ++k) {
      Hypothesis h;
      h.yaw_rad = deg2rad(k * o.yaw_step_deg);
      h.downtilt_rad = deg2rad(tilt);
      hypotheses.push_back(h);
    }
  // The hypotheses are independent: refine them in parallel (ICP itself is parallel too; TBB
  // nests the two without oversubscribing).
  tbb::parallel_for(std::size_t{0}, hypotheses.size(), [&](std::size_t i) {
    auto& h = hypotheses[i];
    // R_scene_model: upright, turned by yaw about up, tilted down about the model's x axis.
    const Mat3 R_scene_model = R_scene_upright * exp_so3(Vec3::UnitZ() * h.yaw_rad) *
                               exp_so3(Vec3::UnitX() * -h.downtilt_rad);
    Iso3 T_model_scene = Iso3::Identity();
    T_model_scene.linear() = R_scene_model.transpose();
    T_model_scene.translation() = c_model - R_scene_model.transpose() * c_scene;
    T_model_scene = align(scene, model, T_model_scene, o.coarse).T_target_source;
    h.T_model_scene = align(scene, model, T_model_scene, o.fine).T_target_source;
    std::tie(h.residual, h.unseen) = score(scene, model, h.T_model_scene, o);
  });
  std::sort(hypotheses.begin(), hypotheses.end(),
            [](const Hypothesis& a, const Hypothesis& b) { return a.score() < b.score(); });

  GlobalStartResult out;
  const Hypothesis& best = hypotheses.front();
  out.fit = align(scene, model, best.T_model_scene, o.fine);
  // Runner-up: the best hypothesis whose boresight (model y axis) points the other way.
  const Vec3 b_best = best.T_model_scene.linear().transpose() * Vec3::UnitY();
  out.front_back_ratio = std::numeric_limits<double>::infinity();
  for (const auto& h : hypotheses)
    if ((h.T_model_scene.linear().transpose() * Vec3::UnitY()).dot(b_best) < 0.0) {
      out.front_back_ratio = h.score() / std::max(best.score(), 1e-12);
      break;
    }
  out.front_back_ambiguous = out.front_back_ratio < o.ambiguity_ratio;
  out.hypotheses = std::move(hypotheses);
  return out;
}

}  // namespace antpose::registration
