#include "antpose/imu/hard_iron.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/sim/imu_simulator.hpp"
#include "support/test_support.hpp"

namespace antpose::imu {
namespace {

using ::testing::HasSubstr;

TEST(HardIron, RecoversSimulatedOffsetFromATumble) {
  sim::ImuSimulation s;
  s.trajectory = sim::tumble(60.0, 1.5, 11);
  s.phone = sim::PhoneModel::typical();
  s.phone.magnetometer.hard_iron_uT = Vec3(30.0, -20.0, 45.0);
  s.phone.magnetometer.soft_iron = Mat3::Identity();
  const Capture c = sim::simulate_imu(s);
  const auto est = estimate_hard_iron(c.require("magnetometer"));
  EXPECT_LT((est.hard_iron_uT - Vec3(30.0, -20.0, 45.0)).norm(), 2.0) << est.hard_iron_uT.transpose();
  EXPECT_NEAR(est.field_uT, s.field_world_uT.norm(), 1.5);
  EXPECT_GT(est.coverage.minCoeff(), 0.7);
}

TEST(HardIron, RealFullSphereRecordingMatchesTheSphereFit) {
  // HMC5883L tumble (../shared/data/imu-calibration/README.md): sphere-fit hard iron
  // (−1.171, −11.035, 2.114) µT. (max+min)/2 lands within a few tenths of a µT.
  Diagnostics diag;
  const Capture c = read_capture(test::shared_path("data/imu-calibration/hmc5883l-mpu6050-full-sphere"), diag);
  const auto est = estimate_hard_iron(c.require("magnetometer"));
  EXPECT_NEAR(est.hard_iron_uT.x(), -1.171, 0.6);
  EXPECT_NEAR(est.hard_iron_uT.y(), -11.035, 0.6);
  EXPECT_NEAR(est.hard_iron_uT.z(), 2.114, 0.6);
}

TEST(HardIron, RefusesARecordingThatWasNotTurned) {
  sim::ImuSimulation s;
  s.trajectory = sim::Trajectory(Mat3::Identity()).hold(3.0).rotate_to(rot_z(deg2rad(90.0)), 3.0).hold(3.0);
  s.phone.magnetometer.hard_iron_uT = Vec3(10.0, 0.0, 0.0);
  const Capture c = sim::simulate_imu(s);
  try {
    estimate_hard_iron(c.require("magnetometer"), {}, "calib-folder");
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("calib-folder"));
    EXPECT_THAT(e.what(), HasSubstr("not turned enough"));
    EXPECT_THAT(e.what(), HasSubstr("z: range"));
  }
  try {
    estimate_hard_iron(Stream::vector3("magnetometer", {0.0, 1.0}, {Vec3(1, 2, 3), Vec3(1, 2, 3)}));
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("at least 20 magnetometer samples"));
  }
}

}  // namespace
}  // namespace antpose::imu
