// antpose simulate imu: the CLI writes readable captures with truth and rejects bad options.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "antpose/geometry/attitude.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

using ::testing::HasSubstr;

TEST(SimulateCli, ContactPresetWritesSceneTruthAndWmmField) {
  test::TempDir dir;
  const auto out = (dir / "contact").string();
  const auto r = test::run_cli("simulate imu -o '" + out +
                               "' --preset contact --seed 3 --antenna-azimuth-deg 250 --antenna-downtilt-deg 4 "
                               "--antenna-roll-deg 1 --lat 48.14 --lon 11.58 --alt-m 520 --date 2025-06-01");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("accelerometer"));
  Diagnostics diag;
  const Capture c = read_capture(out, diag);
  EXPECT_EQ(c.kind, "contact");
  ASSERT_TRUE(c.site);
  EXPECT_DOUBLE_EQ(c.site->lat_deg, 48.14);
  ASSERT_TRUE(c.truth_orientation);
  const YAML::Node scene = YAML::Load(io::read_text(dir / "contact/truth/scene.yaml"));
  const auto antenna = scene["antennas"][0];
  EXPECT_NEAR(antenna["azimuth_deg"].as<double>(), 250.0, 1e-9);
  EXPECT_NEAR(antenna["downtilt_deg"].as<double>(), 4.0, 1e-9);
  EXPECT_NEAR(antenna["roll_deg"].as<double>(), 1.0, 1e-9);
  // Munich in 2025: declination ≈ +4.2° (WMM2025), so the magnetic azimuth is smaller.
  const double decl = antenna["declination_deg"].as<double>();
  EXPECT_NEAR(decl, 4.2, 0.5);
  EXPECT_NEAR(antenna["magnetic_azimuth_deg"].as<double>(), 250.0 - decl, 1e-9);
  const YAML::Node device = YAML::Load(io::read_text(dir / "contact/truth/device.yaml"));
  EXPECT_NEAR(device["gravity"].as<double>(), 9.807, 0.001);
  // The magnetometer magnitude is the site's field (≈ 48.8 µT) up to the phone's small errors.
  const Stream& mag = c.require(streams::kMagnetometer);
  EXPECT_NEAR(mag.xyz(0).norm(), 48.8, 3.0);
}

TEST(SimulateCli, SameSeedSameCaptureAndForceReplaces) {
  test::TempDir dir;
  const auto a = (dir / "a").string(), b = (dir / "b").string();
  ASSERT_EQ(test::run_cli("simulate imu -o '" + a + "' --preset tumble --duration 5 --phone random --seed 9").status, 0);
  ASSERT_EQ(test::run_cli("simulate imu -o '" + b + "' --preset tumble --duration 5 --phone random --seed 9").status, 0);
  EXPECT_EQ(io::read_text(dir / "a/sensors/gyroscope.csv"), io::read_text(dir / "b/sensors/gyroscope.csv"));
  EXPECT_EQ(io::read_text(dir / "a/truth/device.yaml"), io::read_text(dir / "b/truth/device.yaml"));
  const auto again = test::run_cli("simulate imu -o '" + a + "' --preset tumble --duration 5");
  EXPECT_EQ(again.status, 2);
  EXPECT_THAT(again.err, HasSubstr("already exists"));
  ASSERT_EQ(test::run_cli("simulate imu -o '" + a + "' --preset tumble --duration 5 --seed 10 --force").status, 0);
  EXPECT_NE(io::read_text(dir / "a/sensors/gyroscope.csv"), io::read_text(dir / "b/sensors/gyroscope.csv"));
}

TEST(SimulateCli, StaticPosesWithDisturbanceAndHardIron) {
  test::TempDir dir;
  const auto out = (dir / "s").string();
  const auto r = test::run_cli("simulate imu -o '" + out +
                               "' --phone ideal --duration 40 --hard-iron-uT 10,-20,30 --disturbance-uT 0,0,15 "
                               "--disturbance-window 2,3");
  ASSERT_EQ(r.status, 0) << r.err;
  Diagnostics diag;
  const Capture c = read_capture(out, diag);
  EXPECT_EQ(c.kind, "imu-calibration");
  const YAML::Node device = YAML::Load(io::read_text(dir / "s/truth/device.yaml"));
  EXPECT_EQ(device["magnetometer"]["hard_iron_uT"][1].as<double>(), -20.0);
  EXPECT_EQ(device["disturbances"][0]["extra_world_uT"][2].as<double>(), 15.0);
  EXPECT_NEAR(c.truth_orientation->t.back(), 40.0, 1e-9);
}

TEST(SimulateCli, BadOptionsNameTheOptionAndTheValue) {
  test::TempDir dir;
  const auto out = " -o '" + (dir / "x").string() + "'";
  auto r = test::run_cli("simulate imu" + out + " --hard-iron-uT 1,2");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--hard-iron-uT: '1,2' has 2 values, expected three numbers"));
  r = test::run_cli("simulate imu" + out + " --hard-iron-uT 1,a,3");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'1,a,3' is not a list of numbers"));
  r = test::run_cli("simulate imu" + out + " --disturbance-uT 1,2,3");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--disturbance-uT and --disturbance-window go together"));
  r = test::run_cli("simulate imu" + out + " --disturbance-uT 1,2,3 --disturbance-window 5,4");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'5,4': T0 must be before T1"));
  r = test::run_cli("simulate imu" + out + " --preset tumble --antenna-azimuth-deg 30");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("apply to '--preset contact' only"));
  r = test::run_cli("simulate imu" + out + " --preset contact --duration 3");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--duration: 3 s is too short for the contact preset"));
  r = test::run_cli("simulate imu" + out + " --preset contact --antenna-downtilt-deg 95");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--antenna-downtilt-deg: 95 must be within [-90, 90] deg"));
  // Values that once gave streams of NaN.
  r = test::run_cli("simulate imu" + out + " --preset contact --tremor-deg nan");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--tremor-deg: nan must be within [0, 10] deg"));
  r = test::run_cli("simulate imu" + out + " --preset contact --antenna-azimuth-deg 1e308");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--antenna-azimuth-deg: 1e308 must be within [-360, 360] deg"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x"));
  r = test::run_cli("simulate imu" + out + " --preset contact --placement sideways");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--placement"));
  EXPECT_THAT(r.err, HasSubstr("sideways"));
  r = test::run_cli("simulate imu" + out + " --lat 48");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--lat and --lon go together"));
  r = test::run_cli("simulate imu" + out + " --lat 48 --lon 11 --date 2025-13-01");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("2025-13-01"));
  r = test::run_cli("simulate imu" + out + " --preset static-poses --duration 10");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("too short for 18 poses"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x"));
}

}  // namespace
}  // namespace antpose
