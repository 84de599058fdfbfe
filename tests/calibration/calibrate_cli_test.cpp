// antpose calibrate imu / allan: end to end, and every bad input with its message.
#include <unistd.h>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/imu/imu_calibration.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "support/test_support.hpp"

namespace antpose::calibration {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

fs::path write_sim(const test::TempDir& dir, const std::string& name, const sim::Trajectory& trajectory, bool drop_acc = false) {
  std::mt19937_64 rng(21);
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::random(rng);
  sim.kind = "imu-calibration";
  sim.trajectory = trajectory;
  Capture capture = sim::simulate_imu(sim);
  if (drop_acc) capture.streams.erase(std::string(streams::kAccelerometer));
  const fs::path folder = dir / name;
  write_capture(capture, folder);
  return folder;
}

TEST(CalibrateCli, WritesDeviceYamlAndPrintsResiduals) {
  test::TempDir dir;
  const auto cap = write_sim(dir, "cal", sim::static_poses(sim::calibration_poses(), 3.0, 2.0));
  const auto out = dir / "device.yaml";
  const auto r = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors acc,gyro", cap.string(), out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("accelerometer (18 static frames"));
  EXPECT_THAT(r.out, HasSubstr("residual RMS(|a| - g)  before"));
  EXPECT_THAT(r.out, HasSubstr("gyroscope (17 moves"));
  const auto c = imu::read_imu_calibration(out);
  EXPECT_NE(c.acc_misalignment, Mat3::Identity());
  EXPECT_NE(c.gyro_scale, Vec3::Ones());
  ASSERT_TRUE(c.acc_residual_rms_m_s2);
  EXPECT_LT(*c.acc_residual_rms_m_s2, 0.005);
  EXPECT_FALSE(c.document["imu"]["magnetometer"]);  // not calibrated, not claimed
  // A second run on the magnetometer alone keeps the accelerometer and gyroscope sections.
  const auto tumble = write_sim(dir, "tumble", sim::tumble(40.0, 1.5, 4));
  const auto r2 = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors mag", tumble.string(), out.string()));
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_THAT(r2.out, HasSubstr("field strength"));
  const auto c2 = imu::read_imu_calibration(out);
  EXPECT_EQ(c2.acc_bias, c.acc_bias);
  EXPECT_EQ(c2.gyro_misalignment, c.gyro_misalignment);
  EXPECT_TRUE(c2.mag_field_uT);
  // Aligned to the accelerometer just calibrated, with each fit's σ for the compass.
  EXPECT_NE(c2.mag_alignment, Mat3::Identity());
  ASSERT_TRUE(c2.mag_alignment_sigma_rad && c2.mag_hard_iron_sigma_uT && c2.mag_soft_iron_sigma);
  EXPECT_GT(rad2deg(c2.mag_alignment_sigma_rad->minCoeff()), 0.001);
  EXPECT_LT(rad2deg(c2.mag_alignment_sigma_rad->maxCoeff()), 0.2);
  EXPECT_GT(c2.mag_hard_iron_sigma_uT->minCoeff(), 0.001);
  EXPECT_LT(c2.mag_hard_iron_sigma_uT->maxCoeff(), 0.1);
  EXPECT_GT(c2.mag_soft_iron_sigma->minCoeff(), 1e-5);
  EXPECT_LT(c2.mag_soft_iron_sigma->maxCoeff(), 1e-2);
}

TEST(CalibrateCli, TooFewStaticFramesSaysFoundAndNeededAndKeepsOldFile) {
  test::TempDir dir;
  const std::vector<Mat3> all = sim::calibration_poses();
  const std::vector<Mat3> four(all.begin(), all.begin() + 4);
  const auto cap = write_sim(dir, "four", sim::static_poses(four, 3.0, 2.0));
  const auto out = dir / "device.yaml";
  test::write_file(out, "format: antpose-device\nversion: 1\nimu:\n  gyroscope:\n    bias_rad_s: [0.1, 0.2, 0.3]\n");
  const std::string before = io::read_text(out);
  const auto r = test::run_cli(fmt::format("calibrate imu {} -o {}", cap.string(), out.string()));
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("found 4 static frames, need at least 6"));
  EXPECT_THAT(r.err, HasSubstr("the existing " + out.string() + " was kept unchanged"));
  EXPECT_EQ(io::read_text(out), before);
}

TEST(CalibrateCli, CaptureWithoutAccelerometer) {
  test::TempDir dir;
  const auto cap = write_sim(dir, "noacc", sim::static_poses(sim::calibration_poses(), 1.0, 1.0), true);
  const auto r = test::run_cli(fmt::format("calibrate imu {} -o {}", cap.string(), (dir / "d.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("accelerometer"));
  EXPECT_THAT(r.err, HasSubstr("was not written"));
  EXPECT_FALSE(fs::exists(dir / "d.yaml"));
}

TEST(CalibrateCli, MagnetometerWithoutCoverage) {
  test::TempDir dir;
  std::vector<Mat3> poses;
  for (int k = 0; k < 12; ++k) poses.push_back(rot_z(k * M_PI / 6));
  const auto cap = write_sim(dir, "spin", sim::static_poses(poses, 1.0, 1.0));
  const auto r = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors mag", cap.string(), (dir / "d.yaml").string()));
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("magnetometer calibration: poor coverage"));
}

TEST(CalibrateCli, BadOutputPathsAndOptions) {
  test::TempDir dir;
  const auto cap = write_sim(dir, "cal", sim::static_poses(sim::calibration_poses(), 2.5, 1.0));
  auto r = test::run_cli(fmt::format("calibrate imu {} -o {}", cap.string(), (dir / "missing" / "d.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("does not exist; create it first"));
  r = test::run_cli(fmt::format("calibrate imu {} -o {}", cap.string(), dir.path().string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("is a folder"));
  test::write_file(dir / "notes.yaml", "shopping: [milk]\n");
  r = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors acc", cap.string(), (dir / "notes.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("not a valid antpose device calibration"));
  EXPECT_THAT(r.err, HasSubstr("--force"));
  EXPECT_EQ(io::read_text(dir / "notes.yaml"), "shopping: [milk]\n");
  r = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors acc --force", cap.string(), (dir / "notes.yaml").string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(io::read_text(dir / "notes.yaml"), HasSubstr("format: antpose-device"));
  r = test::run_cli(fmt::format("calibrate imu {} -o {} --sensors acc,compass", cap.string(), (dir / "x.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'compass' is not a sensor"));
  r = test::run_cli(fmt::format("calibrate imu {} -o {} --error-model magic", cap.string(), (dir / "x.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--error-model: magic not in {thesis,full}"));
  // The option's name before it was --error-model is refused with the new name.
  r = test::run_cli(fmt::format("calibrate imu {} -o {} --method full", cap.string(), (dir / "x.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--method: this option is now called --error-model (given 'full')"));
}

TEST(CalibrateCli, ReadOnlyFolderIsAnInputError) {
  test::TempDir dir;
  const auto cap = write_sim(dir, "cal", sim::static_poses(sim::calibration_poses(), 2.5, 1.0));
  fs::create_directory(dir / "ro");
  fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                  fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const auto r = test::run_cli_unprivileged(
      fmt::format("calibrate imu {} -o {} --sensors acc", cap.string(), (dir / "ro" / "d.yaml").string()));
  fs::permissions(dir / "ro", fs::perms::owner_all);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("ro/d.yaml: cannot create a file in its folder (Permission denied)"));
}

TEST(CalibrateCli, AllanWritesJsonAndPlot) {
  test::TempDir dir;
  sim::Trajectory still(Mat3::Identity());
  still.hold(Mat3::Identity(), 60.0);
  const auto cap = write_sim(dir, "still", still);
  const auto r = test::run_cli(fmt::format("calibrate allan {} --json {} --plot {}", cap.string(), (dir / "a.json").string(),
                                           (dir / "a.svg").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("overlapping Allan deviation of 'gyroscope'"));
  EXPECT_THAT(io::read_text(dir / "a.json"), HasSubstr("white_noise"));
  EXPECT_THAT(io::read_text(dir / "a.svg"), HasSubstr("<svg"));
  const auto bad = test::run_cli(fmt::format("calibrate allan {} --stream barometer", cap.string()));
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("barometer"));
}

}  // namespace
}  // namespace antpose::calibration
