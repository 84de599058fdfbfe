#include "antpose/measure/model_free.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "antpose/core/statistics.hpp"

namespace antpose::measure {
namespace {

struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;  // n·p = offset
  double distance(const Vec3& p) const { return std::abs(normal.dot(p) - offset); }
};

std::vector<std::size_t> inliers_of(const PointCloud& cloud, const Plane& plane, double threshold) {
  std::vector<std::size_t> in;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (plane.distance(cloud.points[i]) <= threshold) in.push_back(i);
  return in;
}

// Centroid and scatter matrix of a subset.
std::pair<Vec3, Mat3> moments(const PointCloud& cloud, const std::vector<std::size_t>& idx) {
  Vec3 c = Vec3::Zero();
  for (const auto i : idx) c += cloud.points[i];
  c /= static_cast<double>(idx.size());
  Mat3 S = Mat3::Zero();
  for (const auto i : idx) {
    const Vec3 d = cloud.points[i] - c;
    S += d * d.transpose();
  }
  return {c, S / static_cast<double>(idx.size())};
}

}  // namespace

FaceFit fit_front_face(const PointCloud& cloud, const std::vector<Vec3>& viewpoints, const Vec3& up_in,
                       const ModelFreeOptions& options) {
  if (cloud.size() < 50)
    throw MeasurementError(fmt::format("model-free fit: {} points in the region, at least 50 needed", cloud.size()));
  const Vec3 up = up_in.normalized();

  // RANSAC for the plane with the most inliers; the sample is deterministic for a seed.
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, cloud.size() - 1);
  Plane best;
  std::size_t best_count = 0;
  for (int it = 0; it < options.ransac_iterations; ++it) {
    const Vec3& a = cloud.points[pick(rng)];
    const Vec3& b = cloud.points[pick(rng)];
    const Vec3& c = cloud.points[pick(rng)];
    const Vec3 n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    Plane p{n.normalized(), 0.0};
    p.offset = p.normal.dot(a);
    std::size_t count = 0;
    for (const auto& q : cloud.points) count += p.distance(q) <= options.plane_threshold_m;
    if (count > best_count) best_count = count, best = p;
  }
  // Least-squares refit on the inliers, twice (the refit can gather a few more).
  std::vector<std::size_t> in = inliers_of(cloud, best, options.plane_threshold_m);
  Vec3 centre = Vec3::Zero();
  Mat3 scatter = Mat3::Zero();
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  for (int pass = 0; pass < 2 && in.size() >= 3; ++pass) {
    std::tie(centre, scatter) = moments(cloud, in);
    es.compute(scatter);
    best.normal = es.eigenvectors().col(0);
    best.offset = best.normal.dot(centre);
    in = inliers_of(cloud, best, options.plane_threshold_m);
  }
  FaceFit fit;
  fit.inlier_share = static_cast<double>(in.size()) / static_cast<double>(cloud.size());
  if (in.size() < 3 || fit.inlier_share < options.min_inlier_share)
    throw MeasurementError(
        fmt::format("model-free fit: the largest plane holds {:.0f} % of the region's points (at "
                    "least {:.0f} % needed): no flat face to measure",
                    100 * fit.inlier_share, 100 * options.min_inlier_share));
  std::tie(centre, scatter) = moments(cloud, in);
  es.compute(scatter);
  Vec3 y = es.eigenvectors().col(0);
  Vec3 mean_view = Vec3::Zero();
  for (const auto& v : viewpoints) mean_view += v;
  if (!viewpoints.empty() && y.dot(mean_view / static_cast<double>(viewpoints.size()) - centre) < 0.0) y = -y;
  Vec3 z = es.eigenvectors().col(2);
  z -= y.dot(z) * y;
  z.normalize();
  if (z.dot(up) < 0.0) z = -z;
  const Vec3 x = y.cross(z);
  fit.R_scene_antenna.col(0) = x;
  fit.R_scene_antenna.col(1) = y;
  fit.R_scene_antenna.col(2) = z;
  fit.centre_scene = centre;

  std::vector<double> along, across;
  double ss = 0.0;
  for (const auto i : in) {
    const Vec3 d = cloud.points[i] - centre;
    along.push_back(d.dot(z));
    across.push_back(d.dot(x));
    ss += d.dot(y) * d.dot(y);
  }
  fit.rmse_m = std::sqrt(ss / static_cast<double>(in.size()));
  fit.length_m = quantile(along, 0.95) - quantile(along, 0.05);
  fit.width_m = quantile(across, 0.95) - quantile(across, 0.05);
  const double l1 = es.eigenvalues()(2), l2 = es.eigenvalues()(1);
  if (!(l1 > options.min_elongation * options.min_elongation * l2))
    throw MeasurementError(
        fmt::format("model-free fit: the face is {:.2f} m × {:.2f} m, not elongated enough to give "
                    "the panel's long axis (its spreads differ by less than {}×)",
                    fit.length_m, fit.width_m, options.min_elongation));

  // Covariance. The normal: a plane through n points of scatter σ² along it, spread λ1, λ2 in the
  // plane, tilts by σ²/(n λ1) about one in-plane axis and σ²/(n λ2) about the other. Neighbouring
  // stereo windows share their errors, so n counts 10 cm blocks, not points. The long axis comes
  // from where the face's edges end, each known to about edge_sigma_m: 2σ²/L² about y_a.
  const double n_eff = std::max(3.0, fit.length_m * std::max(fit.width_m, 0.05) / (0.1 * 0.1));
  const double s2 = fit.rmse_m * fit.rmse_m;
  Mat3 cov_antenna = Mat3::Zero();
  cov_antenna(0, 0) = s2 / (n_eff * l1);
  cov_antenna(2, 2) = s2 / (n_eff * l2);
  cov_antenna(1, 1) = 2.0 * options.edge_sigma_m * options.edge_sigma_m / (fit.length_m * fit.length_m);
  fit.covariance = fit.R_scene_antenna * cov_antenna * fit.R_scene_antenna.transpose();

  fit.warnings.push_back(
      "model-free: the face photographed is taken to be the radome; photographed from behind the result is the back "
      "plate's, 180° off in azimuth");
  if (fit.inlier_share < 0.6)
    fit.warnings.push_back(
        fmt::format("model-free: the front face holds only {:.0f} % of the region's points; the "
                    "region may include other objects",
                    100 * fit.inlier_share));
  return fit;
}

}  // namespace antpose::measure
