#include "antpose/imu/static_detector.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/sim/imu_simulator.hpp"

namespace antpose::imu {
namespace {

using ::testing::HasSubstr;

Capture simulate(const sim::Trajectory& trajectory, std::uint64_t seed = 3) {
  sim::ImuSimulation s;
  s.trajectory = trajectory;
  s.phone = sim::PhoneModel::typical();
  s.seed = seed;
  return sim::simulate_imu(s);
}

TEST(StaticDetector, FindsTheHoldsOfAMoveSequence) {
  const Mat3 R0 = Mat3::Identity();
  const Mat3 R1 = rot_x(deg2rad(80.0)) * rot_z(deg2rad(30.0));
  const Mat3 R2 = rot_y(deg2rad(60.0));
  sim::Trajectory tr(R0);
  tr.hold(2.0).rotate_to(R1, 2.0).hold(5.0).rotate_to(R2, 2.0).hold(1.5);
  const auto d = detect_static(simulate(tr));
  ASSERT_EQ(d.windows.size(), 3u);
  EXPECT_TRUE(d.used_gyroscope);
  EXPECT_FALSE(d.used_magnetometer);
  // Longest first: the 5 s hold [4, 9]. Minimum-jerk moves start and end slowly, so the
  // detected edges may reach a little into the moves.
  EXPECT_NEAR(d.windows[0].t0, 4.0, 0.35);
  EXPECT_NEAR(d.windows[0].t1, 9.0, 0.35);
  EXPECT_NEAR(d.windows[1].t0, 0.0, 0.1);
  EXPECT_NEAR(d.windows[1].t1, 2.0, 0.35);
  EXPECT_GE(d.windows[0].duration(), d.windows[1].duration());
  EXPECT_GE(d.windows[1].duration(), d.windows[2].duration());
  // The bias estimate is the typical phone's gyroscope bias (0.15, −0.10, 0.20 °/s).
  EXPECT_NEAR(rad2deg(d.gyro_bias.x()), 0.15, 0.05);
  EXPECT_NEAR(rad2deg(d.gyro_bias.z()), 0.20, 0.05);
}

TEST(StaticDetector, SlowRotationAboutGravityIsNotStatic) {
  // 90° about the vertical in 5 s: the accelerometer does not see it.
  sim::Trajectory tr(Mat3::Identity());
  tr.hold(3.0).rotate_to(rot_z(deg2rad(90.0)), 5.0).hold(3.0);
  const Capture c = simulate(tr);
  auto moving_inside = [](const StaticDetection& d) {
    for (const auto& w : d.windows)
      if (w.t1 > 4.5 && w.t0 < 6.5) return true;
    return false;
  };
  const auto with_gyro = detect_static(c);
  EXPECT_FALSE(moving_inside(with_gyro));

  Capture no_gyro = c;
  no_gyro.streams.erase("gyroscope");
  const auto d = detect_static(no_gyro);
  EXPECT_FALSE(d.used_gyroscope);
  EXPECT_TRUE(d.used_magnetometer);
  ASSERT_EQ(d.notes.size(), 1u);
  EXPECT_THAT(d.notes[0], HasSubstr("accelerometer + magnetometer criteria only"));
  EXPECT_FALSE(moving_inside(d));
  // Accelerometer alone cannot see it, and says so.
  no_gyro.streams.erase("magnetometer");
  const auto acc_only = detect_static(no_gyro);
  EXPECT_TRUE(moving_inside(acc_only));
  EXPECT_THAT(acc_only.notes.at(0), HasSubstr("rotation about gravity is not detected"));
}

TEST(StaticDetector, ContinuousMotionHasNoWindow) {
  const Capture c = simulate(sim::tumble(12.0, 1.5, 5));
  const auto d = detect_static(c);
  for (const auto& w : d.windows) EXPECT_LT(w.duration(), 1.6) << w.t0 << " " << w.t1;  // only the 1 s ends
}

TEST(StaticDetector, NeedsAnAccelerometer) {
  Capture c = simulate(sim::Trajectory(Mat3::Identity()).hold(3.0));
  c.streams.erase("accelerometer");
  try {
    detect_static(c);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no accelerometer stream"));
  }
}

TEST(StaticDetector, AsynchronousStreamsWithAGap) {
  // A gap of 1.5 s in the accelerometer splits a long hold in two.
  Capture c = simulate(sim::Trajectory(Mat3::Identity()).hold(10.0));
  Stream& acc = c.streams.at("accelerometer");
  std::vector<double> t;
  std::vector<Vec3> v;
  for (std::size_t i = 0; i < acc.size(); ++i)
    if (acc.t[i] < 4.0 || acc.t[i] > 5.5) {
      t.push_back(acc.t[i]);
      v.push_back(acc.xyz(i));
    }
  acc = Stream::vector3("accelerometer", t, v);
  const auto d = detect_static(c);
  ASSERT_EQ(d.windows.size(), 2u);
  EXPECT_LT(d.windows[0].t1 - d.windows[0].t0, 6.0);
  for (const auto& w : d.windows) EXPECT_TRUE(w.t1 <= 4.6 || w.t0 >= 4.9) << w.t0 << " " << w.t1;
}

}  // namespace
}  // namespace antpose::imu
