#include "antpose/orientation/rest_benchmark.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <iostream>

#include <fmt/format.h>

#include "support/test_support.hpp"

namespace antpose::orientation {
namespace {

using ::testing::HasSubstr;

TEST(BroadErrors, ClosedForms) {
  const Quat ref(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  // A pure rotation about the world vertical is all heading.
  auto e = broad_errors(Quat(Eigen::AngleAxisd(deg2rad(10.0), Vec3::UnitZ())) * ref, ref);
  EXPECT_NEAR(rad2deg(e.heading), 10.0, 1e-9);
  EXPECT_NEAR(rad2deg(e.inclination), 0.0, 1e-6);
  EXPECT_NEAR(rad2deg(e.total), 10.0, 1e-9);
  // About a horizontal world axis: all inclination.
  e = broad_errors(Quat(Eigen::AngleAxisd(deg2rad(3.0), Vec3(1, 1, 0).normalized())) * ref, ref);
  EXPECT_NEAR(rad2deg(e.heading), 0.0, 1e-9);
  EXPECT_NEAR(rad2deg(e.inclination), 3.0, 1e-9);
  // q and −q are the same attitude.
  const Quat est(Eigen::AngleAxisd(deg2rad(5.0), Vec3::UnitZ()) * ref);
  const Quat neg(-est.w(), -est.x(), -est.y(), -est.z());
  EXPECT_NEAR(broad_errors(neg, ref).heading, broad_errors(est, ref).heading, 1e-12);
}

// The ten BROAD trials (../shared/data/orientation/README.md). Target: heading ≤ 1.0°,
// inclination ≤ 0.3°. Measured (first 20 s of rest, 1 s windows): mean heading 1.23° —
// dominated by 27_disturbed_phone_vibration_B (4.6°, where the vibrating phone bends the field
// by −4.5° per the README); the other nine are 0.59–1.09°; mean inclination 0.18°. The bounds
// below are those figures with a small margin, so a regression fails.
TEST(RestBenchmark, BroadRestPhases) {
  const auto root = test::shared_path("data/orientation/broad");
  const std::vector<std::string> names = {
      "02_undisturbed_slow_rotation_B", "05_undisturbed_slow_rotation_with_breaks_B", "07_undisturbed_fast_rotation_B",
      "09_undisturbed_fast_rotation_with_breaks_B", "11_undisturbed_slow_translation_B",
      "16_undisturbed_fast_translation_B", "25_disturbed_tapping_B", "27_disturbed_phone_vibration_B",
      "30_disturbed_stationary_magnet_C", "33_disturbed_attached_magnet_2cm"};
  std::vector<RestBenchmarkTrial> trials;
  for (const auto& name : names) {
    Diagnostics diag;
    const Capture c = read_capture(root / name, diag);
    const auto t = evaluate_rest_orientation(c, name, {});
    std::cout << fmt::format("{:<45} n {:5}  total {:.3f}  heading {:.3f}  inclination {:.3f} deg\n", name, t.samples,
                             rad2deg(t.rmse.total), rad2deg(t.rmse.heading), rad2deg(t.rmse.inclination));
    EXPECT_GT(t.samples, 5000u);
    EXPECT_NEAR(t.rest_s, 20.0, 0.01);
    EXPECT_EQ(t.rest_phases, 1u);
    EXPECT_LT(rad2deg(t.rmse.inclination), 0.3) << name;
    if (name != "27_disturbed_phone_vibration_B") {
      EXPECT_LT(rad2deg(t.rmse.heading), 1.2) << name;
    }
    trials.push_back(t);
  }
  const auto m = mean_rmse(trials);
  std::cout << fmt::format("mean: total {:.3f}  heading {:.3f}  inclination {:.3f} deg\n", rad2deg(m.total),
                           rad2deg(m.heading), rad2deg(m.inclination));
  ::testing::Test::RecordProperty("mean_heading_rmse_deg", std::to_string(rad2deg(m.heading)));
  ::testing::Test::RecordProperty("mean_inclination_rmse_deg", std::to_string(rad2deg(m.inclination)));
  EXPECT_LT(rad2deg(m.heading), 1.35);
  EXPECT_LT(rad2deg(m.inclination), 0.22);
}

TEST(RestBenchmark, NeedsMagneticTruth) {
  Capture c;
  c.root = "somewhere";
  try {
    evaluate_rest_orientation(c, "x");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no truth orientation"));
  }
  c.truth_orientation = Stream();
  c.truth_world = "enu-true";
  try {
    evaluate_rest_orientation(c, "x");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("needs 'enu-magnetic' truth"));
  }
  c.truth_world = "enu-magnetic";
  c.truth_orientation->columns = {"qw", "qx", "qy", "qz", "valid"};
  try {
    evaluate_rest_orientation(c, "x");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no 'moving' column"));
  }
}

TEST(BenchCli, StaticOrientationTable) {
  const auto trial = test::shared_path("data/orientation/broad/05_undisturbed_slow_rotation_with_breaks_B");
  const auto res = test::run_cli("bench static-orientation " + trial.string());
  ASSERT_EQ(res.status, 0) << res.err;
  EXPECT_THAT(res.out, HasSubstr("05_undisturbed_slow_rotation_with_breaks_B"));
  EXPECT_THAT(res.out, HasSubstr("mean of 1 trials"));
  const auto bad = test::run_cli("bench static-orientation /nonexistent-folder");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("no such folder"));
}

// The comparison with PCL and Open3D runs where they were installed (bench/CMakeLists.txt), and
// elsewhere says what it needs.
TEST(BenchCli, RegistrationComparisonOrWhatItNeeds) {
  const auto res = test::run_cli("bench registration --repeats 1 " + test::shared_path("").string());
  if (res.status == 0) {
    EXPECT_THAT(res.out, HasSubstr("time / antpose"));
    EXPECT_THAT(res.out, HasSubstr("open3d"));
  } else {
    EXPECT_EQ(res.status, 2);  // this build lacks the optional program: not a fault
    EXPECT_THAT(res.err, HasSubstr("needs PCL and Open3D")) << res.err;
  }
  const auto bad = test::run_cli("bench registration /nonexistent-folder");
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("/nonexistent-folder: no data/pointclouds/pcl/bun0.ply"));
  EXPECT_NE(test::run_cli("bench registration --repeats 0").status, 0);
}

}  // namespace
}  // namespace antpose::orientation
