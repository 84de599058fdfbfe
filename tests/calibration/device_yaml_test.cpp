// The extended device calibration file: misalignment/scale of both inertial sensors and the
// fit diagnostics round-trip; version-1 files without them read as the earlier model.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/imu/imu_calibration.hpp"
#include "support/test_support.hpp"

namespace antpose::imu {
namespace {

using ::testing::HasSubstr;

TEST(DeviceYaml, NineParameterModelsRoundTripAndApply) {
  test::TempDir dir;
  ImuCalibration c;
  c.acc_bias = Vec3(0.1, -0.2, 0.3);
  c.acc_scale = Vec3(1.01, 0.99, 1.002);
  c.acc_misalignment << 1, -0.003, 0.009, 0, 1, -0.02, 0, 0, 1;
  c.gyro_bias = Vec3(0.001, -0.06, 0.05);
  c.gyro_scale = Vec3(1.046, 1.049, 1.047);
  c.gyro_misalignment << 1, 0.006, 0.001, 0.008, 1, -0.05, 0.025, -0.0025, 1;
  c.mag_field_uT = 53.2;
  c.acc_residual_rms_m_s2 = 0.001;
  write_imu_calibration(c, dir / "d.yaml");
  const auto r = read_imu_calibration(dir / "d.yaml");
  EXPECT_EQ(r.acc_misalignment, c.acc_misalignment);
  EXPECT_EQ(r.gyro_misalignment, c.gyro_misalignment);
  EXPECT_EQ(r.gyro_scale, c.gyro_scale);
  EXPECT_EQ(*r.mag_field_uT, 53.2);
  Capture capture;
  const Vec3 raw(1.0, 2.0, 9.0);
  capture.streams["accelerometer"] = Stream::vector3("accelerometer", {0.0}, {raw});
  capture.streams["gyroscope"] = Stream::vector3("gyroscope", {0.0}, {raw});
  apply(r, capture);
  const Vec3 a = capture.streams["accelerometer"].xyz(0), w = capture.streams["gyroscope"].xyz(0);
  EXPECT_LT((a - c.acc_misalignment * c.acc_scale.asDiagonal() * (raw - c.acc_bias)).norm(), 1e-12);
  EXPECT_LT((w - c.gyro_misalignment * c.gyro_scale.asDiagonal() * (raw - c.gyro_bias)).norm(), 1e-12);
}

TEST(DeviceYaml, OldFilesReadAsScaleAndBiasOnly) {
  const auto c = parse_imu_calibration(
      "format: antpose-device\nversion: 1\nimu:\n  accelerometer: {bias_m_s2: [1, 2, 3], scale: [1.1, 1, 1]}\n"
      "  gyroscope: {bias_rad_s: [0.1, 0, 0]}\n",
      "old.yaml");
  EXPECT_EQ(c.acc_misalignment, Mat3::Identity());
  EXPECT_EQ(c.gyro_scale, Vec3::Ones());
  EXPECT_EQ(c.correct_acc(Vec3(2, 2, 3)), Vec3(1.1, 0, 0));
}

TEST(DeviceYaml, BadMisalignmentNamesLineAndExpectation) {
  try {
    parse_imu_calibration("format: antpose-device\nversion: 1\nimu:\n  gyroscope:\n    misalignment: [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]\n",
                          "bad.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 5u);
    EXPECT_THAT(e.what(), HasSubstr("imu.gyroscope.misalignment has diagonal [1, 1, 1] and largest off-diagonal 0.5"));
    EXPECT_THAT(e.what(), HasSubstr("expected a unit diagonal"));
  }
  try {
    parse_imu_calibration("format: antpose-device\nversion: 1\nimu:\n  gyroscope:\n    scale: [1, 3, 1]\n", "bad.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu.gyroscope.scale = [1, 3, 1], expected factors between 0.5 and 2"));
  }
}

}  // namespace
}  // namespace antpose::imu
