#include "antpose/geometry/point_cloud.hpp"

namespace antpose {

PointCloud transformed(const PointCloud& cloud, const Iso3& T) {
  PointCloud out;
  out.points.reserve(cloud.size());
  for (const auto& p : cloud.points) out.points.push_back(T * p);
  if (cloud.has_normals()) {
    out.normals.reserve(cloud.size());
    const Mat3 R = T.linear();
    for (const auto& n : cloud.normals) out.normals.push_back(R * n);
  }
  return out;
}

Vec3 centroid(const std::vector<Vec3>& points) {
  if (points.empty()) return Vec3::Zero();
  Vec3 sum = Vec3::Zero();
  for (const auto& p : points) sum += p;
  return sum / static_cast<double>(points.size());
}

std::pair<Vec3, Vec3> bounding_box(const PointCloud& cloud) {
  if (cloud.empty()) return {Vec3::Zero(), Vec3::Zero()};
  Vec3 lo = cloud.points.front(), hi = lo;
  for (const auto& p : cloud.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return {lo, hi};
}

}  // namespace antpose
