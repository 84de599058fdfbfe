#include "antpose/orientation/estimator.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "antpose/orientation/filters.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "orientation/simulated_truth.hpp"

namespace antpose::orientation {
namespace {

using ::testing::HasSubstr;

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(MergeEvents, TimeOrderWithTiesAccMagGyro) {
  ImuData d;
  d.gyroscope = {{0.0, 0.01, 0.02}, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}};
  d.accelerometer = {{0.0, 0.015}, {Vec3::UnitZ(), Vec3::UnitZ()}};
  d.magnetometer = {{0.01}, {Vec3::UnitY()}};
  const auto e = merge_events(d);
  ASSERT_EQ(e.size(), 6u);
  EXPECT_EQ(e[0].sensor, Sensor::kAccelerometer);
  EXPECT_EQ(e[1].sensor, Sensor::kGyroscope);
  EXPECT_EQ(e[2].sensor, Sensor::kMagnetometer);  // t = 0.01 tie: magnetometer before gyroscope
  EXPECT_EQ(e[3].sensor, Sensor::kGyroscope);
  EXPECT_EQ(e[3].index, 1u);
  EXPECT_EQ(e[4].sensor, Sensor::kAccelerometer);
  EXPECT_DOUBLE_EQ(e[5].t, 0.02);
}

TEST(OrientationTrack, SlerpExactAndOutside) {
  OrientationTrack tr;
  tr.method = "test";
  tr.push_back(0.0, Quat::Identity(), Mat3::Identity() * 1e-4);
  tr.push_back(1.0, Quat(Eigen::AngleAxisd(0.4, Vec3::UnitZ())), Mat3::Identity() * 3e-4);
  const auto mid = tr.at(0.5);
  EXPECT_NEAR(mid.q_world_device.angularDistance(Quat(Eigen::AngleAxisd(0.2, Vec3::UnitZ()))), 0.0, 1e-12);
  EXPECT_NEAR((*mid.covariance)(2, 2), 2e-4, 1e-15);
  EXPECT_NEAR(mid.heading_sigma(), std::sqrt(2e-4), 1e-12);
  EXPECT_EQ(tr.at(1.0).q_world_device.coeffs(), tr.q_world_device[1].coeffs());
  const std::string msg = message_of([&] { tr.at(1.5); });
  EXPECT_THAT(msg, HasSubstr("t = 1.5 s is outside"));
  // Sign continuity: −q is stored as q's neighbour.
  Quat neg = tr.q_world_device[1];
  neg.coeffs() *= -1.0;
  tr.push_back(2.0, neg, Mat3::Identity());
  EXPECT_GT(tr.q_world_device[2].coeffs().dot(tr.q_world_device[1].coeffs()), 0.0);
}

// True azimuth = magnetic azimuth + D: a phone whose y axis points to magnetic north points
// D east of true north after the conversion.
TEST(Declination, MagneticToTrue) {
  const double D = deg2rad(10.0);
  OrientationTrack tr;
  tr.method = "test";
  tr.push_back(0.0, Quat::Identity(), Mat3(Vec3(1e-4, 2e-4, 9e-4).asDiagonal()));
  const auto t = apply_declination(tr, D);
  EXPECT_EQ(t.world, "enu-true");
  const Vec3 y_true = t.q_world_device[0] * Vec3::UnitY();
  EXPECT_NEAR(rad2deg(std::atan2(y_true.x(), y_true.y())), 10.0, 1e-9);
  EXPECT_NEAR(t.covariance[0](2, 2), 9e-4, 1e-15);  // heading variance unchanged
  EXPECT_THROW(apply_declination(t, D), std::invalid_argument);
}

TEST(Params, ParsingAndRegistryErrors) {
  const auto p = parse_params({"beta=0.3", "zeta=1e-2"});
  EXPECT_DOUBLE_EQ(p.at("beta"), 0.3);
  EXPECT_DOUBLE_EQ(p.at("zeta"), 0.01);
  EXPECT_THAT(message_of([] { parse_params({"beta"}); }), HasSubstr("'beta' is not name=value"));
  EXPECT_THAT(message_of([] { parse_params({"beta=abc"}); }), HasSubstr("value 'abc' is not a finite number"));
  EXPECT_THAT(message_of([] { parse_params({"beta=1", "beta=2"}); }), HasSubstr("'beta' is given twice"));
  EXPECT_THAT(message_of([] { make_estimator("kalman"); }),
              HasSubstr("unknown orientation method 'kalman' (expected one of ecompass, madgwick"));
  EXPECT_THAT(message_of([] { make_estimator("madgwick", {{"betta", 0.1}}); }),
              HasSubstr("unknown parameter 'betta' for method madgwick (expected beta, zeta, mag)"));
  EXPECT_THAT(message_of([] { make_estimator("mahony", {{"mag", 2}}); }), HasSubstr("mag must be 0 or 1 (got 2)"));
  EXPECT_THAT(message_of([] { make_estimator("madgwick", {{"beta", -1}}); }), HasSubstr("beta must be >= 0"));
  for (const auto& name : estimator_names()) EXPECT_NE(make_estimator(name), nullptr);
}

// ---- simulated ground truth ----------------------------------------------------------------

using test::errors;
using test::ErrorStats;
using test::Sim;

using test::simulate;

TEST(Estimators, IdealDataNearZeroError) {
  const Sim s = simulate(sim::random_rotations(6, 2.0, 2.0, 21));
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.empty()) << diag.warnings().front().to_string();
  const double end = s.sim.trajectory.duration();
  // madgwick-broad is left out: BROAD's initial state (quatFromAccMag) is right only near the
  // BROAD IMU's start pose; see MadgwickBroad.InitialStateOnBroad.
  for (const char* name : {"madgwick", "mahony"}) {
    const auto track = make_estimator(name)->estimate(data, diag);
    const auto e = errors(track, s.sim.trajectory, 0.5, end);
    EXPECT_TRUE(e.finite) << name;
    EXPECT_LT(e.rms_deg, 0.3) << name;
    EXPECT_LT(e.max_deg, 1.0) << name;
  }
  // The eCompass is exact at rest; the centred window lags nothing but smooths the moves.
  const auto ec = make_estimator("ecompass")->estimate(data, diag);
  ASSERT_TRUE(ec.has_uncertainty());
  for (const auto& [h0, h1] : s.sim.trajectory.holds()) {
    const auto e = errors(ec, s.sim.trajectory, h0 + 0.2, h1 - 0.2);
    EXPECT_LT(e.max_deg, 1e-6);
  }
  const auto mid = ec.at(1.0);
  EXPECT_GT(rad2deg(mid.tilt_sigma()), 0.05);  // the 0.02 m/s² floor ≈ 0.12°
  EXPECT_LT(rad2deg(mid.tilt_sigma()), 0.3);
}

