#include "antpose/measure/mount_side.hpp"

#include <algorithm>
#include <cmath>

namespace antpose::measure {

std::optional<double> seen_face_depth_noise(const std::vector<Vec3>& points, const Vec3& size_m,
                                            const Vec3& toward_cameras, const MountSideOptions& o) {
  // Projected areas of the broad face and of a side face, as the cameras see them.
  if (std::abs(toward_cameras.y()) * size_m.x() < std::abs(toward_cameras.x()) * size_m.y()) return std::nullopt;
  const double side = toward_cameras.y() >= 0.0 ? 1.0 : -1.0;
  std::vector<double> into;  // depth behind the seen face, into the panel
  for (const Vec3& p : points) {
    if (std::abs(p.x()) > size_m.x() / 4 || std::abs(p.z()) > size_m.z() / 2) continue;
    const double depth = size_m.y() / 2 - side * p.y();
    if (depth > 0.0 && depth < size_m.y()) into.push_back(depth);
  }
  if (into.size() < o.min_noise_points) return std::nullopt;
  const auto median = into.begin() + static_cast<std::ptrdiff_t>(into.size() / 2);
  std::nth_element(into.begin(), median, into.end());
  return *median / 0.6745;
}

MountSide count_mount_side(const PointCloud& cloud, const Iso3& T_antenna_cloud, const registration::KdTree& model,
                           const Vec3& size_m, double reach_m, const Vec3& toward_cameras_c,
                           const MountSideOptions& o) {
  std::vector<Vec3> points;
  points.reserve(cloud.size());
  for (const auto& point : cloud.points) points.push_back(T_antenna_cloud * point);
  const Vec3 toward_cameras = T_antenna_cloud.linear() * toward_cameras_c;
  MountSide side;
  side.depth_noise_m = seen_face_depth_noise(points, size_m, toward_cameras, o).value_or(0.0);
  const bool cameras_before = toward_cameras.y() >= 0.0;
  const double gap_cameras_side = std::max(o.gap_m, o.noise_sigmas * side.depth_noise_m);
  for (const Vec3& p : points) {
    if (std::abs(p.x()) > size_m.x() / 2 + o.lateral_margin_m || std::abs(p.z()) > size_m.z() / 2) continue;
    const bool before = p.y() > 0.0;
    const double gap = before == cameras_before ? gap_cameras_side : o.gap_m;
    const double beyond = std::abs(p.y()) - size_m.y() / 2;
    if (beyond < gap || beyond > o.depth_m) continue;
    std::size_t index = 0;
    double d2 = 0.0;
    if (model.nearest(p, index, d2, reach_m * reach_m)) continue;
    ++(before ? side.before : side.behind);
  }
  return side;
}

MountVerdict mount_verdict(const MountSide& s, const MountSideOptions& o) {
  const auto outnumbers = [&](std::size_t more, std::size_t fewer, std::size_t at_least) {
    return more >= at_least && static_cast<double>(more) >= o.ratio * static_cast<double>(fewer);
  };
  if (outnumbers(s.behind, s.before, o.min_points)) return MountVerdict::kAsRegistered;
  if (outnumbers(s.before, s.behind, o.min_points_to_turn)) return MountVerdict::kTurned;
  return MountVerdict::kUndecided;
}

MountVerdict mast_side_verdict(const Vec3& axis_point, const Vec3& axis_dir, double radius_m, const Iso3& T_c_antenna,
                               double max_angle_rad) {
  const auto across = [&](const Vec3& v) -> Vec3 { return v - v.dot(axis_dir) * axis_dir; };
  const Vec3 away = across(T_c_antenna.translation() - axis_point);
  const Vec3 boresight = across(T_c_antenna.linear().col(1));
  if (away.norm() <= radius_m || boresight.norm() < 1e-9) return MountVerdict::kUndecided;
  const double cosine = away.normalized().dot(boresight.normalized());
  if (cosine >= std::cos(max_angle_rad)) return MountVerdict::kAsRegistered;
  if (cosine <= -std::cos(max_angle_rad)) return MountVerdict::kTurned;
  return MountVerdict::kUndecided;
}

bool attachments_turn_round(const OutlineScores& registered, const OutlineScores& turned, double margin) {
  const double whole = registered.score_with_attachments - turned.score_with_attachments;
  const double attachments = whole - (registered.score - turned.score);
  return whole > margin && attachments > margin;
}

double boresight_downtilt(const Mat3& R, const Vec3& up) {
  return -std::asin(std::clamp(R.col(1).dot(up.normalized()), -1.0, 1.0));
}

namespace {

MountVerdict by_downtilt(double as_registered, double turned, double max_uptilt) {
  if (as_registered > max_uptilt && turned < -max_uptilt) return MountVerdict::kAsRegistered;
  if (as_registered < -max_uptilt && turned > max_uptilt) return MountVerdict::kTurned;
  return MountVerdict::kUndecided;
}

}  // namespace

FrontBack decide_front_back(MountVerdict mount, double downtilt_registered, double downtilt_turned, double max_uptilt) {
  if (mount != MountVerdict::kUndecided) {
    const double chosen = mount == MountVerdict::kTurned ? downtilt_turned : downtilt_registered;
    if (chosen < -max_uptilt) return {MountVerdict::kUndecided, false, true};  // the cues disagree
    return {mount, false, false};
  }
  const auto verdict = by_downtilt(downtilt_registered, downtilt_turned, max_uptilt);
  return {verdict, verdict != MountVerdict::kUndecided, false};
}

}  // namespace antpose::measure
