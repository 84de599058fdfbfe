// antpose's causal attitude filter (registry name `antpose`), a GyroDrivenFilter (estimator.hpp).
//
// Design after D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with bias
// estimation and magnetic disturbance rejection", Information Fusion 91:187–204, 2023 (§3–4);
// own implementation, own parameter choices (bias clip, uncertainty model):
//  - strapdown integration of the bias-corrected gyroscope into q_I_device, I an almost-inertial
//    frame (eq. 4 of the paper: exact quaternion exponential);
//  - inclination: the specific force rotated into I, low-pass filtered there by a second-order
//    Butterworth (time constant tau_acc, f_c = √2 / (2π τ)), rotated by the inclination
//    correction q_E_I and fully re-aligned with the vertical each step (the low-pass sets the
//    time constant, so linear acceleration averages out instead of tilting the estimate);
//  - heading decoupled: the field in the 6-D earth frame gives a scalar heading disagreement
//    δ_m = atan2(m_x, m_y) − δ, corrected by a first-order gain k = 1 − exp(−T/τ_mag) about
//    the vertical only, so the magnetometer never tilts the estimate;
//    q_world_device = Rz(δ) ⊗ q_E_I ⊗ q_I_device (world = ENU, y = magnetic north);
//  - gyroscope bias b (device frame) by a 3-state Kalman filter, updated with scalar
//    (sequential) measurements — no matrix inverse: at rest (gyro and acc deviations from their
//    0.5 s low-pass below thresholds for rest_min_s) the low-passed gyro is a direct
//    measurement of b; in motion the inclination correction rate (−a_y/T, a_x/T) in the earth
//    frame measures R_E_device b (H = low-passed R rows), plus a weak pseudo-measurement pulling
//    the vertical component to zero (paper §4.3);
//  - magnetic disturbance: field norm and dip (in the 6-D earth frame, low-passed) against a
//    reference learned while undisturbed; outside |Δnorm| < mag_norm_th·ref or |Δdip| <
//    mag_dip_th the heading correction stops, for at most mag_max_reject_s, then resumes at a
//    reduced gain; a new field that stays consistent for mag_new_s while the device rotates is
//    accepted as the new reference (paper §4.4), so heading re-converges after long disturbances.
// Uncertainty (own, heuristic 1σ for weighting): the heading and tilt standard deviations grow
// with the bias standard deviation × dt (a constant bias error integrates linearly) and relax
// towards floors with the correction gains: σ² ← (1−k)σ² + k σ_floor². Reported as the
// diagonal covariance diag(σ_i², σ_i², σ_h²) in the world frame.
#pragma once

#include <cstddef>

#include "antpose/orientation/estimator.hpp"

