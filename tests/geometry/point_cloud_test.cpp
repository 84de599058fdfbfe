#include "antpose/geometry/point_cloud.hpp"

#include <gtest/gtest.h>

namespace antpose {
namespace {

TEST(PointCloud, CentroidIsTheMeanAndZeroForNoPoints) {
  EXPECT_TRUE(centroid({}).isZero());
  EXPECT_TRUE(centroid({Vec3(1, 2, 3), Vec3(3, 2, -1), Vec3(-1, 5, 1)}).isApprox(Vec3(1, 3, 1)));
}

TEST(PointCloud, TransformedMapsPointsAndTurnsNormals) {
  PointCloud c{{Vec3(1, 0, 0)}, {Vec3(1, 0, 0)}};
  Iso3 T = Iso3::Identity();
  T.linear() = rot_z(deg2rad(90));
  T.translation() = Vec3(0, 0, 2);
  const PointCloud t = transformed(c, T);
  EXPECT_TRUE(t.points[0].isApprox(Vec3(0, 1, 2)));
  EXPECT_TRUE(t.normals[0].isApprox(Vec3(0, 1, 0)));  // a normal turns, it does not move
}

TEST(PointCloud, BoundingBox) {
  const auto [lo, hi] = bounding_box(PointCloud{{Vec3(1, -2, 0), Vec3(-1, 4, 3)}, {}});
  EXPECT_TRUE(lo.isApprox(Vec3(-1, -2, 0)));
  EXPECT_TRUE(hi.isApprox(Vec3(1, 4, 3)));
}

}  // namespace
}  // namespace antpose
