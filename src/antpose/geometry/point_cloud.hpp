// Point clouds and rigid transforms, the currency of reconstruction and registration.
//
// A cloud's points are in metres in the frame its owner names (e.g. `cloud_board`,
// `model_antenna`); normals, when present, are unit vectors in the same frame, one per point.
// Rigid transforms follow the conventions: T_a_b maps points of frame b into frame a,
// p_a = R_a_b p_b + t_a_b (Eigen::Isometry3d).
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "antpose/geometry/rotation.hpp"

namespace antpose {

using Iso3 = Eigen::Isometry3d;

/// The rigid transform p ↦ R p + t.
inline Iso3 isometry(const Mat3& R, const Vec3& t) {
  Iso3 T = Iso3::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

struct PointCloud {
  std::vector<Vec3> points;
  std::vector<Vec3> normals;  // empty, or one unit normal per point

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_normals() const { return !normals.empty() && normals.size() == points.size(); }
};

/// The cloud with every point (and normal) mapped by T: p' = T p, n' = R n.
PointCloud transformed(const PointCloud& cloud, const Iso3& T);

/// The mean of the points; zero for none.
Vec3 centroid(const std::vector<Vec3>& points);

/// Axis-aligned bounding box of the points (min, max); both zero for an empty cloud.
std::pair<Vec3, Vec3> bounding_box(const PointCloud& cloud);

}  // namespace antpose
