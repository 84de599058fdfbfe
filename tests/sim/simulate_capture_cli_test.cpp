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
  const auto r = test::run_cli("simulate capture -o '" + out + "'" + kSmall +
                               " --seed 4 --time-offset-ms 25 --board charuco --progress json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("3 photos 160x120"));
  EXPECT_THAT(r.err, HasSubstr("\"done\":3,"));
  EXPECT_THAT(r.err, HasSubstr("\"stage\":\"rendering photos\""));
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

// The antenna scenario's distribution and the wide draws' fixes: each bad value is named with
// what was expected; the wide-only fixes refuse the classic distribution.
TEST(SimulateCaptureCli, WideDistributionFlagsNameTheirValues) {
  test::TempDir dir;
  const std::string out = " -o '" + (dir / "x").string() + "' --scenario antenna";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"--distribution narrow", {"--distribution", "'narrow'", "classic or wide"}},
      {"--photo-scale 0.1", {"--photo-scale", "0.1", "0.25..1"}},
      {"--photo-scale 1.5", {"--photo-scale", "1.5", "0.25..1"}},
      {"--arrangement ring", {"--arrangement", "'ring'", "sectors or side-by-side"}},
      {"--radome chrome", {"--radome", "'chrome'", "plain, weathered or ribbed"}},
      {"--background forest", {"--background", "'forest'", "sky, buildings or trees"}},
      {"--light dusk", {"--light", "'dusk'", "sun, low-sun, overcast or shade"}},
      {"--distribution classic --radome ribbed", {"--radome", "'ribbed'", "--distribution wide"}},
      {"--distribution classic --light sun", {"--light", "--distribution wide"}},
      {"--distribution classic --photo-scale 0.5", {"--photo-scale", "--distribution wide"}},
      {"--distribution classic --arrangement sectors", {"--arrangement", "--distribution wide"}},
      {"--distribution classic --background sky", {"--background", "--distribution wide"}},
  };
  for (const auto& [args, parts] : cases) {
    const auto r = test::run_cli("simulate capture" + out + " " + args);
    EXPECT_EQ(r.status, 2) << args << ": " << r.err;
    for (const auto& part : parts) EXPECT_THAT(r.err, HasSubstr(part)) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x"));

  // Wide by default: the photos a resize of the native size, the draws summarised.
  const auto wide = test::run_cli("simulate capture -o '" + (dir / "w").string() +
                                  "' --scenario antenna --width 1600 --height 1200 --photo-scale 0.5 --photos 3 "
                                  "--supersampling 1 --seed 5 --light overcast --background buildings");
  ASSERT_EQ(wide.status, 0) << wide.err;
  EXPECT_THAT(wide.out, HasSubstr("3 photos 800x600"));
  EXPECT_THAT(wide.out, HasSubstr("overcast light, buildings behind"));
  EXPECT_THAT(io::read_text(dir / "w/truth/scene.yaml"), HasSubstr("distribution: wide"));
}

}  // namespace
}  // namespace antpose
