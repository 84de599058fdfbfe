#include "antpose/reconstruction/mast.hpp"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/photo_simulator.hpp"
#include "support/render_support.hpp"

namespace antpose::reconstruction {
namespace {

using test::iso;

// A ground site: a 0.5 m mast, 20 m tall, photographed from 20 m away over 10° of directions,
// looking up at 16 m, against the sky. The board frame is an arbitrary rigid frame with the
// world's up as its own (T_world_board turns about the vertical only: a level board).
struct MastScene {
  camera::CameraIntrinsics K;
  Iso3 T_world_board;
  Vec3 axis_world = Vec3(0.4, -0.3, 0.0);
  double radius = 0.25;
  std::vector<PosedView> views;
  Vec3 up_board() const { return T_world_board.linear().transpose() * Vec3::UnitZ(); }
  Vec3 board(const Vec3& p_world) const { return T_world_board.inverse() * p_world; }
};

MastScene make_mast_scene(bool with_mast = true) {
  MastScene s;
  s.K.width = 1280, s.K.height = 960, s.K.fx = s.K.fy = 2400, s.K.cx = 641.3, s.K.cy = 478.6;
  s.K.distortion = {0.06, -0.15, 0.0002, -0.0003, 0.08};
  s.T_world_board = iso(rot_z(deg2rad(-70.0)), Vec3(3.0, -18.0, 1.4));
  sim::Scene scene;
  sim::MeshObject mast;
  mast.name = "mast";
  mast.mesh = sim::cylinder_mesh(s.axis_world, s.axis_world + Vec3(0, 0, 20), s.radius, 48);
  mast.corner_normals = sim::smooth_corner_normals(mast.mesh, deg2rad(30));
  mast.albedo = 0.45;
  if (with_mast) scene.meshes.push_back(mast);
  const sim::PhotoRenderer renderer(s.K, 2);
  sim::SensorModel sensor;
  sensor.jpeg_quality = 95;
  for (int k = 0; k < 8; ++k) {
    const double a = deg2rad(200.0 + 10.0 * k / 7.0);
    const Vec3 from = s.axis_world + Vec3(20.0 * std::sin(a), 20.0 * std::cos(a), 1.6);
    const auto pose = test::level_camera(from, s.axis_world + Vec3(0, 0, 15.5) - from, deg2rad(1.5 * ((k % 3) - 1)));
    PosedView v;
    v.image = sim::sensor_image(renderer.render(scene, pose, sim::Lighting{}), sensor, 300 + k);
    const Iso3 T_camera_board = test::camera_from_board(pose, s.T_world_board);
    v.R_camera_board = T_camera_board.linear();
    v.t_camera_board = T_camera_board.translation();
    s.views.push_back(v);
  }
  return s;
}

const MastScene& mast_scene() {
  static const MastScene s = make_mast_scene();
  return s;
}

// Points on the mast as dense stereo gives them from 20 m: one side of its front only (the region
// around a panel hanging there), scattered by 2 cm in depth, among 15 % of stray points.
PointCloud seen_points(const MastScene& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3 camera = s.T_world_board * camera::camera_centre(s.views[4].R_camera_board, s.views[4].t_camera_board);
  const double towards = std::atan2(camera.y() - s.axis_world.y(), camera.x() - s.axis_world.x());
  PointCloud cloud;
  for (int i = 0; i < 3000; ++i) {
    Vec3 p_world;
    if (u(rng) < 0.85) {
      const double a = towards + deg2rad(10.0 + 60.0 * u(rng));  // one side of the front
      const Vec3 radial(std::cos(a), std::sin(a), 0.0);
      p_world = s.axis_world + Vec3(0, 0, 15.8 + 1.4 * u(rng)) + (s.radius + noise(rng)) * radial +
                noise(rng) * (camera - s.axis_world).normalized();
    } else {
      p_world = s.axis_world + Vec3(-1.0 + 2.0 * u(rng), -1.0 + 2.0 * u(rng), 15.8 + 1.4 * u(rng));
    }
    cloud.points.push_back(s.board(p_world));
  }
  return cloud;
}

TEST(Mast, RecoversAxisAndRadiusFromNoisyPointsAndTheOutline) {
  const auto& s = mast_scene();
  const Vec3 up = s.up_board();
  const Vec3 axis_board = s.board(s.axis_world);
  const double ground = up.dot(axis_board);
  const auto mast = fit_mast(seen_points(s, 1), up, s.views, s.K, ground + 14.0, ground + 15.6, {});
  ASSERT_TRUE(mast.has_value());
  const Vec3 off = mast->axis_point_board - axis_board;
  std::printf("radius %.4f m (truth %.2f), axis %.4f m off, %zu photos, edge RMS %.2f px\n", mast->radius_m, s.radius,
              (off - off.dot(up) * up).norm(), mast->views, mast->edge_rms_px);
  EXPECT_NEAR(mast->radius_m, s.radius, 0.005);
  EXPECT_LT((off - off.dot(up) * up).norm(), 0.01);  // horizontal distance between the axes
  EXPECT_NEAR(mast->up_board.dot(up), 1.0, 1e-12);
  EXPECT_EQ(mast->views, s.views.size());
  EXPECT_LT(mast->edge_rms_px, 0.5);
  EXPECT_GT(mast->points, 2000u);
  // It reaches from the outline's stretch to above the points.
  const double low = up.dot(mast->axis_point_board) + mast->low_m, high = up.dot(mast->axis_point_board) + mast->high_m;
  EXPECT_LE(low, ground + 14.0 + 1e-9);
  EXPECT_GE(high, ground + 17.2);

  // Its outline in a photo is the mast's edges: both lines lie on strong steps, the mast's width
  // apart; the camera lies outside it, and the mast stands in front of what is behind it.
  const auto& v = s.views[2];
  const auto lines = mast_outline(*mast, s.K, v.R_camera_board, v.t_camera_board);
  ASSERT_EQ(lines[0].size(), 17u);
  ASSERT_EQ(lines[1].size(), 17u);
  const Vec3 centre = camera::camera_centre(v.R_camera_board, v.t_camera_board);
  const Vec3 middle = mast->axis_point_board + 0.5 * (mast->low_m + mast->high_m) * up;
  const auto width = cv::norm(lines[0][8] - lines[1][8]);
  EXPECT_NEAR(width, 2 * s.radius * s.K.fx / (middle - centre).norm(), 1.5);
  const Vec3 behind = axis_board + 0.6 * (axis_board - centre - (axis_board - centre).dot(up) * up).normalized();
  EXPECT_TRUE(mast_in_front(*mast, centre, behind));
  EXPECT_FALSE(mast_in_front(
      *mast, centre, axis_board + 2.0 * (centre - axis_board - (centre - axis_board).dot(up) * up).normalized()));
}

// Points that lie on an arc but no mast in the photos; too few points; an empty outline stretch:
// no mast.
TEST(Mast, IsNotClaimedWithoutItsOutline) {
  const auto empty = make_mast_scene(false);
  const Vec3 up = empty.up_board();
  const double ground = up.dot(empty.board(empty.axis_world));
  EXPECT_FALSE(fit_mast(seen_points(empty, 2), up, empty.views, empty.K, ground + 14.0, ground + 15.6, {}));
  const auto& s = mast_scene();
  PointCloud few = seen_points(s, 3);
  few.points.resize(100);
  EXPECT_FALSE(fit_mast(few, up, s.views, s.K, ground + 14.0, ground + 15.6, {}));
  EXPECT_FALSE(fit_mast(seen_points(s, 4), up, s.views, s.K, ground + 15.6, ground + 14.0, {}));
}

// A fatter cylinder sharing one of the mast's outline lines (its axis moved sideways by as much as
// its radius grew) meets edges along that line in every photo and along the other in none: at the
// share the outline search asks of the two together it would pass, but one line fixes no
// cylinder, so it is not confirmed; the mast itself, from the same share, is.
TEST(Mast, IsNotConfirmedByOneOutlineLine) {
  const auto& s = mast_scene();
  const Vec3 up = s.up_board();
  const Vec3 axis_board = s.board(s.axis_world);
  const double ground = up.dot(axis_board);
  const Vec3 centre = camera::camera_centre(s.views[4].R_camera_board, s.views[4].t_camera_board);
  const Vec3 towards = (centre - axis_board - (centre - axis_board).dot(up) * up).normalized();
  const Vec3 across = up.cross(towards);
  MastOptions o;
  o.min_edge_fraction = 0.4;
  Mast mast;
  mast.up_board = up;
  mast.axis_point_board = axis_board + (ground + 14.0 - up.dot(axis_board)) * up;
  mast.radius_m = s.radius;
  mast.low_m = -1.0, mast.high_m = 2.0;
  const auto found = confirm_mast(mast, s.views, s.K, ground + 14.0, ground + 15.6, {}, o);
  ASSERT_TRUE(found.has_value());
  EXPECT_NEAR(found->radius_m, s.radius, 0.005);
  Mast fat = mast;
  fat.radius_m = s.radius + 0.3;
  fat.axis_point_board += 0.3 * across;
  EXPECT_FALSE(confirm_mast(fat, s.views, s.K, ground + 14.0, ground + 15.6, {}, o));
}

// Stage 1 alone claims the cylinder the points lie on whatever the photos show, and says no photo
// confirmed it; too few points or too short a stretch: none.
TEST(Mast, FromPointsAloneIsTheCylinderTheyLieOn) {
  const auto empty = make_mast_scene(false);
  const Vec3 up = empty.up_board();
  const Vec3 axis_board = empty.board(empty.axis_world);
  const PointCloud points = seen_points(empty, 5);
  const auto mast = mast_from_points(points, up, {});
  ASSERT_TRUE(mast.has_value());
  const Vec3 off = mast->axis_point_board - axis_board;
  std::printf("radius %.3f m (truth %.2f), axis %.3f m off, %zu points\n", mast->radius_m, empty.radius,
              (off - off.dot(up) * up).norm(), mast->points);
  EXPECT_EQ(mast->views, 0u);
  EXPECT_EQ(mast->edge_samples, 0u);
  EXPECT_GT(mast->points, 2000u);  // of the 85 % on it
  // From 20 m the arc's 2 cm scatter leaves the radius rough, but its band holds the points on
  // the mast.
  Mast truth = *mast;
  truth.up_board = up, truth.axis_point_board = axis_board, truth.radius_m = empty.radius;
  std::size_t on_mast = 0, in_band = 0;
  for (const Vec3& p : points.points)
    if (distance_from_surface(truth, p) < 0.06) {
      ++on_mast;
      in_band += distance_from_surface(*mast, p) <= MastOptions{}.point_tolerance_m;
    }
  std::printf("%zu of the %zu points on the mast in its band\n", in_band, on_mast);
  EXPECT_GT(in_band, 0.85 * static_cast<double>(on_mast));  // the 2 cm scatter leaves ~11 % beyond 4 cm
  const double low = up.dot(mast->axis_point_board) + mast->low_m, high = up.dot(mast->axis_point_board) + mast->high_m;
  const double ground = up.dot(axis_board);
  EXPECT_NEAR(low, ground + 15.8, 0.1);
  EXPECT_NEAR(high, ground + 17.2, 0.1);
  PointCloud few = points;
  few.points.resize(100);
  EXPECT_FALSE(mast_from_points(few, up, {}));
  MastOptions tall;
  tall.min_height_m = 2.0;
  EXPECT_FALSE(mast_from_points(points, up, tall));
}

// A mast of 0.2 m radius leaning away from the board's z axis, 3 m of it about (1, 2, 3).
Mast leaning_mast() {
  Mast mast;
  mast.axis_point_board = Vec3(1.0, 2.0, 3.0);
  mast.up_board = Vec3(0.0, 0.6, 0.8);
  mast.radius_m = 0.2;
  mast.low_m = -1.0, mast.high_m = 2.0;
  return mast;
}

// On the mast: within the clearance of its surface or inside it, and of its extent along the axis.
TEST(Mast, HoldsThePointsOnItsSurfaceAndInsideOverItsExtent) {
  const Mast mast = leaning_mast();
  const Vec3 out = mast.up_board.unitOrthogonal();
  const auto at = [&](double from_axis, double along) {
    return Vec3(mast.axis_point_board + from_axis * out + along * mast.up_board);
  };
  EXPECT_TRUE(on_mast(mast, at(0.2, 0.0), 0.03));
  EXPECT_TRUE(on_mast(mast, at(0.0, 1.5), 0.03));
  EXPECT_TRUE(on_mast(mast, at(0.225, -1.02), 0.03));
  EXPECT_FALSE(on_mast(mast, at(0.24, 0.0), 0.03));
  EXPECT_FALSE(on_mast(mast, at(0.1, 2.05), 0.03));
  EXPECT_FALSE(on_mast(mast, at(0.1, -1.05), 0.03));
  EXPECT_TRUE(on_mast(mast, at(0.24, 0.0), 0.05));
}

// Distances across the axis: a point's height along it does not count.
TEST(Mast, MeasuresDistancesAcrossItsAxis) {
  Mast mast;
  mast.axis_point_board = Vec3(1.0, 2.0, 3.0);
  mast.up_board = Vec3(0.0, 0.6, 0.8);
  mast.radius_m = 0.2;
  const Vec3 out = mast.up_board.cross(Vec3::UnitX());
  const Vec3 p = mast.axis_point_board + 0.5 * out + 4.0 * mast.up_board;
  EXPECT_NEAR(distance_from_axis(mast, p), 0.5, 1e-12);
  EXPECT_NEAR(distance_from_surface(mast, p), 0.3, 1e-12);
  EXPECT_NEAR(distance_from_surface(mast, mast.axis_point_board - 7.0 * mast.up_board), 0.2, 1e-12);  // inside
}

// Found again: the same axis described from another point on it is the same mast; a shift of the
// axis (at the antenna or a metre along), a tilt, another radius or another end is not.
TEST(Mast, IsTheSameWhereFoundAgainWithinTheTolerance) {
  const Mast a = leaning_mast();
  const Vec3 antenna = a.axis_point_board + 0.8 * a.up_board.unitOrthogonal() + 1.0 * a.up_board;
  Mast b = a;
  b.axis_point_board += 0.5 * a.up_board;  // the same axis and ends, described from elsewhere
  b.low_m -= 0.5, b.high_m -= 0.5;
  EXPECT_TRUE(same_mast(a, b, antenna, 0.01));
  Mast shifted = a;
  shifted.axis_point_board += 0.015 * a.up_board.unitOrthogonal();
  EXPECT_FALSE(same_mast(a, shifted, antenna, 0.01));
  EXPECT_TRUE(same_mast(a, shifted, antenna, 0.02));
  Mast tilted = a;  // through the same point at the antenna's height, 2° off
  const Vec3 at_antenna = a.axis_point_board + a.up_board.dot(antenna - a.axis_point_board) * a.up_board;
  tilted.up_board = (a.up_board + std::tan(deg2rad(2.0)) * a.up_board.unitOrthogonal()).normalized();
  tilted.axis_point_board = at_antenna;
  tilted.low_m = a.low_m - 1.0, tilted.high_m = a.high_m - 1.0;
  EXPECT_FALSE(same_mast(a, tilted, antenna, 0.01));
  Mast wider = a;
  wider.radius_m += 0.015;
  EXPECT_FALSE(same_mast(a, wider, antenna, 0.01));
  Mast taller = a;
  taller.high_m += 0.3;
  EXPECT_FALSE(same_mast(a, taller, antenna, 0.01));
}

}  // namespace
}  // namespace antpose::reconstruction
