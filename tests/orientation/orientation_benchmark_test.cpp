#include "antpose/orientation/orientation_benchmark.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/orientation/filters.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "support/test_support.hpp"

namespace antpose::orientation {
namespace {

using ::testing::HasSubstr;

std::vector<geomag::MagneticModel> models() {
  return {geomag::MagneticModel::from_file(test::shared_path("data/geomagnetism/wmm2025/wmm2020/WMM.COF")),
          geomag::MagneticModel::wmm2025()};
}

// Acceptance (issue 3): the reference C code as BROAD runs it (madgwick-broad, β = 0.12)
// reproduces BROAD's published per-trial numbers (README table (a)) within 0.05°. Measured:
// identical to the README's "measured on these files" column to 1e-4°.
TEST(OrientationBenchmark, MadgwickBroadReproducesPublishedNumbers) {
  struct Ref {
    const char* trial;
    double total, heading, inclination;
  };
  const Ref refs[] = {{"02_undisturbed_slow_rotation_B", 1.4968, 1.2637, 0.8022},
                      {"05_undisturbed_slow_rotation_with_breaks_B", 1.7859, 1.6328, 0.7233},
                      {"07_undisturbed_fast_rotation_B", 4.9963, 4.3266, 2.4993},
                      {"09_undisturbed_fast_rotation_with_breaks_B", 2.4842, 1.6467, 1.8600},
                      {"11_undisturbed_slow_translation_B", 4.2409, 2.6079, 3.3446},
                      {"16_undisturbed_fast_translation_B", 4.8248, 3.7028, 3.0938},
                      {"25_disturbed_tapping_B", 3.9161, 2.7584, 2.7801},
                      {"27_disturbed_phone_vibration_B", 10.6170, 10.5012, 1.5655},
                      {"30_disturbed_stationary_magnet_C", 5.5660, 1.8065, 5.2648},
                      {"33_disturbed_attached_magnet_2cm", 7.0876, 5.1167, 4.9062}};
  const auto est = make_estimator("madgwick-broad", {{"beta", 0.12}});
  const auto ms = models();
  std::vector<MethodScore> scores;
  for (const auto& r : refs) {
    Diagnostics diag;
    const auto trial = load_benchmark_trial(test::shared_path("data/orientation/broad") / r.trial, ms, diag);
    EXPECT_EQ(trial.truth.protocol, "moving");
    const auto m = run_method(trial, *est, diag);
    std::cout << fmt::format("{:<45} {:.4f} / {:.4f} / {:.4f}  (published {:.4f} / {:.4f} / {:.4f})\n", r.trial,
                             rad2deg(m.score.rmse.total), rad2deg(m.score.rmse.heading),
                             rad2deg(m.score.rmse.inclination), r.total, r.heading, r.inclination);
    EXPECT_NEAR(rad2deg(m.score.rmse.total), r.total, 0.05) << r.trial;
    EXPECT_NEAR(rad2deg(m.score.rmse.heading), r.heading, 0.05) << r.trial;
    EXPECT_NEAR(rad2deg(m.score.rmse.inclination), r.inclination, 0.05) << r.trial;
    EXPECT_EQ(m.score.outside, 0u);
    scores.push_back(m);
  }
  const auto mean = mean_score(scores);
  EXPECT_NEAR(rad2deg(mean.rmse.total), 4.702, 0.005);
  EXPECT_NEAR(rad2deg(mean.rmse.heading), 3.536, 0.005);
  EXPECT_NEAR(rad2deg(mean.rmse.inclination), 2.684, 0.005);
}

// BROAD's initial state: (1/√2, 0, 0, 1/√2) ⊗ q₀ is 1.5° from the first valid truth of 02 and
// 4.2° for 25 (README).
TEST(MadgwickBroad, InitialStateOnBroad) {
  for (const auto& [name, expected] : {std::pair{"02_undisturbed_slow_rotation_B", 1.5}, {"25_disturbed_tapping_B", 4.2}}) {
    Diagnostics diag;
    const Capture c = read_capture(test::shared_path("data/orientation/broad") / name, diag);
    const Quat q0 = q_enu_nwu() * broad_initial_state(c.require("accelerometer").xyz(0), c.require("magnetometer").xyz(0));
    const Stream& truth = *c.truth_orientation;
    std::size_t i = 0;
    while (!std::isfinite(truth.values(static_cast<Eigen::Index>(i), 0))) ++i;
    const auto r = truth.values.row(static_cast<Eigen::Index>(i));
    EXPECT_NEAR(rad2deg(broad_errors(q0, Quat(r(0), r(1), r(2), r(3))).total), expected, 0.1) << name;
  }
}

// The paper's filter without the (2bx, 2bz) defect differs from the reference code (it is a
// different filter), and the two must not be confused by the harness.
TEST(OrientationBenchmark, PaperMadgwickDiffersFromReferenceCode) {
  Diagnostics diag;
  const auto trial =
      load_benchmark_trial(test::shared_path("data/orientation/broad/07_undisturbed_fast_rotation_B"), models(), diag);
  const auto a = run_method(trial, *make_estimator("madgwick"), diag);
  const auto b = run_method(trial, *make_estimator("madgwick-broad"), diag);
  EXPECT_GT(std::abs(a.score.rmse.total - b.score.rmse.total), deg2rad(0.1));
  EXPECT_LT(rad2deg(a.score.rmse.total), 6.0);
}

// Tyrex: true-north truth, the declination of the site (WMM2015 gives +1.48°; WMM2020 extrapolated
// back to 2016 gives 1.49°) applied to the estimate, the first 5 s of truth left out.
TEST(OrientationBenchmark, TyrexDeclinationAndProtocol) {
  Diagnostics diag;
  const auto trial =
      load_benchmark_trial(test::shared_path("data/orientation/tyrex/Thibaud_Nexus5_NoDist_AR"), models(), diag);
  EXPECT_EQ(trial.truth.protocol, "after-skip");
  EXPECT_EQ(trial.truth.world, "enu-true");
  EXPECT_EQ(trial.truth.declination_model, "WMM-2020");
  EXPECT_NEAR(rad2deg(trial.truth.declination), 1.48, 0.03);
  EXPECT_TRUE(diag.mentions("outside the validity of WMM-2020"));
  EXPECT_GT(trial.truth.t.front(), 4.99);
  EXPECT_NEAR(static_cast<double>(trial.truth.t.size()), 6900.0, 5.0);  // 115 s at 60 Hz
  const auto m = run_method(trial, *make_estimator("madgwick"), diag);
  EXPECT_LT(rad2deg(m.score.rmse.total), 8.0);
  EXPECT_LT(rad2deg(m.score.rmse.inclination), 4.0);
  // Without the declination the heading error changes by about its size.
  ScoredTruth magnetic = trial.truth;
  magnetic.world = "enu-magnetic";
  const auto track = make_estimator("madgwick")->estimate(trial.data, diag);
  EXPECT_GT(std::abs(score_track(track, magnetic).rmse.heading - m.score.rmse.heading), deg2rad(0.3));
}

TEST(OrientationBenchmark, TruthErrors) {
  test::TempDir dir;
  Diagnostics diag;
  Capture c = read_capture(test::shared_path("data/orientation/tyrex/Jakob_Nexus5_NoDist_AR"), diag);
  c.site.reset();
  EXPECT_THAT(([&] {
                try {
                  scored_truth(c, models(), diag);
                } catch (const InputError& e) {
                  return std::string(e.what());
                }
                return std::string();
              })(),
              HasSubstr("truth world is enu-true but the capture has no site"));
  c.truth_world = "unaligned";
  EXPECT_THAT(([&] {
                try {
                  scored_truth(c, models(), diag);
                } catch (const InputError& e) {
                  return std::string(e.what());
                }
                return std::string();
              })(),
              HasSubstr("truth world is 'unaligned'"));
  c.truth_orientation.reset();
  EXPECT_THROW(scored_truth(c, models(), diag), InputError);
}

TEST(Heatmap, SvgHasCellsLabelsAndValues) {
  Heatmap map;
  map.title = "yaw <MAE>";
  map.x_label = "zeta";
  map.y_label = "beta";
  map.unit = "°";
  map.x_values = {0.0, 0.01, 0.02};
  map.y_values = {0.1, 0.2};
  map.values.resize(2, 3);
  map.values << 1, 2, 3, 4, 5, 6.25;
  const std::string svg = heatmap_svg(map);
  EXPECT_THAT(svg, HasSubstr("<svg"));
  EXPECT_THAT(svg, HasSubstr("yaw &lt;MAE&gt;"));
  EXPECT_THAT(svg, HasSubstr(">6.25</text>"));
  EXPECT_THAT(svg, HasSubstr(">0.02</text>"));
  EXPECT_THAT(svg, HasSubstr("fill=\"#440154\""));  // minimum → viridis start
  EXPECT_THAT(svg, HasSubstr("fill=\"#fde725\""));  // maximum → viridis end
  map.values.resize(3, 3);
  EXPECT_THROW(heatmap_svg(map), std::invalid_argument);
}

TEST(OrientationCli, OrientationAndBench) {
  test::TempDir dir;
  const auto capture = test::shared_path("data/orientation/broad/02_undisturbed_slow_rotation_B");
  auto r = test::run_cli(fmt::format("orientation {} --method madgwick --param beta=0.1 -o {}", capture.string(),
                                     (dir / "o.csv").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream f(dir / "o.csv");
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header, "t,qw,qx,qy,qz");
  r = test::run_cli(fmt::format("orientation {} --method ecompass -o {}", capture.string(), (dir / "e.csv").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream fe(dir / "e.csv");
  std::getline(fe, header);
  EXPECT_EQ(header, "t,qw,qx,qy,qz,tilt_sigma_deg,heading_sigma_deg");

  r = test::run_cli(fmt::format("orientation {} --method kalman -o {}", capture.string(), (dir / "x.csv").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'kalman' is not an orientation method, expected ecompass"));
  r = test::run_cli(fmt::format("orientation {} --param beta -o {}", capture.string(), (dir / "x.csv").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'beta' is not name=value"));

  r = test::run_cli(fmt::format("bench orientation {} --method madgwick-broad,mahony --json {}", capture.string(),
                                (dir / "b.json").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("1.4968"));
  std::ifstream jf(dir / "b.json");
  const auto j = nlohmann::json::parse(jf);
  EXPECT_NEAR(j["means"]["broad"]["madgwick-broad"]["total_rmse_deg"].get<double>(), 1.4968, 1e-3);
  EXPECT_GT(j["means"]["broad"]["mahony"]["ns_per_sample"].get<double>(), 0.0);
}

TEST(OrientationCli, GridWritesFourHeatMaps) {
  test::TempDir dir;
  sim::ImuSimulation sim;
  sim.trajectory = sim::random_rotations(2, 1.5, 1.5, 3);
  sim.phone = sim::PhoneModel::typical();
  Capture c = sim::simulate_imu(sim);
  c.truth_world = "enu-magnetic";  // the simulated field has no declination
  write_capture(c, dir / "sim" / "trial");
  const auto r = test::run_cli(
      fmt::format("bench orientation-grid {} -o {} --threads 2", (dir / "sim").string(), (dir / "grid").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"yaw_mae.svg", "pitch_mae.svg", "roll_mae.svg", "pitch_roll_mae.svg"}) {
    std::ifstream in(dir / "grid" / f);
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_THAT(ss.str(), HasSubstr("beta (rad/s)")) << f;
    EXPECT_THAT(ss.str(), HasSubstr("zeta (rad/s²)")) << f;
  }
  std::ifstream jf(dir / "grid" / "grid.json");
  const auto j = nlohmann::json::parse(jf);
  ASSERT_EQ(j["yaw_mae_deg"].size(), 11u);
  ASSERT_EQ(j["yaw_mae_deg"][0].size(), 11u);
  // beta = 0 and zeta = 0 is pure gyroscope integration: exact for an error-free start, and the
  // typical phone's small bias keeps it small over 6 s.
  EXPECT_LT(j["pitch_mae_deg"][1][0].get<double>(), 1.0);
}

}  // namespace
}  // namespace antpose::orientation
