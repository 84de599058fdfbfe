#include "antpose/orientation/antpose_filter.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "antpose/orientation/smoother.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "orientation/simulated_truth.hpp"

namespace antpose::orientation {
namespace {

using ::testing::HasSubstr;

using test::errors;
using test::ErrorStats;
using test::Sim;

// This file's simulations use their own seed.
Sim simulate_own_seed(sim::Trajectory trajectory, sim::PhoneModel phone = sim::PhoneModel::ideal(),
                      std::vector<sim::MagneticDisturbance> disturbances = {}) {
  return test::simulate(std::move(trajectory), std::move(phone), std::move(disturbances), 7);
}

constexpr const char* kBoth[] = {"antpose", "antpose-smoother"};

// Largest error over the last `last_s` seconds of the fault-free simulation (the typical phone's
// residual hard iron alone turns the heading by a few degrees).
double baseline_end_error(const char* name, const Sim& baseline, double last_s) {
  Diagnostics diag;
  const auto track = make_estimator(name)->estimate(imu_data_from_capture(baseline.capture, diag), diag);
  const double end = baseline.sim.trajectory.duration();
  return errors(track, baseline.sim.trajectory, end - last_s, end).max_deg;
}

TEST(AntposeFilter, IdealDataBelowATenthOfADegree) {
  const Sim s = simulate_own_seed(sim::random_rotations(6, 2.0, 2.0, 21));
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  const double end = s.sim.trajectory.duration();
  for (const char* name : kBoth) {
    // The simulator samples instantaneous rates.
    const auto track = make_estimator(name, {{"gyro_trapezoid", 1}})->estimate(data, diag);
    ASSERT_TRUE(track.has_uncertainty()) << name;
    const auto e = errors(track, s.sim.trajectory, 0.0, end);
    EXPECT_TRUE(e.finite) << name;
    EXPECT_LT(e.max_deg, 0.1) << name;
  }
}

// A 6°/s gyroscope bias (the iPhone 5 in Tyrex has 5.7°/s): learnt at rest and in motion, the
// error stays bounded and is small once the bias has converged.
TEST(AntposeFilter, LargeGyroscopeBiasEstimated) {
  sim::PhoneModel phone = sim::PhoneModel::ideal();  // no hard iron: the error is the bias's
  phone.gyroscope.noise_density = deg2rad(0.007);
  const Vec3 bias = Vec3(deg2rad(6.0), deg2rad(-3.0), deg2rad(2.0));
  phone.gyroscope.bias = bias;
  const Sim s = simulate_own_seed(sim::random_rotations(8, 3.0, 2.0, 5).hold(10.0), phone);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("bias"));  // the data check warns
  const double end = s.sim.trajectory.duration();
  AntposeFilterParams params;
  params.gyro_trapezoid = true;  // the simulator samples instantaneous rates
  AntposeFilter filter(params, data.gyroscope.median_interval());
  const auto track = run_gyro_driven(filter, data, initial_attitude(data), run_options(filter.params()));
  EXPECT_LT((filter.gyro_bias() - bias).norm(), deg2rad(0.1));
  // Before rest is detected (1.5 s) the bias integrates freely; tilt then heading re-converge.
  EXPECT_LT(errors(track, s.sim.trajectory, 0.0, end).max_deg, 25.0);
  EXPECT_LT(errors(track, s.sim.trajectory, 25.0, end).max_deg, 5.0);
  EXPECT_LT(errors(track, s.sim.trajectory, end - 10.0, end).max_deg, 1.5);
  const auto smoothed = make_estimator("antpose-smoother", {{"gyro_trapezoid", 1}})->estimate(data, diag);
  EXPECT_TRUE(errors(smoothed, s.sim.trajectory, 0.0, end).finite);
  // The smoother averages the heading longer (adaptive τ, smoother.hpp); the 9° lost before rest
  // is detected (a bias 12× its prior σ) re-converges more slowly: 1.96° RMS measured.
  EXPECT_LT(errors(smoothed, s.sim.trajectory, 0.0, end).rms_deg, 2.5);
}

TEST(AntposeFilter, OneSecondGyroscopeGap) {
  Sim s = simulate_own_seed(sim::random_rotations(4, 3.0, 2.0, 9).hold(15.0), sim::PhoneModel::typical());
  const Sim baseline = s;
  test::cut_stream(s.capture, "gyroscope", 6.0, 7.0);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("gap(s) in the gyroscope stream"));
  const double end = s.sim.trajectory.duration();
  for (const char* name : kBoth) {
    const auto track = make_estimator(name)->estimate(data, diag);
    EXPECT_TRUE(errors(track, s.sim.trajectory, 0.0, end).finite) << name;
    EXPECT_NEAR(errors(track, s.sim.trajectory, end - 1.0, end).max_deg, baseline_end_error(name, baseline, 1.0), 1.0)
        << name;
  }
}

