#include "antpose/measure/registration_scene.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

// Two photos from 10 m of an antenna with the mast 0.5 m behind it and a neighbour beside it,
// the board frame's up along -y (camera y points down). The region holds points on all three.
struct Fixture {
  CameraPoses poses;
  reconstruction::RegionReconstruction region;
  SceneObjects objects;
  Vec3 up_board = -Vec3::UnitY();
  std::size_t antenna_points = 0;
};

Fixture make_fixture() {
  Fixture f;
  auto& K = f.poses.intrinsics;
  K.width = 640, K.height = 480, K.fx = K.fy = 600, K.cx = 320, K.cy = 240;
  for (const double x : {0.0, 1.0}) {
    reconstruction::PosedView& v = f.poses.views.emplace_back();
    v.image = cv::Mat(K.height, K.width, CV_8UC1, cv::Scalar(128));
    v.t_camera_board = Vec3(-x, 0.0, 2.0);  // the camera at (x, 0, -2)
  }
  reconstruction::Mast mast;
  mast.axis_point_board = Vec3(0.0, 0.0, 10.5);
  mast.up_board = f.up_board;
  mast.radius_m = 0.2;
  mast.low_m = -3.0, mast.high_m = 3.0;
  f.objects.mast = mast;
  f.objects.board_box = {Vec3(-0.4, -0.3, 0.0), Vec3(0.4, 0.3, 0.0)};
  KnownBox neighbour;
  neighbour.T_board_box.translation() = Vec3(-0.9, 0.0, 10.0);
  neighbour.size_m = Vec3(0.3, 1.2, 0.15);
  f.objects.neighbours.push_back(neighbour);
  auto& cloud = f.region.cloud_board.points;
  for (int i = 0; i < 40; ++i) {
    const double y = -0.6 + 1.2 * i / 39.0;
    const double a = (i % 9 - 4) * 0.3;  // round the mast's near side
    cloud.emplace_back(0.2 * std::sin(a), y, 10.5 - 0.2 * std::cos(a) + 0.01 * (i % 3 - 1));
    cloud.emplace_back(-0.9 + 0.03 * (i % 5 - 2), y, 10.0 - 0.075);  // the neighbour's front
    cloud.emplace_back(0.8 + 0.03 * (i % 5 - 2), y, 10.0 - 0.075);   // the antenna's front
    ++f.antenna_points;
  }
  return f;
}

// The region's points that the mast or a neighbour explains are left out; the mast behind the
// antenna shows in each photo as two edges that are not the antenna's.
TEST(RegistrationScene, LeavesTheMastsAndTheNeighboursPointsOut) {
  const Fixture f = make_fixture();
  const auto s = registration_scene(f.poses, f.up_board, f.region, 0, cv::Rect(300, 180, 60, 120), f.objects);
  ASSERT_EQ(s.points_board.size(), f.antenna_points);
  for (const Vec3& p : s.points_board.points) EXPECT_NEAR(p.x(), 0.8, 0.07);
  ASSERT_EQ(s.views.size(), 2u);
  for (const auto& v : s.views) EXPECT_EQ(v.background_edges.size(), 3u);  // the mast's two and the neighbour's
}

// Without known objects every point is the antenna's; a wider clearance takes in points off the
// mast's surface.
TEST(RegistrationScene, KeepsEveryPointWithoutKnownObjectsAndClaimsByTheClearance) {
  Fixture f = make_fixture();
  auto bare = f.objects;
  bare.mast.reset();
  bare.neighbours.clear();
  EXPECT_EQ(registration_scene(f.poses, f.up_board, f.region, 0, cv::Rect(300, 180, 60, 120), bare).points_board.size(),
            f.region.cloud_board.size());
  f.objects.neighbours.clear();
  f.region.cloud_board.points.emplace_back(0.0, 0.0, 10.5 - 0.26);  // 6 cm off the mast's surface
  f.objects.object_clearance_m = 0.03;
  const auto near = registration_scene(f.poses, f.up_board, f.region, 0, cv::Rect(300, 180, 60, 120), f.objects);
  f.objects.object_clearance_m = 0.08;
  const auto wide = registration_scene(f.poses, f.up_board, f.region, 0, cv::Rect(300, 180, 60, 120), f.objects);
  EXPECT_EQ(near.points_board.size(), 2 * f.antenna_points + 1);
  EXPECT_EQ(wide.points_board.size(), 2 * f.antenna_points);
}

}  // namespace
}  // namespace antpose::measure
