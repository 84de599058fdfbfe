#include "antpose/geometry/oriented_box.hpp"

#include <random>

#include <gtest/gtest.h>

#include "antpose/geometry/rotation.hpp"

namespace antpose {
namespace {

OrientedBox panel(const Vec3& centre, double yaw_deg, double tilt_deg = 0.0) {
  OrientedBox b;
  b.T_frame_box = isometry(rot_z(deg2rad(yaw_deg)) * rot_x(deg2rad(tilt_deg)), centre);
  b.size_m = Vec3(0.4, 0.15, 2.0);
  return b;
}

// Side by side 0.5 m apart, panels 0.4 m wide stand clear of each other at any yaw that keeps
// them apart; 0.3 m apart, turned alike, they share 10 cm of width.
TEST(OrientedBox, SideBySidePanelsOverlapOnlyWhenTheyShareVolume) {
  EXPECT_FALSE(boxes_overlap(panel(Vec3::Zero(), 0), panel(Vec3(0.5, 0, 0), 0)));
  EXPECT_TRUE(boxes_overlap(panel(Vec3::Zero(), 0), panel(Vec3(0.3, 0, 0), 0)));
  EXPECT_TRUE(boxes_overlap(*shrunk(panel(Vec3::Zero(), 0), 0.04), *shrunk(panel(Vec3(0.3, 0, 0), 0), 0.04)));
  EXPECT_FALSE(boxes_overlap(*shrunk(panel(Vec3::Zero(), 0), 0.06), *shrunk(panel(Vec3(0.3, 0, 0), 0), 0.06)));
  EXPECT_TRUE(boxes_overlap(panel(Vec3::Zero(), 0), panel(Vec3::Zero(), 30, 10)));
}

// Against a dense sampling of one box: where a sample of b lies inside a, they overlap; where
// they are reported apart, no sample of b lies inside a. Random poses, sizes and distances.
TEST(OrientedBox, AgreesWithSamplesOfTheBoxes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.1, 1.0);
  const auto random_box = [&] {
    OrientedBox b;
    b.T_frame_box = isometry(Quat(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix(), Vec3(u(rng), u(rng), u(rng)) * 0.8);
    b.size_m = Vec3(size(rng), size(rng), size(rng));
    return b;
  };
  int apart = 0, together = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const OrientedBox a = random_box(), b = random_box();
    bool sample_inside = false;
    for (int k = 0; k < 2000 && !sample_inside; ++k) {
      const Vec3 p = b.T_frame_box * Vec3(u(rng) * b.size_m.x() / 2, u(rng) * b.size_m.y() / 2, u(rng) * b.size_m.z() / 2);
      sample_inside = ((a.T_frame_box.inverse() * p).cwiseAbs().array() <= (a.size_m / 2).array()).all();
    }
    const bool overlap = boxes_overlap(a, b);
    if (sample_inside) {
      EXPECT_TRUE(overlap) << "trial " << trial;
    }
    apart += !overlap, together += overlap;
  }
  EXPECT_GT(apart, 40);
  EXPECT_GT(together, 40);
}

// Against the distances of dense samples along random segments: never more than the nearest
// sample's, never less by more than the sample spacing allows; zero where a sample lies inside.
TEST(OrientedBox, SegmentDistanceAgreesWithSamplesOfTheSegment) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const OrientedBox box = panel(Vec3(0.1, -0.2, 0.3), 35, 8);
  const auto point_distance = [&](const Vec3& p) {
    return ((box.T_frame_box.inverse() * p).cwiseAbs() - box.size_m / 2).cwiseMax(0.0).norm();
  };
  int meeting = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a = 2 * Vec3(u(rng), u(rng), u(rng)), b = 2 * Vec3(u(rng), u(rng), u(rng));
    double nearest = 1e9;
    const int n = 4000;
    for (int k = 0; k <= n; ++k) nearest = std::min(nearest, point_distance(a + (b - a) * (double(k) / n)));
    const double d = box_segment_distance(box, a, b);
    EXPECT_LE(d, nearest + 1e-9) << "trial " << trial;
    EXPECT_GE(d, nearest - (b - a).norm() / n) << "trial " << trial;
    meeting += nearest == 0.0;
  }
  EXPECT_GT(meeting, 20);
  // A vertical pipe 0.2 m behind a panel's back face, and one through it.
  EXPECT_NEAR(box_segment_distance(panel(Vec3::Zero(), 0), Vec3(0, 0.275, -3), Vec3(0, 0.275, 3)), 0.2, 1e-9);
  EXPECT_EQ(box_segment_distance(panel(Vec3::Zero(), 0), Vec3(0, 0.05, -3), Vec3(0, 0.05, 3)), 0.0);
}

}  // namespace
}  // namespace antpose