namespace antpose::orientation {

/// Default adaptive-heading drift budget of the offline smoother, degrees (smoother.hpp).
inline constexpr double kSmootherDriftBudgetDeg = 3.0;

struct AntposeFilterParams {
  double tau_acc_s = 3.0;   // inclination low-pass time constant
  double tau_mag_s = 9.0;   // heading correction time constant (the shortest when adaptive)
  // Adaptive heading time constant (0: off, tau_mag_s fixed): the magnetometer heading is
  // averaged over the longest window τ in which the gyroscope's drift σ_b·τ (σ_b the bias
  // filter's current standard deviation) stays within this budget, τ ∈ [tau_mag_s, tau_mag_max_s].
  double mag_drift_budget = 0.0;  // rad
  double tau_mag_max_s = 60.0;
  double mag_long_max_sigma = deg2rad(15.0);  // rad: above this heading σ, tau_mag_s is used
  // Gyroscope clip level (rad/s, 0: unknown). The smoother sets it from the whole log
  // (gyro_saturation); samples at it grow the attitude σ.
  double gyro_clip_rad_s = 0.0;
  bool use_magnetometer = true;
  // false: a gyroscope sample is the mean rate over the interval before it (VQF's convention;
  // BROAD is scored best so); true: samples are instantaneous rates and the step integrates the
  // trapezoidal mean of consecutive samples (simulated and many phone streams).
  bool gyro_trapezoid = false;
  // bias estimation
  bool motion_bias = true;
  bool rest_bias = true;
  double bias_sigma_init = deg2rad(0.5);     // rad/s
  double bias_forgetting_s = 100.0;          // process noise: (0.1°/s)² per bias_forgetting_s
  // rad/s, steady-state σ from motion updates. 0.3°/s rather than VQF's tighter setting: phone
  // logs (Tyrex) walk with linear acceleration and stream skew that a tighter motion update
  // turns into bias (Thibaud NoDist heading 9.2° at 0.1°/s, 5.6° at 0.3°/s; BROAD unchanged).
  double bias_sigma_motion = deg2rad(0.3);
  double bias_vertical_factor = 1e-4;        // weight of the vertical-bias pseudo-measurement
  double bias_sigma_rest = deg2rad(0.03);    // rad/s
  double bias_clip = deg2rad(8.0);           // rad/s, |b| limit (the iPhone 5 has 5.7°/s)
  // rest detection
  double rest_min_s = 1.5;
  double rest_tau_s = 0.5;
  double rest_gyro_th = deg2rad(2.0);  // rad/s
  double rest_acc_th = 0.5;            // m/s²
  // magnetic disturbance
  bool mag_rejection = true;
  double mag_current_tau_s = 0.05;
  double mag_ref_tau_s = 20.0;
  double mag_norm_th = 0.1;             // relative
  double mag_dip_th = deg2rad(10.0);    // rad
  double mag_new_s = 20.0;
  double mag_new_first_s = 5.0;
  double mag_new_min_gyro = deg2rad(20.0);  // rad/s
  double mag_min_undisturbed_s = 0.5;
  double mag_max_reject_s = 60.0;
  double mag_reject_factor = 2.0;
  // uncertainty model
  double tilt_floor = deg2rad(0.5);     // rad
  double heading_floor = deg2rad(1.5);  // rad
  double tilt_sigma_init = deg2rad(3.0);
  double heading_sigma_init = deg2rad(10.0);
};

/// The filter at a fixed nominal sample interval `Ts` (s, the gyroscope's median interval; the
/// gains are computed once for it, the strapdown integration uses each step's dt).
class AntposeFilter final : public GyroDrivenFilter {
 public:
  AntposeFilter(const AntposeFilterParams& params, double Ts);
  void reset(const Quat& q_world_device) override;
  void update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) override;
  /// As update, with the age (s, ≥ 0) of the held accelerometer / magnetometer samples: they
  /// are carried to the gyroscope instant by the rotation since (v ← v − age ω × v), so
  /// asynchronous streams do not tilt the estimate while the device turns.
  void update_with_ages(double dt, const Vec3& gyro, const Vec3* acc, double acc_age, const Vec3* mag,
                        double mag_age) override;
  Quat q_world_device() const override;
  std::optional<Mat3> covariance() const override;

  /// Bias (rad/s, device frame) and its σ (rad/s) that reset() starts from (default 0 and
  /// bias_sigma_init), e.g. a smoother's other pass.
  void set_initial_bias(const Vec3& bias, double sigma) { bias0_ = bias, bias0_sigma_ = sigma; }
  /// Field reference (norm µT, dip rad) that reset() starts from instead of the first sample.
  void set_initial_mag_reference(double norm, double dip) { ref0_norm_ = norm, ref0_dip_ = dip; }
  double mag_reference_norm() const { return ref_norm_; }
  double mag_reference_dip() const { return ref_dip_; }
  Vec3 gyro_bias() const { return bias_; }  // rad/s, device frame
  const AntposeFilterParams& params() const { return p_; }
  double bias_sigma() const;                // rad/s, RMS over axes
  bool at_rest() const { return rest_; }
  bool mag_disturbed() const { return mag_disturbed_; }
  double heading_sigma() const { return sigma_h_; }  // rad
  double tilt_sigma() const { return sigma_i_; }     // rad
  /// Seconds during which the heading correction was suspended for a detected disturbance.
  double rejected_s() const { return rejected_total_s_; }
  std::size_t nonfinite_inputs() const { return nonfinite_; }
  /// Gyroscope samples at the clip level (gyro_clip_rad_s).
  std::size_t clipped_samples() const { return clipped_; }