TEST(AntposeFilter, SaturatedGyroscope) {
  Sim s = simulate_own_seed(sim::random_rotations(5, 3.0, 0.6, 4).hold(30.0), sim::PhoneModel::typical());
  const Sim baseline = s;
  Stream& g = s.capture.streams.at("gyroscope");
  g.values = g.values.cwiseMax(-2.5).cwiseMin(2.5);  // rad/s: the fast moves exceed it
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("saturated"));
  const double end = s.sim.trajectory.duration();
  for (const char* name : kBoth) {
    const auto track = make_estimator(name)->estimate(data, diag);
    EXPECT_TRUE(errors(track, s.sim.trajectory, 0.0, end).finite) << name;
    // The heading lost while clipped re-converges with tau_mag (9 s): 30 s later within 5°.
    EXPECT_NEAR(errors(track, s.sim.trajectory, end - 1.0, end).max_deg, baseline_end_error(name, baseline, 1.0), 5.0)
        << name;
  }
}

TEST(AntposeFilter, MagnetNearThePhoneRejected) {
  const sim::MagneticDisturbance magnet{10.0, 15.0, Vec3(80.0, 0.0, 30.0)};
  const Sim s =
      simulate_own_seed(sim::random_rotations(5, 4.0, 2.0, 3).hold(20.0), sim::PhoneModel::typical(), {magnet});
  const Sim baseline = simulate_own_seed(sim::random_rotations(5, 4.0, 2.0, 3).hold(20.0), sim::PhoneModel::typical());
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  const double end = s.sim.trajectory.duration();
  for (const char* name : kBoth) {
    Diagnostics own;
    const auto track = make_estimator(name)->estimate(data, own);
    EXPECT_THAT(own.warnings().at(0).to_string(), HasSubstr("magnetic disturbance detected")) << name;
    EXPECT_TRUE(errors(track, s.sim.trajectory, 0.0, end).finite) << name;
    const double base = baseline_end_error(name, baseline, 5.0);
    EXPECT_LT(errors(track, s.sim.trajectory, 9.0, 16.0).max_deg, base + 3.0) << name;
    EXPECT_NEAR(errors(track, s.sim.trajectory, end - 5.0, end).max_deg, base, 1.0) << name;
  }
  // Without rejection the magnet turns the heading far more.
  const auto plain = make_estimator("antpose", {{"mag_rejection", 0}})->estimate(data, diag);
  EXPECT_GT(errors(plain, s.sim.trajectory, 9.0, 16.0).max_deg, baseline_end_error("antpose", baseline, 5.0) + 5.0);
}

TEST(AntposeFilter, NonFiniteSamplesSkippedWithWarning) {
  Sim s = simulate_own_seed(sim::random_rotations(3, 2.0, 2.0, 3));
  Diagnostics diag;
  ImuData data = imu_data_from_capture(s.capture, diag);
  data.accelerometer.v[100] = Vec3(std::nan(""), 0.0, 0.0);
  data.magnetometer.v[50] = Vec3::Zero();
  Diagnostics own;
  const auto track = make_estimator("antpose")->estimate(data, own);
  EXPECT_TRUE(errors(track, s.sim.trajectory, 0.0, 1e9).finite);
  EXPECT_TRUE(own.mentions("non-finite sensor samples were skipped"));
}

TEST(AntposeFilter, SixDofWithoutMagnetometer) {
  Sim s = simulate_own_seed(sim::random_rotations(3, 2.0, 2.0, 3));
  s.capture.streams.erase("magnetometer");
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  try {
    make_estimator("antpose")->estimate(data, diag);
    ADD_FAILURE() << "no exception";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no magnetometer; use mag=0"));
  }
  for (const char* name : kBoth) {
    const auto track = make_estimator(name, {{"mag", 0}, {"gyro_trapezoid", 1}})->estimate(data, diag);
    for (std::size_t i = 0; i < track.size(); i += 50) {
      const Vec3 up_est = track.q_world_device[i].conjugate() * Vec3::UnitZ();
      const Vec3 up_true = s.sim.trajectory.R_world_device(track.t[i]).transpose() * Vec3::UnitZ();
      EXPECT_LT(rad2deg(angle_between(up_est, up_true)), 0.1) << name;
    }
  }
}

TEST(AntposeFilter, ParameterErrors) {
  try {
    make_estimator("antpose", {{"tau_acc", -1.0}});
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("antpose: tau_acc must be > 0 (got -1)"));
  }
  try {
    make_estimator("antpose-smoother", {{"mag", 0.5}});
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("antpose-smoother: mag must be 0 or 1 (got 0.5)"));
  }
}

}  // namespace
}  // namespace antpose::orientation
