// The classic attitude filters, as GyroDrivenFilter steps (estimator.hpp), and the eCompass.
//
// Madgwick (S. O. H. Madgwick, "An efficient orientation filter for inertial and
// inertial/magnetic sensor arrays", report x-io / Univ. of Bristol, 2010):
//   q̇ = ½ q ⊗ (0, ω_c) − β ∇f/‖∇f‖                                  (eq. 42-44)
//   IMU:  f = f_g(q, â)          ∇f = J_gᵀ f_g                          (eq. 25-26)
//   MARG: f = [f_g; f_b(q, b, m̂)] ∇f = [J_g; J_b]ᵀ f                   (eq. 31-34)
//   Earth field reference from the current measurement and the previous estimate:
//   h = q ⊗ m̂ ⊗ q*, b = (√(h_x² + h_y²), 0, h_z)                       (eq. 45-46)
//   Gyroscope bias drift: ω_ε = 2 q* ⊗ ∇f/‖∇f‖, ω_b = ζ Σ ω_ε Δt, ω_c = ω − ω_b  (eq. 47-49)
// The filter's Earth frame is x = magnetic north, z = up (NWU); we convert to ENU by
// q_enu = Rz(+90°) ⊗ q_nwu. This implements the report's equations with b itself in f_b; the
// reference C code (MadgwickAHRS.c, 2011/2012) stores b in variables named 2b and so halves the
// field reference (BROAD issue #1). `MadgwickBroadFilter` keeps that code's behaviour bit for
// bit (single precision, fixed 1/sampleFreq, its normalisation order) to validate the benchmark
// against BROAD's published numbers; do not use it for measurements.
//
// Mahony (R. Mahony, T. Hamel, J.-M. Pflimlin, "Nonlinear complementary filters on the special
// orthogonal group", IEEE TAC 53(5), 2008, explicit complementary filter, eq. 32):
//   ω_mes = Σ_i k_i v_i × v̂_i,  q̇ = ½ q ⊗ (ω_y − b̂ + k_P ω_mes),  ḃ = −k_I ω_mes,
// with v the measured directions (gravity, field) and v̂ = R̂ᵀ v₀ their predictions. As in
// Madgwick's widely used implementation, the field reference v₀ is rebuilt from each measurement
// (horizontal component along x, vertical kept), so the field corrects heading and tilt alike.
// Here integrated with the exact quaternion exponential.
#pragma once

#include <optional>

#include "antpose/orientation/estimator.hpp"

namespace antpose::orientation {

struct MadgwickParams {
  double beta = 0.12;  // rad/s, gradient step gain (BROAD's TAGP for Madgwick)
  double zeta = 0.0;   // rad/s², gyroscope bias drift gain
  bool use_magnetometer = true;  // false: IMU filter (6-D)
};

/// Madgwick's filter as the 2010 report defines it (double precision).
class MadgwickFilter final : public GyroDrivenFilter {
 public:
  explicit MadgwickFilter(const MadgwickParams& params);
  void reset(const Quat& q_world_device) override;
  void update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) override;
  Quat q_world_device() const override;
  Vec3 gyro_bias() const { return bias_; }  // rad/s, device frame (ζ > 0)

 private:
  MadgwickParams p_;
  Eigen::Vector4d q_{1, 0, 0, 0};  // q_nwu_device (w, x, y, z)
  Vec3 bias_ = Vec3::Zero();
};

/// MadgwickAHRS.cpp as shipped with BROAD (float, sampleFreq fixed, (2bx, 2bz) defect).
class MadgwickBroadFilter final : public GyroDrivenFilter {
 public:
  MadgwickBroadFilter(float beta, float sample_freq_hz);
  void reset(const Quat& q_world_device) override;  // stored as float, in the NWU frame
  /// dt is ignored (the code integrates over 1/sampleFreq).
  void update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) override;
  Quat q_world_device() const override;
  /// Sets the internal (NWU) state directly, as BROAD's setState.
  void set_state_nwu(const Quat& q_nwu_device);

 private:
  void update_imu(float gx, float gy, float gz, float ax, float ay, float az);
  float beta_, sample_freq_;
  float q0_ = 1.0f, q1_ = 0.0f, q2_ = 0.0f, q3_ = 0.0f;
};

/// BROAD's initial state (process_data.py, quatFromAccMag): R = [x y z] with z = acc,
/// x = (z × −mag) × z, y = z × x, converted by quatFromRotMat; in the Madgwick (NWU) frame.
Quat broad_initial_state(const Vec3& acc, const Vec3& mag);

struct MahonyParams {
  double kp = 0.74;    // rad/s per unit error (BROAD's TAGP for Mahony)
  double ki = 0.0012;  // rad/s² per unit error
  bool use_magnetometer = true;
};

class MahonyFilter final : public GyroDrivenFilter {
 public:
  explicit MahonyFilter(const MahonyParams& params);
  void reset(const Quat& q_world_device) override;
  void update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) override;
  Quat q_world_device() const override;
  Vec3 gyro_bias() const { return bias_; }

 private:
  MahonyParams p_;
  Quat q_nwu_device_ = Quat::Identity();
  Vec3 bias_ = Vec3::Zero();
};

/// Quaternion of the +90° rotation about up that takes Madgwick's NWU Earth frame to ENU.
Quat q_enu_nwu();

struct EcompassParams {
  double window_s = 0.2;            // centred moving-average window for acc and mag
  double acc_bias_floor_mps2 = 0.02;  // as StaticOrientationOptions
  double mag_residual_uT = 1.0;
};

/// eCompass per accelerometer sample: TRIAD (triad_world_device, thesis §4.4) of the
/// accelerometer and magnetometer averaged over a centred window (acausal by half a window).
/// Uncertainty: tilt σ = (RMS scatter of the window's accelerometer samples + bias floor +
/// | |f̄| − g₀ |) / g₀ with g₀ = the median |f| of the log (linear acceleration shows as scatter
/// and as a norm change); heading σ = (field scatter + residual hard iron/√3) / H ⊕ tilt σ·tan(dip).
/// A heuristic 1σ, not a calibrated one.
OrientationTrack ecompass_track(const ImuData& data, const EcompassParams& params);

}  // namespace antpose::orientation