TEST(Estimators, ConvergeFromWrongStart) {
  const Sim s = simulate(sim::Trajectory(rot_x(0.4) * rot_z(1.0)).hold(40.0));
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  const Quat wrong = Quat(Eigen::AngleAxisd(deg2rad(60.0), Vec3(1, 1, 1).normalized())) * initial_attitude(data);
  MadgwickFilter madgwick({});
  MahonyFilter mahony({});
  for (GyroDrivenFilter* f : {static_cast<GyroDrivenFilter*>(&madgwick), static_cast<GyroDrivenFilter*>(&mahony)}) {
    const auto track = run_gyro_driven(*f, data, wrong);
    EXPECT_GT(errors(track, s.sim.trajectory, 0.0, 0.1).max_deg, 55.0);
    EXPECT_LT(errors(track, s.sim.trajectory, 35.0, 40.0).max_deg, 0.5);
  }
}

TEST(Estimators, MadgwickZetaLearnsGyroBias) {
  auto phone = sim::PhoneModel::ideal();
  phone.gyroscope.bias = Vec3(deg2rad(6.0), deg2rad(-3.0), deg2rad(2.0));
  const Sim s = simulate(sim::random_rotations(8, 4.0, 2.0, 5), phone);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("gyroscope reads"));
  const double end = s.sim.trajectory.duration();
  MadgwickFilter plain({0.12, 0.0, true}), with_zeta({0.12, 0.05, true});
  const auto e0 = errors(run_gyro_driven(plain, data, initial_attitude(data)), s.sim.trajectory, end / 2, end);
  const auto e1 = errors(run_gyro_driven(with_zeta, data, initial_attitude(data)), s.sim.trajectory, end / 2, end);
  EXPECT_TRUE(e0.finite && e1.finite);
  EXPECT_LT(e0.max_deg, 25.0);  // bounded: β outweighs the 6.9 °/s bias
  EXPECT_LT(e1.rms_deg, 0.5 * e0.rms_deg);
  EXPECT_NEAR(rad2deg(with_zeta.gyro_bias().x()), 6.0, 1.0);
}

// ---- robustness (issue 3): bias, gap, saturation, magnet ----------------------------------
// Each run ends with a long hold so that "bounded" can be checked as "recovered at rest".

constexpr const char* kOurs[] = {"ecompass", "madgwick", "mahony"};

// Mahony's k_I integrator winds up during a fault and unwinds slowly (k_I = 0.0012): measured
// 6.9° (saturation) and 3.6° (magnet) above its baseline 20 s after; Madgwick (ζ = 0) < 1°.
double recovery_tol(const char* name) { return std::string(name) == "mahony" ? 8.0 : 1.0; }

// Max error over the last second of `s` for a method: the baseline a disturbed run must return to
// (the typical phone's residual hard iron and biases leave a few degrees at rest).
double end_error(const char* name, const Sim& s) {
  Diagnostics diag;
  const auto track = make_estimator(name)->estimate(imu_data_from_capture(s.capture, diag), diag);
  const double end = s.sim.trajectory.duration();
  return errors(track, s.sim.trajectory, end - 1.0, end).max_deg;
}

