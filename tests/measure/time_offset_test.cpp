#include "antpose/measure/time_offset.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

// A phone turning between holds of `hold_s` by minimum-jerk turns of 1 s, each by another angle
// about another axis (a walk's turns differ, so photos pushed into them disagree), the photos in
// the middle of the holds. The board is fixed (R_world_board = I), so each photo's R_camera_board
// follows from the phone's attitude at its true instant.
struct Walk {
  orientation::OrientationTrack track;
  std::vector<BoardPhoto> photos;
};

Mat3 attitude_at(double t, double hold_s) {
  const double period = hold_s + 1.0;
  Mat3 R = Mat3::Identity();
  for (int k = 0; t > k * period + hold_s; ++k) {
    const double s = std::min(1.0, t - k * period - hold_s);  // 0..1 during turn k
    const double jerk = s * s * s * (10 - 15 * s + 6 * s * s);
    const Vec3 axis = Vec3(std::sin(1.7 * k), std::cos(2.3 * k), 2.0).normalized();
    R = R * exp_so3(deg2rad(15.0 + 7.0 * (k % 3)) * jerk * axis);
  }
  return R;
}

Walk walk(double hold_s, double true_offset_s) {
  Walk w;
  const Mat3 R_device_camera = Vec3(1.0, -1.0, -1.0).asDiagonal();
  for (double t = 0.0; t <= 12.0; t += 0.01) w.track.push_back(t, Quat(attitude_at(t, hold_s)));
  for (int k = 0; k < 8; ++k) {
    const double t_true = k * (hold_s + 1.0) + 0.5 * hold_s;
    const Mat3 R_world_camera = attitude_at(t_true, hold_s) * R_device_camera;
    BoardPhoto p;
    p.name = "photo " + std::to_string(k);
    p.t_shot = t_true - true_offset_s;
    p.R_camera_board = R_world_camera.transpose();
    w.photos.push_back(p);
  }
  return w;
}

CameraImu with_offset(double offset_s) {
  CameraImu c;
  c.R_device_camera = Vec3(1.0, -1.0, -1.0).asDiagonal();
  c.time_offset_s = offset_s;
  return c;
}

TEST(TimeOffset, AnOffsetThatPutsPhotosIntoTheTurnsIsReplacedByOneInsideTheHolds) {
  // The device's offset 0.4 s late puts every photo a quarter into the turn after its hold.
  const Walk w = walk(0.4, 0.05);
  const auto check = check_time_offset(w.photos, w.track, with_offset(0.45), {});
  EXPECT_TRUE(check.checked);
  EXPECT_FALSE(check.device_consistent);
  EXPECT_GT(check.spread_at_device_rad, deg2rad(0.5));
  // Every photo inside its hold (±0.2 s about the truth); the range reaches a little into the
  // turns, whose first tenth of a second turns the phone by hundredths of a degree.
  EXPECT_LT(std::abs(check.used_s - 0.05), 0.2);
  EXPECT_LE(check.consistent_low_s, check.used_s);
  EXPECT_GE(check.consistent_high_s, check.used_s);
  EXPECT_LT(check.consistent_high_s, 0.05 + 0.35);
  ASSERT_EQ(check.warnings.size(), 1u);
  EXPECT_NE(check.warnings[0].find("+450 ms"), std::string::npos) << check.warnings[0];
}

TEST(TimeOffset, TheDevicesOffsetStandsWhereThePhotosAgreeWithIt) {
  const Walk w = walk(0.8, 0.03);
  const auto check = check_time_offset(w.photos, w.track, with_offset(0.06), {});
  EXPECT_TRUE(check.device_consistent);
  EXPECT_DOUBLE_EQ(check.used_s, 0.06);
  EXPECT_TRUE(check.warnings.empty());
}

TEST(TimeOffset, TooFewPhotosOrDisabledLeaveTheDevicesOffset) {
  Walk w = walk(0.4, 0.0);
  w.photos.resize(2);
  EXPECT_FALSE(check_time_offset(w.photos, w.track, with_offset(0.2), {}).checked);
  TimeOffsetOptions off;
  off.enabled = false;
  const Walk all = walk(0.4, 0.0);
  const auto check = check_time_offset(all.photos, all.track, with_offset(0.2), off);
  EXPECT_FALSE(check.checked);
  EXPECT_DOUBLE_EQ(check.used_s, 0.2);
  off.step_s = 0.0;
  EXPECT_THROW(check_time_offset(all.photos, all.track, with_offset(0.2), off), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::measure
