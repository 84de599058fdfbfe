#include "antpose/registration/pose_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "antpose/model/sampling.hpp"

namespace antpose::registration {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double finite_mean(const std::vector<double>& values) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const double v : values)
    if (std::isfinite(v)) sum += v, ++n;
  return n ? sum / static_cast<double>(n) : 0.0;
}

// One stratum's paired differences other − better: their mean and the variance of that mean.
struct Stratum {
  double mean = 0.0, variance_of_mean = 0.0;
  std::size_t n = 0;
};

Stratum paired(const std::vector<double>& better, const std::vector<double>& other) {
  std::vector<double> d;
  for (std::size_t k = 0; k < std::min(better.size(), other.size()); ++k)
    if (std::isfinite(better[k]) && std::isfinite(other[k])) d.push_back(other[k] - better[k]);
  Stratum s;
  s.n = d.size();
  if (d.empty()) return s;
  for (const double x : d) s.mean += x / static_cast<double>(d.size());
  if (d.size() == 1) {
    s.variance_of_mean = s.mean * s.mean;  // one unit alone cannot be decisive
    return s;
  }
  double ss = 0.0;
  for (const double x : d) ss += (x - s.mean) * (x - s.mean);
  s.variance_of_mean = ss / static_cast<double>(d.size() - 1) / static_cast<double>(d.size());
  return s;
}

// The photos' stratum: as paired, or as one unit where their errors are common
// (EvidenceOptions::outline_errors_common).
Stratum photos(const std::vector<double>& better, const std::vector<double>& other, const EvidenceOptions& o) {
  Stratum s = paired(better, other);
  if (o.outline_errors_common) s.variance_of_mean *= static_cast<double>(s.n);
  return s;
}

Comparison combine(const std::vector<std::pair<Stratum, double>>& strata, const EvidenceOptions& o) {
  Comparison c;
  double variance = 0.0;
  for (const auto& [s, weight] : strata) {
    if (s.n == 0) continue;
    c.difference += weight * s.mean;
    variance += weight * weight * s.variance_of_mean;
    c.units += s.n;
  }
  c.standard_error = std::sqrt(variance);
  c.decisive = c.units > 0 && c.difference > o.min_difference && c.difference > o.decisive_z * c.standard_error;
  return c;
}

// The σ of the depth of the face the cameras see (antenna frame, along y): from the points in the
// middle half of its width that lie up to the panel's depth behind it (a half-normal's median is
// 0.674σ). 0 where the cameras see a side face more (the points' spread is then the panel's
// depth) or too few points lie there.
double seen_face_noise(const std::vector<Vec3>& points_antenna, const Vec3& size, const Vec3& toward_cameras) {
  if (std::abs(toward_cameras.y()) * size.x() < std::abs(toward_cameras.x()) * size.y()) return 0.0;
  const double side = toward_cameras.y() >= 0.0 ? 1.0 : -1.0;
  std::vector<double> into;
  for (const Vec3& p : points_antenna) {
    if (std::abs(p.x()) > size.x() / 4 || std::abs(p.z()) > size.z() / 2) continue;
    const double depth = size.y() / 2 - side * p.y();
    if (depth > 0.0 && depth < size.y()) into.push_back(depth);
  }
  if (into.size() < 30) return 0.0;
  const auto median = into.begin() + static_cast<std::ptrdiff_t>(into.size() / 2);
  std::nth_element(into.begin(), median, into.end());
  return *median / 0.6745;
}

}  // namespace

OptionProblems EvidenceOptions::Check() const {
  OptionProblems p;
  p.nest("outline", outline.Check());
  p.require(point_slices >= 1, "point_slices", "at least 1");
  p.require(point_truncation_m > 0, "point_truncation_m", "positive");
  p.require(points_weight >= 0 && side_mount_weight >= 0 && side_mount_outline_weight >= 0,
            "points_weight, side_mount_weight, side_mount_outline_weight", "≥ 0");
  p.require(points_weight_range >= 1, "points_weight_range", "at least 1");
  p.require(model_spacing_m > 0, "model_spacing_m", "positive");
  p.require(mount_gap_m >= 0 && mount_depth_m > mount_gap_m, "mount_gap_m, mount_depth_m", "0 ≤ gap < depth");
  p.require(decisive_z > 0 && min_difference >= 0, "decisive_z, min_difference", "z > 0, difference ≥ 0");
  return p;
}

double PoseEvidence::score(const EvidenceOptions& o) const {
  return finite_mean(outline) + o.points_weight * finite_mean(points);
}

