// Issue acceptance for the camera–IMU calibration, end to end through the command line as a
// user runs it: a simulated typical phone (IMU noise, biases, bias random walk, hard and soft
// iron, mounting errors) is calibrated with `calibrate imu` (18 held poses; a tumble), `calibrate
// camera` (20 rendered board photos) and `calibrate joint` (the thesis's six placements, 12
// rendered photos each, level ±0.2° and compass ±1.5°), every run stored in a device database.
// Truth: truth/device.yaml. Seeds: ANTPOSE_JOINT_SEEDS from 101 (not the seeds the methods were
// developed on). The everyday run takes one, to keep CI's time (phone 401's profile, which the
// measurement tests use, comes from the same commands in scripts/calibrate-simulated-phone.sh);
// the end-to-end figures in docs/camera-imu.md take 3 (ANTPOSE_JOINT_SEEDS=3).
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
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

using test::json_mat3;
using test::run;

TEST(JointCalibrationAcceptance, SimulatedCapturesThroughTheCommandLine) {
  const char* env = std::getenv("ANTPOSE_JOINT_SEEDS");
  const int seeds = env ? std::atoi(env) : 1;
  test::TempDir dir;
  const std::string db = (dir / "devices.sqlite").string();
  double sq_free = 0, sq_thesis = 0, sq_smoother = 0, sq_dt = 0, nees = 0;
  std::printf("%-5s %-26s %-26s %-26s %-16s\n", "seed", "reference-free err° (σ°)", "thesis antpose err°",
              "thesis smoother err°", "δt err ms (σ)");
  for (int k = 0; k < seeds; ++k) {
    const int seed = 101 + k;
    const std::string id = fmt::format("phone{}", seed);
    const auto d = [&](const char* name) {
      return fmt::format("'{}'", (dir / fmt::format("{}-{}", name, seed)).string());
    };
    const std::string dev = fmt::format("--device {} --db '{}'", id, db);
    run(fmt::format("simulate imu -o {} --preset static-poses --phone typical --seed {}", d("poses"), seed));
    run(fmt::format("simulate imu -o {} --preset tumble --phone typical --seed {}", d("tumble"), seed + 1000));
    run(fmt::format("calibrate imu {} {} --sensors acc,gyro", d("poses"), dev));
    run(fmt::format("calibrate imu {} {} --sensors mag", d("tumble"), dev));
    run(fmt::format("simulate capture -o {} --scenario camera-calibration --seed {}", d("camera"), seed));
    run(fmt::format("calibrate camera {} {}", d("camera"), dev));
    run(fmt::format("simulate capture -o {} --scenario joint-calibration --seed {}", d("joint"), seed));
    const auto json = dir / fmt::format("joint-{}.json", seed);
    // The simulator's gyroscope samples are instantaneous rates (gyro_trapezoid).
    const auto r =
        test::run_cli(fmt::format("calibrate joint {} {} --method antpose,antpose-smoother "
                                  "--param gyro_trapezoid=1 --json '{}'",
                                  d("joint"), dev, json.string()));
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    if (k == 0) std::printf("%s", r.out.c_str());  // the thesis-style tables of the first seed

    const auto truth_file = dir / fmt::format("joint-{}", seed) / "truth/device.yaml";
    const YAML::Node truth = YAML::LoadFile(truth_file.string());
    // The device's IMU calibration was applied: its frame is the calibrated one (simulator.md).
    const Mat3 X = io::yaml_mat3(truth["camera_imu"]["R_calibrated_camera"], truth_file, "R_calibrated_camera");
    const double dt_true = truth["camera_imu"]["time_offset_s"].as<double>();
    const auto j = nlohmann::json::parse(io::read_text(json));
    const auto& rf = j["reference_free"];
    const Mat3 X_free = json_mat3(rf["R_device_camera"]);
    const Vec3 e = log_so3(X_free * X.transpose());
    const Vec3 sigma =
        deg2rad(1.0) * Vec3(rf["rotation_sigma_deg"][0].get<double>(), rf["rotation_sigma_deg"][1].get<double>(),
                            rf["rotation_sigma_deg"][2].get<double>());
    const double err_free = rad2deg(e.norm());
    const double err_thesis = rad2deg(rotation_distance(json_mat3(j["thesis"][0]["R_device_camera"]), X));
    const double err_smoother = rad2deg(rotation_distance(json_mat3(j["thesis"][1]["R_device_camera"]), X));
    const double dt_err = rf["time_offset_s"].get<double>() - dt_true;
    // For the record: against the phone body's frame, which includes the accelerometer's own
    // mounting rotation that no IMU-based calibration can see (docs/camera-imu.md).
    const double body = rad2deg(rotation_distance(
        X_free, io::yaml_mat3(truth["camera_imu"]["R_device_camera"], truth_file, "R_device_camera")));
    std::printf("seed %d: reference-free %.3f° from R_device_camera of the body frame\n", seed, body);
    std::printf("%-5d %8.3f (%.3f %.3f %.3f)  %-26.3f %-26.3f %7.2f (%.2f)\n", seed, err_free, rad2deg(sigma.x()),
                rad2deg(sigma.y()), rad2deg(sigma.z()), err_thesis, err_smoother, 1e3 * dt_err,
                1e3 * rf["time_offset_sigma_s"].get<double>());
    EXPECT_LT(err_free, 0.2) << seed;
    EXPECT_LT(err_thesis, 0.5) << seed;
    EXPECT_LT(err_smoother, 0.5) << seed;
    EXPECT_LT(std::abs(dt_err), 0.005) << seed;
    sq_free += err_free * err_free / seeds;
    sq_thesis += err_thesis * err_thesis / seeds;
    sq_smoother += err_smoother * err_smoother / seeds;
    sq_dt += dt_err * dt_err / seeds;
    nees += e.cwiseQuotient(sigma).squaredNorm() / seeds;  // diagonal approximation

    // Every run is in the database, and the profile holds the result.
    const auto show = test::run_cli(fmt::format("device show {} --history --db '{}'", id, db));
    ASSERT_EQ(show.status, 0) << show.err;
    EXPECT_NE(show.out.find("camera-imu  ok"), std::string::npos) << show.out;
    EXPECT_NE(show.out.find("method: reference-free"), std::string::npos);
  }
  std::printf(
      "RMS over %d seeds: reference-free %.3f°, thesis (antpose) %.3f°, thesis (smoother) %.3f°, δt %.2f ms; "
      "mean rotation NEES %.1f (3 if σ were complete)\n",
      seeds, std::sqrt(sq_free), std::sqrt(sq_thesis), std::sqrt(sq_smoother), 1e3 * std::sqrt(sq_dt), nees);
}

}  // namespace
}  // namespace antpose
