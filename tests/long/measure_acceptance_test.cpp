// Issue acceptance for the non-contact measurement, end to end through the command line as a
// user runs it. One simulated typical phone is calibrated once (`calibrate imu`, `calibrate
// camera`, `calibrate joint`, stored in a device database); then it photographs antenna sites it
// was never tuned on — rooftop and ground, 1–3 antennas, with and without a magnetised mast — and
// `antpose measure` reads each antenna's attitude with the rectangle the simulator suggests.
// Errors against truth/scene.yaml, per antenna and RMS.
//
// Photos are 12 MP (4000 × 3000, a phone's main camera), the resolution the method is meant for:
// at 2 MP a light grey panel's outline moves by well under a pixel per degree of yaw.
// Captures: ANTPOSE_MEASURE_CAPTURES (default 2: one rooftop, one ground; the acceptance figures
// use 12 or more, with ANTPOSE_MEASURE_ACCEPTANCE=1 to assert the targets), scene seeds from
// ANTPOSE_MEASURE_SEED_BASE (default 501) and device seed 401 (not the seeds the pipeline was
// developed on: device 21, scenes 601–612 and earlier ones below 100).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "acceptance_support.hpp"
#include "antpose/geometry/attitude.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

using test::json_mat3;
using test::run;

// Seconds since the last call: where the run's time goes, printed so that the everyday set of
// sites can be chosen against the CI budget.
class Lap {
 public:
  double seconds() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

struct Errors {
  double sq_az = 0, sq_tilt = 0, sq_roll = 0;
  double z2_az = 0, z2_tilt = 0, z2_roll = 0;  // squared errors over σ²
  int n = 0;
  void add(double az, double tilt, double roll, double s_az, double s_tilt, double s_roll) {
    sq_az += az * az, sq_tilt += tilt * tilt, sq_roll += roll * roll;
    z2_az += az * az / (s_az * s_az), z2_tilt += tilt * tilt / (s_tilt * s_tilt),
        z2_roll += roll * roll / (s_roll * s_roll);
    ++n;
  }
  double rms(double sq) const { return n ? std::sqrt(sq / n) : 0.0; }
};

TEST(MeasureAcceptance, SimulatedSitesThroughTheCommandLine) {
  const char* env = std::getenv("ANTPOSE_MEASURE_CAPTURES");
  const int captures = env ? std::atoi(env) : 2;
  // A new set of sites once the pipeline has been tuned on the findings of the last one.
  const char* base_env = std::getenv("ANTPOSE_MEASURE_SEED_BASE");
  const int seed_base = base_env ? std::atoi(base_env) : 501;
  const bool acceptance = std::getenv("ANTPOSE_MEASURE_ACCEPTANCE") != nullptr;
  test::TempDir dir;
  const int device_seed = 401;
  const auto path = [&](const std::string& name) { return fmt::format("'{}'", (dir / name).string()); };
  const std::string camera = "--width 4000 --height 3000 --supersampling 2";
  // The phone's profile as antpose's calibrations produce it. The acceptance run calibrates it
  // here through the command line, as a user would (six minutes of CPU, most of it rendering the
  // 72 board photos of the camera–IMU capture); the everyday run reads the profile those same
  // commands wrote (tests/data/phone401.yaml), to keep CI within its budget, and
  // JointCalibrationAcceptance checks that chain every day. Both come from
  // scripts/calibrate-simulated-phone.sh.
  const auto stored_profile = test::source_path("tests/data/phone401.yaml");
  const auto fresh_profile = dir / fmt::format("phone{}.yaml", device_seed);
  const std::string dev = fmt::format("--device '{}'", (acceptance ? fresh_profile : stored_profile).string());
  Lap lap;
  if (acceptance) {
    const auto work = dir / "calibration";
    const auto log = dir / "calibration.log";
    const int status =
        std::system(fmt::format("bash '{}' {} '{}' '{}' '{}' >'{}' 2>&1",
                                test::source_path("scripts/calibrate-simulated-phone.sh").string(), device_seed,
                                fresh_profile.string(), test::cli_path().string(), work.string(), log.string())
                        .c_str());
    ASSERT_EQ(status, 0) << io::read_text(log);
    const auto joint_json = work / "joint.json";
    // Its camera–IMU rotation against the simulator's, to JointCalibrationAcceptance's limit, and
    // against the stored profile's (which the everyday run uses: regenerate it if they differ).
    const auto truth_file = work / "joint/truth/device.yaml";
    const Mat3 R_calibrated_camera = io::yaml_mat3(
        YAML::LoadFile(truth_file.string())["camera_imu"]["R_calibrated_camera"], truth_file, "R_calibrated_camera");
    const Mat3 R_device_camera =
        json_mat3(nlohmann::json::parse(io::read_text(joint_json))["reference_free"]["R_device_camera"]);
    const double joint_err_deg = rad2deg(rotation_distance(R_device_camera, R_calibrated_camera));
    const double stored_deg = rad2deg(rotation_distance(
        R_device_camera, io::yaml_mat3(YAML::LoadFile(stored_profile.string())["camera_imu"]["R_device_camera"],
                                       stored_profile, "R_device_camera")));
    std::printf("phone %d: R_device_camera %.3f° from the truth, %.4f° from %s\n", device_seed, joint_err_deg,
                stored_deg, stored_profile.string().c_str());
    EXPECT_LT(joint_err_deg, 0.2);
    std::printf("phone calibrated in %.0f s\n", lap.seconds());
  }

  Errors clean, disturbed;
  int failures = 0, disturbed_unflagged_over_3 = 0;
  std::printf("%-4s %-8s %-5s %-3s %9s %9s %9s %9s %9s %9s %8s  %s\n", "cap", "setting", "dist", "ant", "az err°",
              "az σ°", "tilt err°", "tilt σ°", "roll err°", "roll σ°", "fit mm", "warnings");
  // The acceptance sites alternate rooftop and ground, with disturbance on every third and 1–3
  // antennas. The everyday run adds sites where a fault was once found (not counted in the RMS),
  // and measures there only the antenna that showed it (each antenna's outline is first fitted
  // alone; the others matter only to one that fitted from no start):
  // 3312 (seeds base 3301, k = 11), whose thesis panel in front of its mast from the ground came
  // out 3.66° off in downtilt with σ 0.18° (silhouette_tilt_probe_deg); 3406 (base 3401, k = 5),
  // whose third panel, a third hidden by its mast, came out 70° off in azimuth and 5.0° in downtilt
  // (σ 2.3°): the held-axis search's score, the mast known, was compared with the free search's
  // without it; 3208 (base 3201, k = 7), a 2 m panel from the ground, refused because the points'
  // box sat 0.14 m behind it, out of every outline start's reach (other_positions); 3711 (base
  // 3701, k = 10), whose thesis panel between two wider ones on a rooftop came out 12.4° off in
  // azimuth with σ 1.1°: every outline descent left its basin at the coarse levels (the points'
  // boresight polished, silhouette_search); 3811 (base 3801, k = 10), whose 2 m panel behind two
  // thesis panels on a rooftop was refused: the points' box sat 0.12 m along its axis from it
  // (other_positions); 3802 (base 3801, k = 1), whose lone 2 m panel from the ground came out
  // 1.42° off in downtilt with σ 0.36°: false feature tracks had turned every camera by
  // 0.03–0.10° (PoseRefinementOptions::max_board_rms_growth); 5111 (base 5101, k = 10), whose
  // third panel's rectangle held the lower half of the nearer middle panel, measured for it 112°
  // off in azimuth and 1.79° in downtilt with σ 0.24° (NonContactOptions::min_roi_fill); 5810
  // (base 5801, k = 9), whose 2 m panel seen side-on from behind from the ground was refused: no
  // outline start lay in its narrow basin (NonContactOptions::fine_yaw_step_deg); 6109 (base 6101,
  // k = 8), whose 2 m panel 4.3 m away on a rooftop was refused: its mast, clamps and arms held
  // two thirds of the region's points, and the box on them sat 0.29 m beside the panel
  // (NonContactOptions::off_mast_m).
  struct Site {
    int seed;
    bool ground, disturbance;
    int antennas;
    bool regression;
    int only = 0;                 // the one antenna (1-based) measured, or 0 for all
    const char* warns = nullptr;  // a warning the antenna's answer must give (a part of its text)
  };
  std::vector<Site> sites;
  for (int k = 0; k < captures; ++k) sites.push_back({seed_base + k, k % 2 == 1, k % 3 == 2, 1 + (k / 2) % 3, false});
  // Every regression site with ANTPOSE_MEASURE_REGRESSION=all (run it before changing the
  // registration); everyday, to keep CI within its budget, the sites whose fault no shorter test
  // guards: 3208 leaves for 3811, which takes the same path (other_positions) in half the time,
  // 3802 for BundleAdjust.FeaturesThatPullThePosesOffTheBoardAreLeftOut, and 6109 (160 s, every
  // fallback before its own run) for Mast.FromPointsAloneIsTheCylinderTheyLieOn.
  const char* regression_env = std::getenv("ANTPOSE_MEASURE_REGRESSION");
  const bool all_regression = regression_env != nullptr && std::string(regression_env) == "all";
  if (!acceptance) {
    // A thesis panel seen face-on from the ground over 9°: its outline's width barely changes with
    // yaw, and the answer says so (SilhouetteResult::dilation_yaw_sigma_rad).
    sites.push_back({3312, true, true, 3, true, 2, "width barely changes with yaw"});
    sites.push_back({3406, true, true, 3, true, 3});
    if (all_regression) sites.push_back({3208, true, false, 1, true});
    sites.push_back({3711, false, false, 3, true, 2});
    sites.push_back({3811, false, false, 3, true, 3});
    if (all_regression) sites.push_back({3802, true, false, 1, true});
    sites.push_back({5111, false, false, 3, true, 3});
    sites.push_back({5810, true, false, 2, true, 1});
    if (all_regression) sites.push_back({6109, false, true, 2, true, 2});
  }
  for (std::size_t k = 0; k < sites.size(); ++k) {
    const auto [seed, ground, disturbance, antennas, regression, only, warns] = sites[k];
    const std::string name = fmt::format("site-{}", seed);
    run(fmt::format(
        "simulate capture -o {} --scenario antenna --seed {} --device-seed {} --setting {} --antennas {}{} {}",
        path(name), seed, device_seed, ground ? "ground" : "rooftop", antennas, disturbance ? " --disturbance" : "",
        camera));
    const double simulated_s = lap.seconds();
    const YAML::Node truth = YAML::LoadFile((dir / name / "truth/scene.yaml").string());
    std::vector<std::pair<int, YAML::Node>> measured;  // (1-based antenna, its truth) of each --roi
    for (std::size_t i = 0; i < truth["antennas"].size(); ++i)
      if (only == 0 || only == static_cast<int>(i) + 1)
        measured.emplace_back(static_cast<int>(i) + 1, truth["antennas"][i]);
    std::string rois;
    for (const auto& [i, a] : measured) {
      const auto roi = a["roi"];
      rois += fmt::format(" --roi '{}:{},{},{},{}' --model {}", roi["image"].as<std::string>(), roi["x"].as<int>(),
                          roi["y"].as<int>(), roi["width"].as<int>(), roi["height"].as<int>(),
                          a["model"].as<std::string>());
    }
    const auto json = dir / (name + ".json");
    const auto r = test::run_cli(fmt::format("measure {} {} {} --json '{}'", path(name), dev, rois, json.string()));
    if (k == 0) std::printf("%s%s", r.out.c_str(), r.err.c_str());
    std::printf("%-4d simulated in %.0f s, measured in %.0f s\n", seed, simulated_s, lap.seconds());
    ASSERT_TRUE(r.status == 0 || r.status == 3) << r.err << r.out;
    const auto j = nlohmann::json::parse(io::read_text(json));
    ASSERT_EQ(j["antennas"].size(), measured.size());
    // The camera poses under every site's rows: the board's residual, and whether the features
    // were kept (bundle_adjustment.cpp: the board is the reference).
    const auto& poses = j["camera_poses"];
    std::printf("%-4d camera poses: board %.2f px, scene %.2f px over %d tracks\n", seed,
                poses["board_rms_px"].get<double>(), poses["scene_rms_px"].get<double>(), poses["tracks"].get<int>());
    for (std::size_t n = 0; n < measured.size(); ++n) {
      const auto& [i, a] = measured[n];
      const auto& m = j["antennas"][n];
      ASSERT_TRUE(m.contains("azimuth_magnetic_deg") && m.contains("uncertainty_deg")) << m.dump();
      if (!m["error"].is_null()) {
        EXPECT_FALSE(m["error"].get<std::string>().empty());
        EXPECT_TRUE(m["azimuth_magnetic_deg"].is_null());
        ++failures;
        std::printf("%-4d %-8s %-5s %-3d FAILED: %s\n", seed, ground ? "ground" : "rooftop", disturbance ? "yes" : "no",
                    i, m["error"].get<std::string>().c_str());
        continue;
      }
      const double az =
          rad2deg(wrap_pi(deg2rad(m["azimuth_magnetic_deg"].get<double>() - a["azimuth_magnetic_deg"].as<double>())));
      const double tilt = m["downtilt_deg"].get<double>() - a["downtilt_deg"].as<double>();
      const double roll = m["roll_deg"].get<double>() - a["roll_deg"].as<double>();
      const auto& s = m["uncertainty_deg"];
      for (const char* angle : {"azimuth", "downtilt", "roll"})
        EXPECT_TRUE(s[angle].is_number() && s[angle].get<double>() > 0.0) << m.dump();
      std::string warnings;
      for (const auto& w : m["warnings"]) warnings += w.get<std::string>().substr(0, 60) + "…; ";
      std::printf("%-4d %-8s %-5s %-3d %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %8.1f  %s\n", seed,
                  ground ? "ground" : "rooftop", disturbance ? "yes" : "no", i, az, s["azimuth"].get<double>(), tilt,
                  s["downtilt"].get<double>(), roll, s["roll"].get<double>(), 1e3 * m["fit_rmse_m"].get<double>(),
                  warnings.c_str());
      if (regression) {
        EXPECT_LE(std::abs(tilt), 0.5) << "site " << seed << ", antenna " << i;
        if (warns) {
          EXPECT_NE(warnings.find(warns), std::string::npos) << "site " << seed << ": " << warnings;
        }
        if (!disturbance) {
          EXPECT_LE(std::abs(az), 2.0) << "site " << seed << ", antenna " << i;
        }
        continue;
      }
      const double s_az = s["azimuth"].get<double>(), s_tilt = s["downtilt"].get<double>();
      const double s_roll = s["roll"].get<double>();
      if (disturbance) {
        disturbed.add(az, tilt, roll, s_az, s_tilt, s_roll);
        // With disturbance: within 3°, or flagged.
        const bool flagged = warnings.find("magnet") != std::string::npos ||
                             warnings.find("disagree on the heading") != std::string::npos;
        if (std::abs(az) > 3.0 && !flagged) ++disturbed_unflagged_over_3;
      } else {
        clean.add(az, tilt, roll, s_az, s_tilt, s_roll);
      }
    }
  }
  std::printf("undisturbed: %d antennas, RMS azimuth %.3f°, downtilt %.3f°, roll %.3f°\n", clean.n,
              clean.rms(clean.sq_az), clean.rms(clean.sq_tilt), clean.rms(clean.sq_roll));
  std::printf("disturbed:   %d antennas, RMS azimuth %.3f°, downtilt %.3f°, roll %.3f°\n", disturbed.n,
              disturbed.rms(disturbed.sq_az), disturbed.rms(disturbed.sq_tilt), disturbed.rms(disturbed.sq_roll));
  // Honest σ: RMS of error/σ near 1 (above 1: σ too small).
  std::printf("undisturbed RMS(error/σ): azimuth %.2f, downtilt %.2f, roll %.2f\n", clean.rms(clean.z2_az),
              clean.rms(clean.z2_tilt), clean.rms(clean.z2_roll));
  // The accuracy targets, asserted in the acceptance run (ANTPOSE_MEASURE_ACCEPTANCE=1).
  // The pipeline does not meet them yet on every site (docs/non-contact.md, "Where it stands"),
  // so the everyday run checks what must always hold: every antenna has a number with a finite
  // σ (above), and none is refused (site 501's was, its rectangle reaching the roof's edge).
  EXPECT_EQ(failures, 0);
  if (std::getenv("ANTPOSE_MEASURE_ACCEPTANCE")) {
    EXPECT_EQ(disturbed_unflagged_over_3, 0);
    EXPECT_LE(clean.rms(clean.sq_az), 1.0);
    EXPECT_LE(clean.rms(clean.sq_tilt), 0.3);
    EXPECT_LE(clean.rms(clean.sq_roll), 0.5);
    EXPECT_LE(disturbed.rms(disturbed.sq_tilt), 0.3);  // the magnetometer does not touch downtilt
  }
}

}  // namespace
}  // namespace antpose