double PoseEvidence::side_score(const EvidenceOptions& o) const {
  return o.side_mount_weight * finite_mean(mount) + o.side_mount_outline_weight * finite_mean(mount_outline);
}

Comparison compare_shape(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& o) {
  return combine(
      {{photos(better.outline, other.outline, o), 1.0}, {paired(better.points, other.points), o.points_weight}}, o);
}

Comparison compare_placement(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& o) {
  return combine({{photos(better.placement, other.placement, o), 1.0}}, o);
}

Comparison compare_side(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& o) {
  return combine({{paired(better.mount, other.mount), o.side_mount_weight},
                  {paired(better.mount_outline, other.mount_outline), o.side_mount_outline_weight}},
                 o);
}

EvidenceJudge::EvidenceJudge(const model::AntennaModel& model, const EvidenceScene& scene,
                             const EvidenceOptions& options)
    : model_(model),
      scene_(scene),
      options_(options),
      surface_(model::sample_surface(model.mesh_antenna, options.model_spacing_m, 1).points) {
  throw_unless_ok(options.Check(), "EvidenceOptions");
  if (!scene.views || scene.views->empty() || !scene.points_board)
    throw std::invalid_argument("EvidenceJudge: a scene without photos or points");
  options_.outline.outline_box_m = model::outline_box(model);
  const Vec3 up = scene.up_board.normalized();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec3& p : scene.points_board->points) lo = std::min(lo, p.dot(up)), hi = std::max(hi, p.dot(up));
  const double height = std::max(hi - lo, 1e-9);
  slice_size_.assign(options.point_slices, 0);
  for (const Vec3& p : scene.points_board->points) {
    const auto k = std::min(options.point_slices - 1,
                            static_cast<std::size_t>(std::max(0.0, (p.dot(up) - lo) / height * options.point_slices)));
    slice_.push_back(k);
    ++slice_size_[k];
  }
}

void EvidenceJudge::judge_points(const Iso3& T_board_antenna, PoseEvidence& out) const {
  const auto& o = options_;
  const Iso3 T_antenna_board = T_board_antenna.inverse();
  const auto& cloud = scene_.points_board->points;
  std::vector<Vec3> points_antenna;
  points_antenna.reserve(cloud.size());
  for (const Vec3& p : cloud) points_antenna.push_back(T_antenna_board * p);
  Vec3 toward_cameras = Vec3::Zero();
  for (const Vec3& c : scene_.viewpoints_board) toward_cameras += T_antenna_board * c;
  if (!scene_.viewpoints_board.empty()) toward_cameras /= static_cast<double>(scene_.viewpoints_board.size());
  const Vec3& size = model_.size_m;
  const double noise = seen_face_noise(points_antenna, size, toward_cameras);
  const bool cameras_before = toward_cameras.y() >= 0.0;
  std::vector<double> cost(slice_size_.size(), 0.0), before(slice_size_.size(), 0.0);
  const double tau2 = o.point_truncation_m * o.point_truncation_m;
  for (std::size_t i = 0; i < points_antenna.size(); ++i) {
    const Vec3& p = points_antenna[i];
    std::size_t index = 0;
    double d2 = tau2;
    const bool near = surface_.nearest(p, index, d2, tau2);
    cost[slice_[i]] += near ? d2 / tau2 : 1.0;
    if (near || p.y() <= 0.0 || std::abs(p.x()) > size.x() / 2 + o.mount_margin_m || std::abs(p.z()) > size.z() / 2)
      continue;
    const double gap = cameras_before ? std::max(o.mount_gap_m, o.mount_noise_sigmas * noise) : o.mount_gap_m;
    const double beyond = p.y() - size.y() / 2;
    if (beyond >= gap && beyond <= o.mount_depth_m) before[slice_[i]] += 1.0;
  }
  for (std::size_t k = 0; k < slice_size_.size(); ++k) {
    const auto n = static_cast<double>(slice_size_[k]);
    out.points.push_back(n > 0 ? cost[k] / n : kNaN);
    out.mount.push_back(n > 0 ? before[k] / n : kNaN);
  }
}

PoseEvidence EvidenceJudge::operator()(const Iso3& T_board_antenna) const {
  PoseEvidence out;
  const auto outline =
      evaluate_outline(model_.mesh_antenna, T_board_antenna, *scene_.views, scene_.intrinsics, options_.outline);
  out.outline = outline.cost;
  out.placement = outline.placement;
  judge_points(T_board_antenna, out);
  return out;
}

}  // namespace antpose::registration
