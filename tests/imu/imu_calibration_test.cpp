#include "antpose/imu/imu_calibration.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/geometry/rotation.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::imu {
namespace {

using ::testing::HasSubstr;

TEST(ImuCalibration, RoundTripKeepsValuesAndUnknownKeys) {
  test::TempDir dir;
  ImuCalibration c;
  c.mag_hard_iron_uT = Vec3(12.5, -3.25, 40.0000001);
  c.mag_soft_iron << 1.01, 0.02, 0.0, 0.02, 0.98, -0.01, 0.0, -0.01, 1.03;
  c.mag_alignment = exp_so3(deg2rad(1.0) * Vec3(0.17, 0.12, -0.06));
  c.mag_alignment_sigma_rad = deg2rad(1.0) * Vec3(0.021, 0.018, 0.024);
  c.mag_hard_iron_sigma_uT = Vec3(0.011, 0.013, 0.012);
  c.mag_soft_iron_sigma = Mat3::Constant(2e-4);
  c.acc_bias = Vec3(0.05, -0.1, 0.2);
  c.acc_scale = Vec3(1.001, 0.999, 1.0);
  c.gyro_bias = Vec3(1e-3, -2e-3, 3e-3);
  c.device_model = "Pixel 7";
  c.document = YAML::Load("later_section: {a: 1}\nformat: antpose-device\n");
  write_imu_calibration(c, dir / "phone.yaml");
  const std::string text = io::read_text(dir / "phone.yaml");
  EXPECT_THAT(text, HasSubstr("format: antpose-device"));
  EXPECT_THAT(text, HasSubstr("hard_iron_uT"));
  const ImuCalibration r = read_imu_calibration(dir / "phone.yaml");
  EXPECT_EQ(r.mag_hard_iron_uT, c.mag_hard_iron_uT);
  EXPECT_EQ(r.mag_soft_iron, c.mag_soft_iron);
  EXPECT_LT((r.mag_alignment - c.mag_alignment).cwiseAbs().maxCoeff(), 1e-15);
  ASSERT_TRUE(r.mag_alignment_sigma_rad);
  EXPECT_LT((*r.mag_alignment_sigma_rad - *c.mag_alignment_sigma_rad).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(r.mag_hard_iron_sigma_uT, c.mag_hard_iron_sigma_uT);
  EXPECT_EQ(r.mag_soft_iron_sigma, c.mag_soft_iron_sigma);
  EXPECT_EQ(r.acc_bias, c.acc_bias);
  EXPECT_EQ(r.acc_scale, c.acc_scale);
  EXPECT_EQ(r.gyro_bias, c.gyro_bias);
  EXPECT_EQ(r.device_model, "Pixel 7");
  EXPECT_EQ(r.document["later_section"]["a"].as<int>(), 1);
}

TEST(ImuCalibration, MissingEntriesAreNeutral) {
  const auto c = parse_imu_calibration("format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_uT: [1, 2, 3]\n",
                                       "x.yaml");
  EXPECT_EQ(c.mag_hard_iron_uT, Vec3(1, 2, 3));
  EXPECT_EQ(c.mag_soft_iron, Mat3::Identity());
  EXPECT_EQ(c.mag_alignment, Mat3::Identity());
  EXPECT_FALSE(c.mag_alignment_sigma_rad);
  EXPECT_EQ(c.acc_scale, Vec3::Ones());
  EXPECT_EQ(c.gyro_bias, Vec3::Zero());
}

struct BadFile {
  const char* text;
  const char* message;
};

class ImuCalibrationBad : public ::testing::TestWithParam<BadFile> {};

TEST_P(ImuCalibrationBad, NamesFileLineAndExpectation) {
  test::TempDir dir;
  const auto file = dir / "bad.yaml";
  test::write_file(file, GetParam().text);
  try {
    read_imu_calibration(file);
    FAIL() << "accepted: " << GetParam().text;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.yaml"));
    EXPECT_THAT(e.what(), HasSubstr(GetParam().message));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ImuCalibrationBad,
    ::testing::Values(
        BadFile{"format: antpose-capture\nversion: 1\nimu: {}\n",
                "bad.yaml:1: format is 'antpose-capture', expected 'antpose-device'"},
        BadFile{"version: 1\n", "no 'format' key"},
        BadFile{"format: antpose-device\nversion: 7\nimu: {}\n", "bad.yaml:2: format version 7 is not supported"},
        BadFile{"format: antpose-device\nversion: 1\n", "no 'imu' section"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_uT: [1, 2]\n",
                "bad.yaml:5: imu.magnetometer.hard_iron_uT is a list of 2, expected a list of 3 numbers"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  accelerometer:\n    bias_m_s2: [0.1,\n      abc, 0]\n",
                "bad.yaml:6: imu.accelerometer.bias_m_s2[1]: 'abc' is not a number"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    soft_iron: [[0,0,0],[0,1,0],[0,0,1]]\n",
                "bad.yaml:5: imu.magnetometer.soft_iron has determinant 0"},
        BadFile{
            "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    alignment: [[1,0,0],[0,1,0],[0,0,-1]]\n",
            "bad.yaml:5: imu.magnetometer.alignment is not a small rotation (RᵀR − I off by 0, determinant -1.000, "
            "angle 90.0°); expected a rotation within 10° of the identity"},
        BadFile{
            "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    alignment: [[1,0.1,0],[0,1,0],[0,0,1]]\n",
            "imu.magnetometer.alignment is not a small rotation (RᵀR − I off by 0.14"},
        BadFile{
            "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    alignment_sigma_deg: [0.02, -0.01, 0.02]\n",
            "bad.yaml:5: imu.magnetometer.alignment_sigma_deg is (0.02, -0.01, 0.02); expected 1σ per axis in "
            "degrees, each from 0 to 10"},
        BadFile{
            "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_sigma_uT: [0.01, 0.01, 500]\n",
            "bad.yaml:5: imu.magnetometer.hard_iron_sigma_uT is (0.01, 0.01, 500); expected 1σ per axis in µT, "
            "each from 0 to 100"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n"
                "    soft_iron_sigma: [[0.001, 0.002, 0], [0, 0.001, 0], [0, 0, 0.001]]\n",
                "bad.yaml:5: imu.magnetometer.soft_iron_sigma has entries from 0 to 0.002; expected a symmetric 3×3 "
                "of 1σ per soft-iron entry, each from 0 to 1"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_uT: [20000, 0, 0]\n",
                "was it written in nT?"},
        BadFile{"format: antpose-device\nversion: 1\nimu:\n  accelerometer:\n    scale: [9.81, 1, 1]\n",
                "expected factors between 0.5 and 2"},
        BadFile{"format: antpose-device\nversion: 1\nimu: [1, 2]\n",
                "bad.yaml:3: 'imu' is a list of 2, expected a map"},
        BadFile{"format: antpose-device\nversion: 1\nimu: {magnetometer: [\n", "not valid YAML"},
        // A map where a name belongs is bad input like any other.
        BadFile{"format: antpose-device\nversion: 1\ndevice:\n  id: {a: 1}\nimu: {}\n", "bad.yaml:4: device.id"}));

TEST(ImuCalibration, MissingFile) {
  test::TempDir dir;
  EXPECT_THROW(read_imu_calibration(dir / "none.yaml"), InputError);
}

TEST(ImuCalibration, ApplyCorrectsTheStreams) {
  Capture c;
  c.streams["magnetometer"] = Stream::vector3("magnetometer", {0.0}, {Vec3(11, 22, 33)});
  c.streams["accelerometer"] = Stream::vector3("accelerometer", {0.0}, {Vec3(1, 2, 10)});
  c.streams["gyroscope"] = Stream::vector3("gyroscope", {0.0}, {Vec3(0.1, 0.2, 0.3)});
  ImuCalibration cal;
  cal.mag_hard_iron_uT = Vec3(1, 2, 3);
  cal.mag_soft_iron = Vec3(2, 1, 0.5).asDiagonal();
  cal.acc_bias = Vec3(0, 0, 0.2);
  cal.acc_scale = Vec3(1, 1, 1.0 / 0.98);
  cal.gyro_bias = Vec3(0.1, 0.1, 0.1);
  cal.mag_alignment = rot_z(M_PI / 2);  // after the soft iron: (20, 20, 15) turned to (−20, 20, 15)
  apply(cal, c);
  EXPECT_TRUE(c.streams["magnetometer"].xyz(0).isApprox(Vec3(-20, 20, 15)));
  EXPECT_TRUE(c.streams["accelerometer"].xyz(0).isApprox(Vec3(1, 2, 10)));
  EXPECT_TRUE(c.streams["gyroscope"].xyz(0).isApprox(Vec3(0, 0.1, 0.2)));
}

}  // namespace
}  // namespace antpose::imu
