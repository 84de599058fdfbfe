// The scale checks: the walk's speed and the region's extent against the model.
#include "antpose/measure/scale_check.hpp"

#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

// Photos every `interval_s` from cameras `step_m` apart along x, each looking at the board.
struct WalkFixture {
  Capture capture;
  CameraPoses poses;
};

WalkFixture walk(double step_m, double interval_s, int photos) {
  WalkFixture w;
  for (int i = 0; i < photos; ++i) {
    Shot shot;
    shot.index = i;
    shot.t = 3.0 + interval_s * i;
    w.capture.shots.push_back(shot);
    reconstruction::PosedView view;
    const Vec3 centre(step_m * i, -4.0, 1.5);
    view.R_camera_board = rot_x(1.2) * rot_z(0.1 * i);
    view.t_camera_board = -view.R_camera_board * centre;
    w.poses.views.push_back(view);
    w.poses.shot_of_view.push_back(static_cast<std::size_t>(i));
  }
  return w;
}

camera::BoardSpec board(double square_m) {
  camera::BoardSpec b;
  b.cols = 9, b.rows = 6, b.square_m = square_m;
  return b;
}

TEST(WalkScale, AWalkingPaceIsQuietAndTenfoldLengthsAreNamed) {
  const auto slow = walk(1.5, 2.0, 8);  // 0.75 m/s
  const WalkScale ok = check_walk_scale(slow.capture, slow.poses, board(0.07));
  ASSERT_TRUE(ok.median_speed_m_s);
  EXPECT_NEAR(*ok.median_speed_m_s, 0.75, 1e-9);
  EXPECT_FALSE(ok.warning);

  const auto fast = walk(15.0, 2.0, 8);  // the same walk with square_m ten times too large
  const WalkScale bad = check_walk_scale(fast.capture, fast.poses, board(0.7));
  ASSERT_TRUE(bad.warning);
  EXPECT_THAT(*bad.warning, HasSubstr("median 7.5 m/s between photos"));
  EXPECT_THAT(*bad.warning, HasSubstr("check square_m (0.7 m in board.yaml)"));
}

TEST(WalkScale, PhotosInABurstOrTooFewSayNothing) {
  const auto burst = walk(1.0, 0.2, 8);  // 5 m/s, but 0.2 s apart: left out
  EXPECT_FALSE(check_walk_scale(burst.capture, burst.poses, board(0.07)).median_speed_m_s);
  const auto two = walk(30.0, 1.0, 2);
  EXPECT_FALSE(check_walk_scale(two.capture, two.poses, board(0.07)).warning);
}

// Points along a panel of `length_m` (z), a little depth noise, a few strays.
std::vector<Vec3> panel_points(double length_m) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> along(-0.5 * length_m, 0.5 * length_m), across(-0.15, 0.15);
  std::vector<Vec3> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(across(rng), 0.01 * across(rng), along(rng));
  for (int i = 0; i < 5; ++i) points.emplace_back(0.0, 0.0, 3.0 * length_m);  // strays beyond the 98th percentile
  return points;
}

TEST(ModelScaleHint, NamesAFactorOnlyFarFromTheModelsLength) {
  const auto model = model::builtin_panel("panel-2000x300x150");
  EXPECT_FALSE(model_scale_hint(panel_points(2.0), model, board(0.07)));
  EXPECT_FALSE(model_scale_hint(panel_points(1.3), model, board(0.07)));  // part of a plain radome
  const auto half = model_scale_hint(panel_points(1.0), model, board(0.035));
  ASSERT_TRUE(half);
  EXPECT_THAT(*half, HasSubstr("span 0.9"));
  EXPECT_THAT(*half, HasSubstr("where the model is 2.00 m long"));
  EXPECT_THAT(*half, HasSubstr("square_m (0.035 m in board.yaml)"));
  EXPECT_TRUE(model_scale_hint(panel_points(4.0), model, board(0.14)));
  EXPECT_FALSE(model_scale_hint({Vec3::Zero(), Vec3::UnitZ()}, model, board(0.07)));  // too few points
}

}  // namespace
}  // namespace antpose::measure
