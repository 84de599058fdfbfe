#include "antpose/calibration/magnetometer.hpp"

#include <cmath>
#include <cstdio>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/calibration/accelerometer.hpp"
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "support/test_support.hpp"

namespace antpose::calibration {
namespace {

using ::testing::HasSubstr;

TEST(MagnetometerCalibration, Hmc5883lMatchesReadmeReferenceNumbers) {
  Diagnostics d;
  const auto folder = test::shared_path("data/imu-calibration/hmc5883l-mpu6050-full-sphere");
  const Capture capture = read_capture(folder, d);
  MagnetometerOptions algebraic;
  algebraic.refine = false;
  const auto a = fit_magnetometer(capture.require(streams::kMagnetometer), algebraic, d, folder);
  // README §2 (numpy algebraic fit of the general quadric on the same 8190 samples).
  EXPECT_LT((a.hard_iron_uT - Vec3(-0.645, -10.543, 2.026)).cwiseAbs().maxCoeff(), 0.005);
  EXPECT_NEAR(a.field_uT, 53.205, 0.005);
  EXPECT_LT((a.semi_axes_uT - Vec3(47.38, 54.53, 58.30)).cwiseAbs().maxCoeff(), 0.01);
  Mat3 W;
  W << 0.979458, 0.002505, 0.027668, 0.002505, 0.923199, -0.042864, 0.027668, -0.042864, 1.108693;
  EXPECT_LT((a.soft_iron - W).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(a.residual_rms_uT, 0.245, 0.002);
  // The geometric refinement may only lower the geometric residual.
  const auto r = fit_magnetometer(capture.require(streams::kMagnetometer), {}, d, folder);
  EXPECT_LE(r.residual_rms_uT, a.residual_rms_uT + 1e-9);
  EXPECT_LT((r.hard_iron_uT - a.hard_iron_uT).norm(), 0.05);
  EXPECT_NEAR(r.residual_rel_hard_iron, 0.0557, 0.001);
  EXPECT_GT(r.direction_coverage, 0.99);
  std::printf("HMC5883L: b (%.3f, %.3f, %.3f) µT, F %.3f µT, residual %.3f µT (algebraic %.3f), std|m|/F raw %.2f%% "
              "hard-iron %.2f%% ellipsoid %.3f%%\n",
              r.hard_iron_uT.x(), r.hard_iron_uT.y(), r.hard_iron_uT.z(), r.field_uT, r.residual_rms_uT, a.residual_rms_uT,
              100 * r.residual_rel_raw, 100 * r.residual_rel_hard_iron, 100 * r.residual_rel);
}

// A phone tumbled with a large hard iron (an uncalibrated phone: 200+ µT) and a strong symmetric
// soft iron, as the iPhone case of the issue. Bounds: 0.4 µT noise over ≈ 3000 samples gives
// σ(b) ≈ 0.4·sqrt(3/3000) ≈ 0.013 µT; we test 0.1 µT for b, 0.05 µT for F, 1e-3 for S.
TEST(MagnetometerCalibration, RecoversLargeHardIronAndSoftIronFromSimulatedTumble) {
  std::mt19937_64 rng(5);
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::typical();
  sim.phone.magnetometer.hard_iron_uT = Vec3(212.0, -148.0, 87.0);
  sim.phone.magnetometer.soft_iron << 1.08, 0.04, -0.03, 0.04, 0.93, 0.02, -0.03, 0.02, 1.02;
  sim.trajectory = sim::tumble(60.0, 1.5, 3);
  sim.seed = 9;
  const Capture capture = sim::simulate_imu(sim);
  Diagnostics d;
  const auto c = fit_magnetometer(capture.require(streams::kMagnetometer), {}, d, "sim");
  const Mat3 S_inv = sim.phone.magnetometer.soft_iron.inverse();
  const Mat3 S_true = S_inv / std::cbrt(S_inv.determinant());
  const double F_true = sim.field_world_uT.norm() / std::cbrt(S_inv.determinant());
  const double e_b = (c.hard_iron_uT - sim.phone.magnetometer.hard_iron_uT).cwiseAbs().maxCoeff();
  const double e_S = (c.soft_iron - S_true).cwiseAbs().maxCoeff();
  EXPECT_LT(e_b, 0.1);
  EXPECT_LT(e_S, 1e-3);
  EXPECT_NEAR(c.field_uT, F_true, 0.05);
  EXPECT_LT(c.residual_rel, 0.02);
  EXPECT_GT(c.residual_rel_raw, 0.05);  // the raw norm swings with the 270 µT offset
  std::printf("tumble: hard iron error %.4f µT, soft iron error %.2e, F %.3f (true %.3f) µT, std|m|/F raw %.1f%% hard-iron "
              "%.2f%% ellipsoid %.3f%%\n",
              e_b, e_S, c.field_uT, F_true, 100 * c.residual_rel_raw, 100 * c.residual_rel_hard_iron, 100 * c.residual_rel);
}

TEST(MagnetometerCalibration, RotationAboutOneAxisIsPoorCoverage) {
  std::vector<Mat3> poses;
  for (int k = 0; k < 12; ++k) poses.push_back(rot_z(k * M_PI / 6));
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::typical();
  sim.trajectory = sim::static_poses(poses, 1.0, 1.0);
  const Capture capture = sim::simulate_imu(sim);
  Diagnostics d;
  try {
    fit_magnetometer(capture.require(streams::kMagnetometer), {}, d, "flat-spin");
    FAIL() << "accepted a planar rotation";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("flat-spin: magnetometer calibration: poor coverage"));
    EXPECT_THAT(e.what(), HasSubstr("turned about one axis only"));
  }
}

TEST(MagnetometerCalibration, PartialCoverageWarns) {
  // Only the upper hemisphere of device orientations: an ellipsoid is still determined, but
  // half the directions are missing.
  std::vector<Mat3> poses;
  for (int k = 0; k < 5; ++k)
    for (double tilt : {0.0, 0.4, 0.8}) poses.push_back(rot_z(k * M_PI / 4) * rot_x(tilt));
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::typical();
  sim.trajectory = sim::static_poses(poses, 0.5, 0.5);
  const Capture capture = sim::simulate_imu(sim);
  Diagnostics d;
  double coverage = -1;
  try {
    coverage = fit_magnetometer(capture.require(streams::kMagnetometer), {}, d, "half").direction_coverage;
  } catch (const MeasurementError&) {
    // acceptable as well: a partial sweep can fail the ellipsoid test (after the warning)
  }
  std::printf("partial sweep: direction coverage %.2f\n", coverage);
  EXPECT_TRUE(d.mentions("magnetometer coverage is poor")) << (d.empty() ? "" : d.warnings()[0].message);
}

TEST(MagnetometerCalibration, TooFewSamples) {
  Stream s = Stream::vector3("magnetometer", {0, 1, 2}, {Vec3(1, 2, 3), Vec3(2, 3, 4), Vec3(3, 4, 5)});
  Diagnostics d;
  try {
    fit_magnetometer(s, {}, d, "few");
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("3 samples, need at least 50"));
  }
}

// A typical phone tumbled: its accelerometer's mounting rotation Q defines the calibrated frame
// (x along the accelerometer's x axis), which the magnetometer, in the device's own axes, does
// not share. Both sensors corrected with the simulator's own calibrations, the dot-product fit
// recovers R_calibrated_magnetometer = Qᵀ (0.1–0.2° per axis) to its σ, and the field's dip.
TEST(MagnetometerAlignment, RecoversTheAccelerometersMountingFromATumble) {
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::typical();
  sim.trajectory = sim::tumble(30.0, 1.0, 4);
  sim.seed = 11;
  Capture capture = sim::simulate_imu(sim);
  const auto& a = sim.phone.accelerometer;
  const auto& m = sim.phone.magnetometer;
  imu::ImuCalibration truth;
  Mat3 Q;
  canonical_accelerometer((a.misalignment * a.scale.asDiagonal()).inverse(), truth.acc_misalignment, truth.acc_scale,
                          &Q);
  truth.acc_bias = a.bias;
  truth.mag_hard_iron_uT = m.hard_iron_uT;
  truth.mag_soft_iron = m.soft_iron.inverse();
  imu::apply(truth, capture);
  const auto r = fit_magnetometer_alignment(capture.require(streams::kAccelerometer),
                                            capture.require(streams::kMagnetometer), sim.gravity, {}, "tumble");
  const Vec3 truth_turn = log_so3(Q.transpose()), error = log_so3(r.R_calibrated_magnetometer * Q);
  const double dip = std::atan2(-sim.field_world_uT.z(), sim.field_world_uT.head<2>().norm());
  std::printf(
      "alignment: truth (%.3f, %.3f, %.3f)°, error (%.3f, %.3f, %.3f)°, 1σ (%.3f, %.3f, %.3f)°, dip error %.4f°, "
      "%zu samples\n",
      rad2deg(truth_turn.x()), rad2deg(truth_turn.y()), rad2deg(truth_turn.z()), rad2deg(error.x()), rad2deg(error.y()),
      rad2deg(error.z()), rad2deg(r.sigma_rad.x()), rad2deg(r.sigma_rad.y()), rad2deg(r.sigma_rad.z()),
      rad2deg(r.dip_rad - dip), r.samples);
  EXPECT_GT(truth_turn.norm(), deg2rad(0.1));  // there is something to find
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(error(i)), 4.0 * r.sigma_rad(i) + deg2rad(0.01)) << i;
  EXPECT_LT(r.sigma_rad.maxCoeff(), deg2rad(0.05));
  EXPECT_NEAR(rad2deg(r.dip_rad), rad2deg(dip), 0.05);

  // The same phone only turned about its screen's normal: gravity from one direction.
  sim::ImuSimulation flat = sim;
  std::vector<Mat3> poses;
  for (int k = 0; k < 12; ++k) poses.push_back(rot_z(k * M_PI / 6));
  flat.trajectory = sim::static_poses(poses, 1.0, 1.0);
  Capture flat_capture = sim::simulate_imu(flat);
  imu::apply(truth, flat_capture);
  try {
    fit_magnetometer_alignment(flat_capture.require(streams::kAccelerometer),
                               flat_capture.require(streams::kMagnetometer), sim.gravity, {}, "flat");
    FAIL() << "accepted gravity from one direction";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("flat: magnetometer alignment: gravity was seen from too few directions"));
  }
  // Accelerations everywhere (a phone shaken, not turned): nothing at rest-like acceleration.
  Stream shaken = capture.require(streams::kAccelerometer);
  shaken.values *= 1.2;
  try {
    fit_magnetometer_alignment(shaken, capture.require(streams::kMagnetometer), sim.gravity, {}, "shaken");
    FAIL() << "accepted accelerations of 0.2 g";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("shaken: magnetometer alignment: 0 samples at rest-like acceleration"));
  }
}

}  // namespace
}  // namespace antpose::calibration