 private:
  struct Butter2 {  // second-order low-pass, direct form II transposed
    double b0 = 0, b1 = 0, b2 = 0, a1 = 0, a2 = 0;
    void design(double tau, double Ts);
  };
  void update_acc(const Vec3& acc);
  void update_bias();
  void update_rest(const Vec3& gyro, const Vec3* acc);
  void update_mag(const Vec3& mag);
  void scalar_bias_update(const Vec3& h, double innovation, double w);

  AntposeFilterParams p_;
  double Ts_;
  Butter2 acc_lp_;
  double k_rest_ = 0, k_mag_ = 0, k_mag_current_ = 0, k_mag_ref_ = 0, k_acc_ = 0;
  double bias_v_ = 0, w_motion_ = 0, w_vertical_ = 0, w_rest_ = 0;

  Quat q_I_device_ = Quat::Identity();
  Quat q_E_I_ = Quat::Identity();
  double delta_ = 0.0;  // heading offset about up, rad

  bool acc_init_ = false;
  Vec3 acc_s0_ = Vec3::Zero(), acc_s1_ = Vec3::Zero();  // Butterworth states (I frame)
  Vec3 acc_earth_ = Vec3::UnitZ();                      // last low-passed, normalised, E frame
  bool acc_fresh_ = false;

  Vec3 bias0_ = Vec3::Zero();
  double bias0_sigma_ = -1.0;
  Vec3 bias_ = Vec3::Zero();
  Mat3 P_ = Mat3::Zero();
  bool R_init_ = false;
  double R_s0_[8] = {}, R_s1_[8] = {};  // low-pass states of R rows 0–1 and of R b (x, y)
  double R_lp_[8] = {};

  bool rest_init_ = false;
  Vec3 gyro_lp_ = Vec3::Zero(), acc_rest_lp_ = Vec3::Zero();
  double rest_t_ = 0.0;
  bool rest_ = false;

  bool mag_init_ = false;
  double norm_lp_ = 0, dip_lp_ = 0;
  double ref_norm_ = 0, ref_dip_ = 0;
  double ref0_norm_ = 0, ref0_dip_ = 0;
  double cand_norm_ = 0, cand_dip_ = 0, cand_t_ = 0;
  double undisturbed_t_ = 0, reject_t_ = 0;
  bool mag_disturbed_ = false;
  double rejected_total_s_ = 0;

  double sigma_h_ = 0, sigma_i_ = 0;
  std::size_t nonfinite_ = 0, clipped_ = 0;
};

/// run_gyro_driven options for this filter (the gyroscope sample convention of its params).
inline GyroDrivenOptions run_options(const AntposeFilterParams& params) {
  GyroDrivenOptions options;
  options.gyro_trapezoid = params.gyro_trapezoid;
  return options;
}

/// Registry wrapper: runs AntposeFilter with run_gyro_driven from initial_attitude; warns when
/// the heading correction was suspended for magnetic disturbances or inputs were not finite.
class AntposeEstimator final : public OrientationEstimator {
 public:
  explicit AntposeEstimator(const AntposeFilterParams& params) : p_(params) {}
  std::string name() const override { return "antpose"; }
  bool causal() const override { return true; }
  OrientationTrack estimate(const ImuData& data, Diagnostics& diagnostics) const override;
  const AntposeFilterParams& params() const { return p_; }

 private:
  AntposeFilterParams p_;
};

/// The parameters exposed to --param (name, default, help) and their mapping. `offline`: the
/// smoother's defaults (adaptive heading time constant on, see smoother.hpp).
std::vector<ParamSpec> antpose_filter_param_specs(bool offline = false);
AntposeFilterParams antpose_filter_params(const EstimatorParams& params, const char* method);

}  // namespace antpose::orientation
