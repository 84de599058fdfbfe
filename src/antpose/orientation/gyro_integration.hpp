// The device's rotation over an interval from the gyroscope alone
// ("preintegration"), with its first-order sensitivity to a constant gyro-bias
// correction (Forster, Carlone, Dellaert & Scaramuzza, "On-Manifold
// Preintegration for Real-Time Visual–Inertial Odometry", IEEE T-RO 33(1),
// 2017, eqs. 38 and 44).
//
// Why: over a few tens of seconds a calibrated gyroscope gives the relative
// rotation of the phone far more accurately than any filter's absolute
// attitude, whose tilt follows the accelerometer and so leans into every linear
// acceleration (walking around a board leans it towards the board, nearly
// constantly in the device frame, which no hand–eye method can tell from
// R_device_camera).
//
// Frames: device frame d of the conventions. ΔR(t) = R_world_device(t0)ᵀ
// R_world_device(t), i.e. it rotates device-frame vectors at t into the device
// frame at t0. Rates in rad/s. Sample convention as the estimators
// (OrientationOptions::gyro_trapezoid): sample k's rate ω_k acts over (t_{k−1},
// t_k], or with `trapezoid` the mean (ω_{k−1} + ω_k)/2 does.
#pragma once

#include <vector>

#include "antpose/geometry/rotation.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::orientation {

class GyroIntegration {
 public:
  /// Integrates `gyroscope` (`bias` subtracted) over [t0, t1] (clamped to the
  /// stream's span). A gap in the stream is integrated with its rate held:
  /// callers that cannot accept that check longest_step_s().
  /// std::invalid_argument for fewer than 2 samples or t1 < t0.
  GyroIntegration(const SensorSeries& gyroscope, double t0, double t1, const Vec3& bias = Vec3::Zero(),
                  bool trapezoid = false);

  struct Sample {
    Mat3 R;  // ΔR(t), device(t) → device(t0)
    Mat3 J;  // ∂/∂δb: ΔR(t; bias + δb) ≈ ΔR(t) exp(J δb)
  };
  /// ΔR and J at t in [t0, t1] (t outside is clamped), between samples by a
  /// partial step of the interval's rate.
  Sample at(double t) const;
  /// Body-frame rate acting at t (so ΔR(t + ε) ≈ ΔR(t) exp(ω ε)), bias removed.
  Vec3 rate(double t) const;

  double t0() const { return t_.front(); }
  double t1() const { return t_.back(); }
  const Vec3& bias() const { return bias_; }
  /// Longest interval between samples inside [t0, t1] (s).
  double longest_step_s() const { return longest_step_; }
  /// Time of that interval's start, for messages.
  double longest_step_at() const { return longest_at_; }

 private:
  std::vector<double> t_;    // t0, the samples inside (t0, t1), t1
  std::vector<Vec3> w_;      // rate acting over (t_{k−1}, t_k], w_[0] unused
  std::vector<Mat3> R_, J_;  // at t_k
  Vec3 bias_;
  double longest_step_ = 0.0, longest_at_ = 0.0;
};

/// Right Jacobian of SO(3), J_r(φ) (Forster et al. eq. 8): exp(φ + δ) ≈ exp(φ)
/// exp(J_r(φ) δ).
Mat3 right_jacobian_so3(const Vec3& phi);

}  // namespace antpose::orientation