TEST(Robustness, GyroBiasSixDegPerSecond) {
  auto phone = sim::PhoneModel::typical();
  phone.gyroscope.bias = Vec3(deg2rad(6.0), 0.0, 0.0);
  const Sim s = simulate(sim::random_rotations(6, 3.0, 2.0, 8).hold(10.0), phone);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("gyroscope reads")) << "no bias warning";
  const double end = s.sim.trajectory.duration();
  for (const char* name : kOurs) {
    const auto track = make_estimator(name)->estimate(data, diag);
    const auto e = errors(track, s.sim.trajectory, 5.0, end);
    EXPECT_TRUE(e.finite) << name;
    EXPECT_LT(e.rms_deg, 30.0) << name;  // bounded; Mahony's k_I learns the bias slowly
    // Steady state at rest: Madgwick's β and the eCompass ignore the bias; Mahony holds it with a
    // proportional error until k_I has integrated it (measured 34° after 10 s for k_I = 0.0012).
    EXPECT_LT(errors(track, s.sim.trajectory, end - 1.0, end).max_deg, 40.0) << name;
  }
}

TEST(Robustness, OneSecondGapInTheGyroscope) {
  Sim s = simulate(sim::random_rotations(5, 3.0, 2.0, 9).hold(10.0), sim::PhoneModel::typical());
  const Sim baseline = s;
  test::cut_stream(s.capture, "gyroscope", 6.0, 7.0);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("gap(s) in the gyroscope stream, longest 1.0"));
  for (const char* name : {"madgwick", "mahony"}) {
    const auto track = make_estimator(name)->estimate(data, diag);
    const auto e = errors(track, s.sim.trajectory, 0.0, s.sim.trajectory.duration());
    EXPECT_TRUE(e.finite) << name;
    EXPECT_LT(e.max_deg, 120.0) << name;  // the gap's rotation is lost, then corrected
    EXPECT_NEAR(errors(track, s.sim.trajectory, s.sim.trajectory.duration() - 1.0, 1e9).max_deg,
                end_error(name, baseline), 1.0)
        << name;
  }
}

TEST(Robustness, SaturatedGyroscope) {
  Sim s = simulate(sim::random_rotations(5, 3.0, 0.6, 4).hold(20.0), sim::PhoneModel::typical());
  const Sim baseline = s;
  Stream& g = s.capture.streams.at("gyroscope");
  const double limit = 2.5;  // rad/s: the fast moves exceed it
  g.values = g.values.cwiseMax(-limit).cwiseMin(limit);
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("saturated"));
  for (const char* name : {"madgwick", "mahony"}) {
    const auto track = make_estimator(name)->estimate(data, diag);
    const double end = s.sim.trajectory.duration();
    EXPECT_TRUE(errors(track, s.sim.trajectory, 0, end).finite) << name;
    EXPECT_NEAR(errors(track, s.sim.trajectory, end - 1.0, end).max_deg, end_error(name, baseline), recovery_tol(name))
        << name;  // recovered at rest
  }
}

TEST(Robustness, MagnetNearThePhone) {
  const sim::MagneticDisturbance magnet{10.0, 15.0, Vec3(80.0, 0.0, 30.0)};
  const Sim s = simulate(sim::random_rotations(5, 4.0, 2.0, 3).hold(20.0), sim::PhoneModel::typical(), {magnet});
  const Sim baseline = simulate(sim::random_rotations(5, 4.0, 2.0, 3).hold(20.0), sim::PhoneModel::typical());
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_TRUE(diag.mentions("magnetic disturbance"));
  const double end = s.sim.trajectory.duration();
  for (const char* name : kOurs) {
    const auto track = make_estimator(name)->estimate(data, diag);
    EXPECT_TRUE(errors(track, s.sim.trajectory, 0, end).finite) << name;
    if (std::string(name) == "ecompass") continue;  // per-sample: wrong by the disturbance, right again after
    EXPECT_LT(errors(track, s.sim.trajectory, 10.0, 15.0).max_deg, 120.0) << name;
    EXPECT_NEAR(errors(track, s.sim.trajectory, end - 1.0, end).max_deg, end_error(name, baseline), recovery_tol(name))
        << name;
  }
}

TEST(Robustness, MissingMagnetometer) {
  Sim s = simulate(sim::random_rotations(3, 2.0, 2.0, 3));
  s.capture.streams.erase("magnetometer");
  Diagnostics diag;
  const ImuData data = imu_data_from_capture(s.capture, diag);
  EXPECT_THAT(message_of([&] { make_estimator("madgwick")->estimate(data, diag); }),
              HasSubstr("no magnetometer; use mag=0"));
  // 6-D: inclination still right.
  const auto track = make_estimator("madgwick", {{"mag", 0}})->estimate(data, diag);
  for (std::size_t i = 0; i < track.size(); i += 50) {
    const Vec3 up_est = track.q_world_device[i].conjugate() * Vec3::UnitZ();
    const Vec3 up_true = s.sim.trajectory.R_world_device(track.t[i]).transpose() * Vec3::UnitZ();
    EXPECT_LT(rad2deg(angle_between(up_est, up_true)), 1.0);
  }
}

}  // namespace
}  // namespace antpose::orientation
