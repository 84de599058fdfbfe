// All 9 parameters of the accelerometer and gyroscope models recovered from simulated
// multi-position captures (sim::calibration_poses, PhoneModel::random) within their
// noise-limited bounds: 4σ of the fit's covariance (σ̂²(JᵀJ)⁻¹; calibrated against a Monte
// Carlo over seeds in tests/long/calibration_monte_carlo_test.cpp).
#include <cmath>
#include <cstdio>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/calibration/static_frames.hpp"
#include "sim_recovery_support.hpp"

namespace antpose::calibration {
static const char* kAccNames[9] = {"t01", "t02", "t12", "k0", "k1", "k2", "b0", "b1", "b2"};
static const char* kGyroNames[9] = {"t01", "t02", "t10", "t12", "t20", "t21", "k0", "k1", "k2"};
namespace {

class SimRecovery : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(SimRecovery, AllNineParametersOfEachSensorWithinFourSigma) {
  const auto s = test::simulate_calibration(GetParam());
  const auto frames = collect_static_frames(s.capture);
  ASSERT_EQ(frames.size(), 18u);
  std::vector<Vec3> means;
  for (const auto& f : frames) means.push_back(f.acc_mean);
  const auto thesis = fit_accelerometer_thesis(means, s.gravity);
  const auto acc = fit_accelerometer_full(means, s.gravity, thesis);
  EXPECT_LT(acc.rms_after, thesis.rms_after);
  const auto ea = test::acc_errors(acc, s);
  const double walk = test::bias_walk_sigma(s.phone.accelerometer, s.capture.require(streams::kAccelerometer).duration());
  Eigen::Matrix<double, 9, 1> bound = acc.sigma;
  for (int i = 6; i < 9; ++i) bound[i] = std::hypot(acc.sigma[i], walk);
  for (int i = 0; i < 9; ++i) {
    ASSERT_GT(acc.sigma[i], 0.0);
    EXPECT_LT(std::abs(ea[i]), 4.0 * bound[i]) << "accelerometer " << kAccNames[i] << " error " << ea[i] << " σ " << bound[i];
  }
  const auto gyro = fit_gyroscope(s.capture.require(streams::kGyroscope), frames, acc);
  EXPECT_LT(gyro.rms_after, gyro.rms_bias_only);
  const auto eg = test::gyro_errors(gyro, s);
  for (int i = 0; i < 9; ++i) {
    ASSERT_GT(gyro.sigma[i], 0.0);
    EXPECT_LT(std::abs(eg[i]), 4.0 * gyro.sigma[i]) << "gyroscope " << kGyroNames[i] << " error " << eg[i] << " σ " << gyro.sigma[i];
  }
  // The gyroscope bias is a mean over ≈ 36 s of static samples (white noise N/√36 s) and
  // departs from b by the walk's mean (bias_walk_sigma).
  const double gyro_bound = std::hypot(s.phone.gyroscope.noise_density / std::sqrt(36.0),
                                       test::bias_walk_sigma(s.phone.gyroscope, s.capture.require(streams::kGyroscope).duration()));
  EXPECT_LT((gyro.bias - s.gyro_b).cwiseAbs().maxCoeff(), 4.0 * gyro_bound);
  std::printf("seed %llu: acc rms %.4f -> %.4f -> %.5f m/s²; |err|/σ max %.2f; gyro rms %.3f -> %.4f°, |err|/σ max %.2f\n",
              static_cast<unsigned long long>(GetParam()), acc.rms_before, thesis.rms_after, acc.rms_after,
              ea.cwiseQuotient(bound).cwiseAbs().maxCoeff(), gyro.rms_bias_only * 180 / M_PI, gyro.rms_after * 180 / M_PI,
              eg.cwiseQuotient(gyro.sigma).cwiseAbs().maxCoeff());
  std::printf("  acc σ: misalignment %.2e %.2e %.2e rad, scale %.2e %.2e %.2e, bias %.2e %.2e %.2e m/s²\n", acc.sigma[0],
              acc.sigma[1], acc.sigma[2], acc.sigma[3], acc.sigma[4], acc.sigma[5], acc.sigma[6], acc.sigma[7], acc.sigma[8]);
  std::printf("  gyro σ: misalignment %.2e %.2e %.2e %.2e %.2e %.2e rad, scale %.2e %.2e %.2e\n", gyro.sigma[0], gyro.sigma[1],
              gyro.sigma[2], gyro.sigma[3], gyro.sigma[4], gyro.sigma[5], gyro.sigma[6], gyro.sigma[7], gyro.sigma[8]);
}

INSTANTIATE_TEST_SUITE_P(Seeds, SimRecovery, ::testing::Values(1, 2, 3));

}  // namespace
}  // namespace antpose::calibration

