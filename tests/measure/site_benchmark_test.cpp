#include "antpose/measure/site_benchmark.hpp"

#include <chrono>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

constexpr const char* kScene = R"(antennas:
  - model: panel-1310x300x160
    roi: {image: images/img_0003.jpg, x: 10, y: 20, width: 300, height: 120}
    azimuth_magnetic_deg: 350.5
    downtilt_deg: -4.25
    roll_deg: 1.5
  - model: panel-2000x300x150
    roi: {image: images/img_0001.jpg, x: 1, y: 2, width: 3, height: 4}
    azimuth_magnetic_deg: 10
    downtilt_deg: 12
    roll_deg: -2
)";

TEST(SiteBenchmark, ReadsEveryAntennaOfTheTruth) {
  test::TempDir dir;
  test::write_file(dir / "truth/scene.yaml", kScene);
  const auto antennas = read_truth_antennas(dir.path());
  ASSERT_EQ(antennas.size(), 2u);
  EXPECT_EQ(antennas[0].model, "panel-1310x300x160");
  EXPECT_EQ(antennas[0].roi.image, "images/img_0003.jpg");
  EXPECT_EQ(antennas[0].roi.roi.x, 10);
  EXPECT_EQ(antennas[0].roi.roi.height, 120);
  EXPECT_NEAR(rad2deg(antennas[0].azimuth_magnetic), 350.5, 1e-12);
  EXPECT_NEAR(rad2deg(antennas[0].downtilt), -4.25, 1e-12);
  EXPECT_NEAR(rad2deg(antennas[1].roll), -2.0, 1e-12);
}

TEST(SiteBenchmark, ABadTruthValueIsNamedWithItsLine) {
  test::TempDir dir;
  std::string scene = kScene;
  scene.replace(scene.find("downtilt_deg: 12"), 16, "downtilt_deg: steep");
  test::write_file(dir / "truth/scene.yaml", scene);
  const auto message = test::input_error([&] { read_truth_antennas(dir.path()); });
  EXPECT_THAT(message, HasSubstr("scene.yaml:10"));
  EXPECT_THAT(message, HasSubstr("antennas[1].downtilt_deg"));
  EXPECT_THAT(message, HasSubstr("steep"));
}

TEST(SiteBenchmark, AMissingTruthSaysWhatIsNeeded) {
  test::TempDir dir;
  EXPECT_THAT(test::input_error([&] { read_truth_antennas(dir.path()); }),
              HasSubstr("needs the truth of a simulated capture"));
}

TEST(SiteBenchmark, TheClockSumsAStageOverTheAntennas) {
  StageClock clock;
  clock("features", 1, 1);
  clock("antenna 1 (images/img_0003.jpg): dense stereo", 1, 2);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  clock("antenna 2 (images/img_0001.jpg): dense stereo", 2, 2);
  clock("antenna 12: with its neighbours known", 1, 1);
  const auto& s = clock.seconds();
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[2].first, "with its neighbours known");
  EXPECT_EQ(s[0].first, "features");
  EXPECT_EQ(s[1].first, "dense stereo");
  EXPECT_GE(s[1].second, 0.015);  // the wait before the second antenna's report
}

}  // namespace
}  // namespace antpose::measure
