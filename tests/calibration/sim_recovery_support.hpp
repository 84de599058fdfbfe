// Simulated multi-position calibration captures and their canonical truth (shared by the
// calibration tests and the long Monte Carlo test).
#pragma once

#include <cmath>
#include <random>

#include "antpose/calibration/accelerometer.hpp"
#include "antpose/calibration/gyroscope.hpp"
#include "antpose/sim/imu_simulator.hpp"

namespace antpose::test {

struct SimulatedCalibration {
  Capture capture;
  sim::PhoneModel phone;
  // Truth in the fitted parameterisation: accelerometer (T upper triangular, k, b) and the
  // gyroscope in the calibrated accelerometer frame (T full, k, b).
  Mat3 acc_T, gyro_T;
  Vec3 acc_k, gyro_k, acc_b, gyro_b;
  double gravity = 9.80665;
};

inline SimulatedCalibration simulate_calibration(std::uint64_t seed, double hold_s = 3.0, double move_s = 2.0) {
  SimulatedCalibration s;
  std::mt19937_64 rng(seed);
  s.phone = sim::PhoneModel::random(rng);
  sim::ImuSimulation sim;
  sim.phone = s.phone;
  sim.kind = "imu-calibration";
  sim.seed = seed;
  sim.trajectory = sim::static_poses(sim::calibration_poses(), hold_s, move_s);
  s.gravity = sim.gravity;
  s.capture = sim::simulate_imu(sim);
  const auto& a = s.phone.accelerometer;
  const auto& g = s.phone.gyroscope;
  Mat3 Q;
  calibration::canonical_accelerometer((a.misalignment * a.scale.asDiagonal()).inverse(), s.acc_T, s.acc_k, &Q);
  calibration::canonical_gyroscope(Q.transpose() * (g.misalignment * g.scale.asDiagonal()).inverse(), s.gyro_T,
                                   s.gyro_k);
  s.acc_b = a.bias;
  s.gyro_b = g.bias;
  return s;
}

/// The bias truth is the constant b at t = 0, but the simulated bias also walks (rate random
/// walk K); a calibration can only find the walk's mean over the recording, whose spread about b
/// is K·sqrt(T/3) (variance of the mean of a Wiener process over T). The noise-limited bound of a
/// bias is therefore sqrt(σ_fit² + K² T / 3).
inline double bias_walk_sigma(const sim::InertialSensorErrors& e, double duration_s) {
  return e.bias_random_walk * std::sqrt(duration_s / 3.0);
}

/// Errors (fit − truth) in the order of AccelerometerCalibration::sigma.
inline Eigen::Matrix<double, 9, 1> acc_errors(const calibration::AccelerometerCalibration& c,
                                              const SimulatedCalibration& s) {
  Eigen::Matrix<double, 9, 1> e;
  e << c.misalignment(0, 1) - s.acc_T(0, 1), c.misalignment(0, 2) - s.acc_T(0, 2), c.misalignment(1, 2) - s.acc_T(1, 2),
      c.scale - s.acc_k, c.bias - s.acc_b;
  return e;
}

/// Errors in the order of GyroscopeCalibration::sigma (plus the bias, not in sigma).
inline Eigen::Matrix<double, 9, 1> gyro_errors(const calibration::GyroscopeCalibration& c,
                                               const SimulatedCalibration& s) {
  Eigen::Matrix<double, 9, 1> e;
  const Mat3 d = c.misalignment - s.gyro_T;
  e << d(0, 1), d(0, 2), d(1, 0), d(1, 2), d(2, 0), d(2, 1), c.scale - s.gyro_k;
  return e;
}

}  // namespace antpose::test
