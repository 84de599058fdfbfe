// antpose simulate capture: the CLI writes a readable photo capture, names bad option values and
// never overwrites a non-empty folder without --force.
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/capture.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Tiny photos: the CLI path, not the rendering, is under test here.
const std::string kSmall = " --scenario camera-calibration --photos 3 --width 160 --height 120 --supersampling 1";

TEST(SimulateCaptureCli, WritesCaptureAndRefusesToOverwrite) {
  test::TempDir dir;
  const std::string out = (dir / "cc").string();
  const auto r = test::run_cli("simulate capture -o '" + out + "'" + kSmall + " --seed 4 --time-offset-ms 25 --board charuco");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("3 photos 160x120"));
  EXPECT_THAT(r.err, HasSubstr("rendering photo 3/3"));
  Diagnostics diag;
  const Capture c = read_capture(out, diag);
  EXPECT_EQ(c.kind, "camera-calibration");
  EXPECT_EQ(c.shots.size(), 3u);
  EXPECT_THAT(io::read_text(dir / "cc/truth/device.yaml"), HasSubstr("time_offset_s: 0.025"));
  EXPECT_THAT(io::read_text(dir / "cc/board.yaml"), HasSubstr("type: charuco"));

  const std::string before = io::read_text(dir / "cc/shots.csv");
  const auto again = test::run_cli("simulate capture -o '" + out + "'" + kSmall + " --seed 5");
  EXPECT_EQ(again.status, 2);
  EXPECT_THAT(again.err, HasSubstr("not empty"));
  EXPECT_THAT(again.err, HasSubstr("--force"));
  EXPECT_EQ(io::read_text(dir / "cc/shots.csv"), before);
  const auto forced = test::run_cli("simulate capture -o '" + out + "'" + kSmall + " --seed 5 --force");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_NE(io::read_text(dir / "cc/shots.csv"), before);

  // An existing empty folder is fine.
  fs::create_directories(dir / "empty");
  EXPECT_EQ(test::run_cli("simulate capture -o '" + (dir / "empty").string() + "'" + kSmall).status, 0);
  EXPECT_TRUE(fs::exists(dir / "empty/shots.csv"));
}

TEST(SimulateCaptureCli, BadValuesNameTheOption) {
  test::TempDir dir;
  const std::string out = " -o '" + (dir / "x").string() + "'";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--jpeg-quality 0", "--jpeg-quality"},
      {"--width 10", "--width"},
      {"--height 99999", "--height"},
      {"--blur-px -1", "--blur-px"},
      {"--noise -0.5", "--noise"},
      {"--photos-per-placement 1", "--photos-per-placement"},
      {"--photos 2", "--photos"},
      {"--time-offset-ms 5000", "--time-offset-ms"},
      {"--board hexagons", "--board"},
      {"--supersampling 9", "--supersampling"},
  };
  for (const auto& [args, name] : cases) {
    const auto r = test::run_cli("simulate capture" + out + " " + args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_THAT(r.err, HasSubstr(name)) << args;
    EXPECT_THAT(r.err, ::testing::AnyOf(HasSubstr("outside"), HasSubstr("is not"))) << args << ": " << r.err;
  }
  // CLI11 rejects values outside the choices itself.
  const auto r = test::run_cli("simulate capture" + out + " --scenario planets");
  EXPECT_NE(r.status, 0);
  EXPECT_THAT(r.err, HasSubstr("--scenario"));
  EXPECT_FALSE(fs::exists(dir / "x"));
}

}  // namespace
}  // namespace antpose
