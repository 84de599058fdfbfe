#include "antpose/measure/long_axis.hpp"

#include <gtest/gtest.h>

#include "antpose/geometry/rotation.hpp"

namespace antpose::measure {
namespace {

// A panel 17 m up and 17 m away seen from below: its axis, the line of sight to it, and the two
// directions the axis can tilt: along the line of sight (the outline barely sees it) and across.
struct Geometry {
  Vec3 axis = Vec3(0.07, -0.98, -0.16).normalized();
  Vec3 sight = Vec3(0.04, -0.71, 0.71);
  Vec3 along() const { return (sight - sight.dot(axis) * axis).normalized(); }
  Vec3 across() const { return axis.cross(along()); }
  Vec3 tilted(double along_deg, double across_deg) const {
    return (axis + std::tan(deg2rad(along_deg)) * along() + std::tan(deg2rad(across_deg)) * across()).normalized();
  }
};

TEST(LongAxis, WithinTheGateTheOutlinesAxisStands) {
  const Geometry g;
  const Vec3 outline = g.tilted(1.5, 0.1), points = g.tilted(-0.5, 0.8);
  const KeptAxis k = keep_axis(outline, points, g.sight, deg2rad(3.0));
  EXPECT_FALSE(k.from_points);
  EXPECT_EQ(k.axis, outline);
  EXPECT_NEAR(rad2deg(k.disagreement_rad), rad2deg(angle_between(outline, points)), 1e-12);
}

TEST(LongAxis, BeyondItTheTiltAlongTheLineOfSightIsThePoints) {
  const Geometry g;
  // 4710-1's pattern: the outline slid along the line of sight, the points off both ways.
  const Vec3 outline = g.tilted(3.64, 0.02), points = g.tilted(-1.35, -1.33);
  const KeptAxis k = keep_axis(outline, points, g.sight, deg2rad(3.0));
  ASSERT_TRUE(k.from_points);
  // The kept axis: the points' component along the line of sight, the outline's across it.
  EXPECT_NEAR(rad2deg(angle_between(k.axis, g.tilted(-1.35, 0.02))), 0.0, 0.01);
  EXPECT_LT(rad2deg(angle_between(k.axis, g.axis)), 1.36);
  EXPECT_GT(rad2deg(angle_between(points, g.axis)), 1.8);
  EXPECT_NEAR(k.axis.norm(), 1.0, 1e-12);
  // Turning the outline's axis about `about` by along_rad gives it, and `about` is across both.
  EXPECT_NEAR(k.about.norm(), 1.0, 1e-12);
  EXPECT_NEAR(k.about.dot(outline), 0.0, 1e-12);
  EXPECT_NEAR(k.about.dot(k.axis), 0.0, 1e-12);
  EXPECT_NEAR(rad2deg(angle_between(Eigen::AngleAxisd(k.along_rad, k.about) * outline, k.axis)), 0.0, 1e-9);
  EXPECT_NEAR(rad2deg(k.along_rad), -(3.64 + 1.35), 0.01);
  // Turning about `sideways` moves the axis across the line of sight, where the outline is sharp.
  EXPECT_NEAR(k.sideways.norm(), 1.0, 1e-12);
  EXPECT_NEAR(k.sideways.dot(outline), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(k.sideways.cross(outline).normalized().dot(g.across())), 1.0, 1e-3);
}

TEST(LongAxis, PointsOffOnlyAcrossTheLineOfSightLeaveTheOutlinesAxis) {
  const Geometry g;
  const Vec3 outline = g.tilted(0.0, 0.0), points = g.tilted(0.0, 4.0);
  const KeptAxis k = keep_axis(outline, points, g.sight, deg2rad(3.0));
  EXPECT_TRUE(k.from_points);
  EXPECT_NEAR(rad2deg(angle_between(k.axis, outline)), 0.0, 1e-9);
}

}  // namespace
}  // namespace antpose::measure