namespace antpose::calibration {
namespace {

TEST(SimRecovery, NoiseFreeSensorWithErrorsIsRecoveredExactly) {
  // Without noise, bias walk and jitter, what is left is the integration and detection error.
  std::mt19937_64 rng(11);
  sim::PhoneModel phone = sim::PhoneModel::random(rng);
  for (auto* s : {&phone.accelerometer, &phone.gyroscope}) s->noise_density = s->bias_random_walk = s->rate_jitter_s = 0.0;
  sim::ImuSimulation sim;
  sim.phone = phone;
  sim.trajectory = sim::static_poses(sim::calibration_poses(), 3.0, 2.0);
  const Capture capture = sim::simulate_imu(sim);
  const auto frames = collect_static_frames(capture);
  std::vector<Vec3> means;
  for (const auto& f : frames) means.push_back(f.acc_mean);
  const auto acc = fit_accelerometer_full(means, sim.gravity, fit_accelerometer_thesis(means, sim.gravity));
  EXPECT_LT(acc.rms_after, 1e-5);
  const auto gyro = fit_gyroscope(capture.require(streams::kGyroscope), frames, acc);
  Mat3 T, Q;
  Vec3 k;
  canonical_accelerometer((phone.accelerometer.misalignment * phone.accelerometer.scale.asDiagonal()).inverse(), T, k, &Q);
  EXPECT_LT((acc.misalignment - T).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((acc.scale - k).cwiseAbs().maxCoeff(), 1e-6);
  canonical_gyroscope(Q.transpose() * (phone.gyroscope.misalignment * phone.gyroscope.scale.asDiagonal()).inverse(), T, k);
  std::printf("noise-free: gyro residual %.5f°, misalignment error %.2e, scale error %.2e\n", gyro.rms_after * 180 / M_PI,
              (gyro.misalignment - T).cwiseAbs().maxCoeff(), (gyro.scale - k).cwiseAbs().maxCoeff());
  EXPECT_LT(gyro.rms_after * 180 / M_PI, 0.01);
  EXPECT_LT((gyro.misalignment - T).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((gyro.scale - k).cwiseAbs().maxCoeff(), 1e-4);
}

}  // namespace
}  // namespace antpose::calibration

namespace antpose::calibration {
namespace {

// Monte Carlo over seeds (each a new random phone, noise and bias walk): the covariance σ must
// describe the actual spread (RMS of error/σ near 1), which is what makes 4σ a noise-limited
// bound (for the accelerometer bias together with the bias walk, see bias_walk_sigma). Also prints the absolute spread of each parameter (the bounds in physical units).
TEST(SimRecovery, CovarianceMatchesMonteCarloSpread) {
  constexpr int kSeeds = 40;
  Eigen::Matrix<double, 9, 1> za = Eigen::Matrix<double, 9, 1>::Zero(), zg = za, ea2 = za, eg2 = za;
  for (int seed = 100; seed < 100 + kSeeds; ++seed) {
    const auto s = test::simulate_calibration(static_cast<std::uint64_t>(seed));
    const auto frames = collect_static_frames(s.capture);
    std::vector<Vec3> means;
    for (const auto& f : frames) means.push_back(f.acc_mean);
    const auto acc = fit_accelerometer_full(means, s.gravity, fit_accelerometer_thesis(means, s.gravity));
    const auto gyro = fit_gyroscope(s.capture.require(streams::kGyroscope), frames, acc);
    const auto ea = test::acc_errors(acc, s), eg = test::gyro_errors(gyro, s);
    Eigen::Matrix<double, 9, 1> bound = acc.sigma;
    const double walk = test::bias_walk_sigma(s.phone.accelerometer, s.capture.require(streams::kAccelerometer).duration());
    for (int i = 6; i < 9; ++i) bound[i] = std::hypot(acc.sigma[i], walk);
    za += ea.cwiseQuotient(bound).array().square().matrix();
    zg += eg.cwiseQuotient(gyro.sigma).array().square().matrix();
    ea2 += ea.array().square().matrix();
    eg2 += eg.array().square().matrix();
  }
  za = (za / kSeeds).cwiseSqrt();
  zg = (zg / kSeeds).cwiseSqrt();
  ea2 = (ea2 / kSeeds).cwiseSqrt();
  eg2 = (eg2 / kSeeds).cwiseSqrt();
  for (int i = 0; i < 9; ++i) {
    EXPECT_GT(za[i], 0.5) << kAccNames[i];
    EXPECT_LT(za[i], 1.6) << kAccNames[i];
    EXPECT_GT(zg[i], 0.5) << kGyroNames[i];
    EXPECT_LT(zg[i], 1.6) << kGyroNames[i];
  }
  std::printf("Monte Carlo (%d seeds) RMS(error/σ): acc", kSeeds);
  for (int i = 0; i < 9; ++i) std::printf(" %s %.2f", kAccNames[i], za[i]);
  std::printf("\n  gyro");
  for (int i = 0; i < 9; ++i) std::printf(" %s %.2f", kGyroNames[i], zg[i]);
  std::printf("\n  RMS errors: acc misalignment %.1e %.1e %.1e rad, scale %.1e %.1e %.1e, bias %.1e %.1e %.1e m/s²\n",
              ea2[0], ea2[1], ea2[2], ea2[3], ea2[4], ea2[5], ea2[6], ea2[7], ea2[8]);
  std::printf("  gyro misalignment %.1e %.1e %.1e %.1e %.1e %.1e rad, scale %.1e %.1e %.1e\n", eg2[0], eg2[1], eg2[2],
              eg2[3], eg2[4], eg2[5], eg2[6], eg2[7], eg2[8]);
}

}  // namespace
}  // namespace antpose::calibration
