// antpose convert / inspect: exit codes and messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(CliConvert, SensorLoggerToNativeThenInspect) {
  test::TempDir dir;
  const fs::path in = test::shared_path("data/phone-logs/android-sensorlogger-walk");
  const fs::path out = dir / "walk";
  auto r = test::run_cli(fmt::format("convert '{}' '{}' --gzip", in.string(), out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("converted sensor-logger capture"));
  EXPECT_THAT(r.err, HasSubstr("warning: "));
  EXPECT_TRUE(fs::exists(out / "sensors" / "accelerometer.csv.gz"));

  r = test::run_cli(fmt::format("inspect '{}' --json '{}'", out.string(), (dir / "s.json").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("format:       native"));
  EXPECT_THAT(r.out, HasSubstr("accelerometer: 2908 samples"));
  EXPECT_THAT(r.out, HasSubstr("magnetometer: 1402 samples"));
  EXPECT_THAT(r.out, HasSubstr("time origin:  2024-03-27T07:13:15.018936600Z"));
  const auto j = nlohmann::json::parse(io::read_text(dir / "s.json"));
  EXPECT_EQ(j["device"]["model"], "22041211AC");

  // Converting again into the existing folder refuses and leaves it intact; --force replaces it.
  const auto before = io::read_text(out / "capture.yaml");
  r = test::run_cli(fmt::format("convert '{}' '{}'", in.string(), out.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("already exists"));
  EXPECT_EQ(io::read_text(out / "capture.yaml"), before);
  r = test::run_cli(fmt::format("convert '{}' '{}' --force", in.string(), out.string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "sensors" / "accelerometer.csv"));
}

TEST(CliInspect, PhyphoxDirectAndBadInput) {
  auto r = test::run_cli(fmt::format("inspect '{}'", test::shared_path("data/phone-logs/phyphox-climbing").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("format:       phyphox"));
  EXPECT_THAT(r.out, HasSubstr("device:       iPhone10,5"));
  test::TempDir dir;
  r = test::run_cli(fmt::format("inspect '{}'", dir.path().string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("error: "));
  EXPECT_THAT(r.err, HasSubstr("not a capture antpose can read"));
}

TEST(CliConvert, NoUnitRepairRefusesGaussMagnetometer) {
  test::TempDir dir;
  test::write_file(dir / "in" / "capture.yaml", "format: antpose-capture\nversion: 1\n");
  test::write_file(dir / "in" / "sensors" / "magnetometer.csv", "t,x,y,z\n0,0.2,-0.3,0.25\n0.01,0.2,-0.3,0.25\n");
  auto r = test::run_cli(fmt::format("convert '{}' '{}' --no-unit-repair", (dir / "in").string(), (dir / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("looks like gauss, expected µT; unit repair is disabled"));
  EXPECT_FALSE(fs::exists(dir / "out"));
  r = test::run_cli(fmt::format("convert '{}' '{}'", (dir / "in").string(), (dir / "out").string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: "));
  EXPECT_THAT(r.err, HasSubstr("looks like gauss: converted to µT"));
}

}  // namespace
}  // namespace antpose
