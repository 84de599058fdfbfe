#include "antpose/orientation/antpose_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/core.h>

namespace antpose::orientation {
namespace {

double gain(double tau, double Ts) { return tau > 0.0 ? 1.0 - std::exp(-Ts / tau) : 1.0; }

double wrap_pi(double a) {
  if (a > std::numbers::pi) a -= 2.0 * std::numbers::pi;
  if (a < -std::numbers::pi) a += 2.0 * std::numbers::pi;
  return a;
}

// Steady-state DF2T states for a constant input x (DC gain 1: b0+b1+b2 = 1+a1+a2).
template <class T>
void butter_steady(double b1, double b2, double a1, double a2, const T& x, T& s0, T& s1) {
  s1 = (b2 - a2) * x;
  s0 = (b1 - a1) * x + s1;
}

}  // namespace

void AntposeFilter::Butter2::design(double tau, double Ts) {
  // Bilinear transform of the second-order Butterworth with f_c = √2 / (2π τ) (VQF §4.2).
  const double fc = std::numbers::sqrt2 / (2.0 * std::numbers::pi * tau);
  const double C = std::tan(std::numbers::pi * fc * Ts);
  const double D = C * C + std::numbers::sqrt2 * C + 1.0;
  b0 = C * C / D;
  b1 = 2.0 * b0;
  b2 = b0;
  a1 = 2.0 * (C * C - 1.0) / D;
  a2 = (1.0 - std::numbers::sqrt2 * C + C * C) / D;
}

AntposeFilter::AntposeFilter(const AntposeFilterParams& params, double Ts) : p_(params), Ts_(Ts) {
  if (!(Ts > 0.0) || !std::isfinite(Ts)) throw std::invalid_argument("AntposeFilter: sample interval must be > 0");
  acc_lp_.design(p_.tau_acc_s, Ts_);
  k_rest_ = gain(p_.rest_tau_s, Ts_);
  k_mag_ = gain(p_.tau_mag_s, Ts_);
  k_mag_current_ = gain(p_.mag_current_tau_s, Ts_);
  k_mag_ref_ = gain(p_.mag_ref_tau_s, Ts_);
  k_acc_ = gain(p_.tau_acc_s, Ts_);
  // Bias Kalman filter (VQF §4.3): random-walk process noise such that σ grows by 0.1°/s over
  // bias_forgetting_s; measurement variances chosen so that the steady-state σ equals the
  // requested one: W = p²/V + p.
  const double s01 = deg2rad(0.1);
  bias_v_ = s01 * s01 * Ts_ / p_.bias_forgetting_s;
  const double pm = p_.bias_sigma_motion * p_.bias_sigma_motion;
  w_motion_ = pm * pm / bias_v_ + pm;
  w_vertical_ = w_motion_ / std::max(p_.bias_vertical_factor, 1e-10);
  const double pr = p_.bias_sigma_rest * p_.bias_sigma_rest;
  w_rest_ = pr * pr / bias_v_ + pr;
  reset(Quat::Identity());
}

void AntposeFilter::reset(const Quat& q_world_device) {
  q_I_device_ = q_world_device.normalized();
  q_E_I_ = Quat::Identity();
  delta_ = 0.0;
  acc_init_ = R_init_ = rest_init_ = mag_init_ = false;
  acc_earth_ = Vec3::UnitZ();
  bias_ = bias0_;
  const double s0 = bias0_sigma_ >= 0.0 ? bias0_sigma_ : p_.bias_sigma_init;
  P_ = Mat3::Identity() * (s0 * s0);
  rest_t_ = 0.0;
  rest_ = false;
  ref_norm_ = ref0_norm_, ref_dip_ = ref0_dip_;
  cand_norm_ = cand_dip_ = cand_t_ = 0.0;
  undisturbed_t_ = reject_t_ = rejected_total_s_ = 0.0;
  mag_disturbed_ = false;
  sigma_h_ = p_.use_magnetometer ? p_.heading_sigma_init : 0.0;
  sigma_i_ = p_.tilt_sigma_init;
  nonfinite_ = clipped_ = 0;
}

double AntposeFilter::bias_sigma() const { return std::sqrt(std::max(P_.trace(), 0.0) / 3.0); }

void AntposeFilter::update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) {
  update_with_ages(dt, gyro, acc, 0.0, mag, 0.0);
}

void AntposeFilter::update_with_ages(double dt, const Vec3& gyro, const Vec3* acc_in, double acc_age, const Vec3* mag_in,
                                     double mag_age) {
  if (!(dt > 0.0) || !std::isfinite(dt)) dt = Ts_;
  const Vec3* acc = acc_in;
  const Vec3* mag = mag_in;
  if (acc && !acc->allFinite()) acc = nullptr, ++nonfinite_;
  if (mag && !mag->allFinite()) mag = nullptr, ++nonfinite_;
  Vec3 acc_now, mag_now;
  if (gyro.allFinite()) {
    const Vec3 w = gyro - bias_;
    if (acc && acc_age > 0.0) acc_now = *acc - acc_age * w.cross(*acc), acc = &acc_now;
    if (mag && mag_age > 0.0) mag_now = *mag - mag_age * w.cross(*mag), mag = &mag_now;
  }
  if (gyro.allFinite()) {
    // Strapdown: q ← q ⊗ exp(½ ω dt), exact for a constant rate over the step.
    const Vec3 w = gyro - bias_;
    const double angle = w.norm() * dt;
    if (angle > 1e-12) {
      const double s = std::sin(0.5 * angle) / (angle / dt);
      q_I_device_ = q_I_device_ * Quat(std::cos(0.5 * angle), s * w.x(), s * w.y(), s * w.z());
      q_I_device_.normalize();
    }
    update_rest(gyro, acc);
    // At the clip level the rotation beyond the range is lost: the attitude uncertainty grows
    // by up to the measured rate over the step.
    if (p_.gyro_clip_rad_s > 0.0 && gyro.cwiseAbs().maxCoeff() >= p_.gyro_clip_rad_s) {
      sigma_i_ += gyro.norm() * dt;
      if (p_.use_magnetometer) sigma_h_ += gyro.norm() * dt;
      ++clipped_;
    }
  } else {
    ++nonfinite_;
  }
  const double sb = bias_sigma() * dt;
  sigma_i_ += sb;
  if (p_.use_magnetometer) sigma_h_ += sb;
  // Process noise of the bias random walk, bounded by its initial variance (VQF §4.3).
  if (P_(0, 0) < p_.bias_sigma_init * p_.bias_sigma_init) P_.diagonal().array() += bias_v_;

  acc_fresh_ = false;
  if (acc && acc->squaredNorm() > 1e-6) update_acc(*acc);
  update_bias();
  if (mag && p_.use_magnetometer && mag->squaredNorm() > 1e-6) update_mag(*mag);
}

void AntposeFilter::update_rest(const Vec3& gyro, const Vec3* acc) {
  if (!rest_init_) {
    gyro_lp_ = gyro;
    acc_rest_lp_ = acc ? *acc : Vec3::Zero();
    rest_init_ = true;
  }
  gyro_lp_ += k_rest_ * (gyro - gyro_lp_);
  bool still = (gyro - gyro_lp_).squaredNorm() < p_.rest_gyro_th * p_.rest_gyro_th &&
               gyro_lp_.cwiseAbs().maxCoeff() <= p_.bias_clip;
  if (acc) {
    acc_rest_lp_ += k_rest_ * (*acc - acc_rest_lp_);
    still = still && (*acc - acc_rest_lp_).squaredNorm() < p_.rest_acc_th * p_.rest_acc_th;
  }
  rest_t_ = still ? rest_t_ + Ts_ : 0.0;
  rest_ = rest_t_ >= p_.rest_min_s;
}

void AntposeFilter::update_acc(const Vec3& acc) {
  const Vec3 acc_I = q_I_device_ * acc;
  const Butter2& f = acc_lp_;
  if (!acc_init_) {
    butter_steady(f.b1, f.b2, f.a1, f.a2, acc_I, acc_s0_, acc_s1_);
    acc_init_ = true;
  }
  const Vec3 y = f.b0 * acc_I + acc_s0_;
  acc_s0_ = f.b1 * acc_I - f.a1 * y + acc_s1_;
  acc_s1_ = f.b2 * acc_I - f.a2 * y;

  const double n = y.norm();
  if (!(n > 1e-9)) return;
  acc_earth_ = (q_E_I_ * y) / n;
  // Full re-alignment of the low-passed vertical: rotation about (a_y, −a_x, 0) taking a to z.
  const double qw = std::sqrt(std::max(0.5 * (acc_earth_.z() + 1.0), 0.0));
  const Quat corr = qw > 1e-6 ? Quat(qw, 0.5 * acc_earth_.y() / qw, -0.5 * acc_earth_.x() / qw, 0.0)
                              : Quat(0.0, 1.0, 0.0, 0.0);
  q_E_I_ = (corr * q_E_I_).normalized();
  acc_fresh_ = true;
  sigma_i_ = std::sqrt((1.0 - k_acc_) * sigma_i_ * sigma_i_ + k_acc_ * p_.tilt_floor * p_.tilt_floor);
}

void AntposeFilter::scalar_bias_update(const Vec3& h, double innovation, double w) {
  const Vec3 Ph = P_ * h;
  const double s = h.dot(Ph) + w;
  if (!(s > 0.0)) return;
  bias_ += (innovation / s) * Ph;
  P_.noalias() -= (Ph / s) * Ph.transpose();  // outer product of one vector: stays exactly symmetric
}

void AntposeFilter::update_bias() {
  if (!p_.motion_bias && !p_.rest_bias) return;
  const double clip = p_.bias_clip;
  auto clipped = [clip](double e) { return std::clamp(e, -clip, clip); };
  if (rest_ && p_.rest_bias) {
    // At rest the low-passed gyroscope is the bias itself.
    const Vec3 b0 = bias_;
    for (int i = 0; i < 3; ++i)
      scalar_bias_update(Vec3::Unit(i), clipped(gyro_lp_[i] - b0[i]) - (bias_[i] - b0[i]), w_rest_);
  } else if (p_.motion_bias && acc_fresh_) {
    const Mat3 R = (q_E_I_ * q_I_device_).toRotationMatrix();  // R_E_device (6-D earth frame)
    double x[8];
    for (int j = 0; j < 3; ++j) x[j] = R(0, j), x[3 + j] = R(1, j);
    x[6] = R.row(0).dot(bias_);
    x[7] = R.row(1).dot(bias_);
    const Butter2& f = acc_lp_;
    if (!R_init_) {
      for (int i = 0; i < 8; ++i) butter_steady(f.b1, f.b2, f.a1, f.a2, x[i], R_s0_[i], R_s1_[i]);
      R_init_ = true;
    }
    for (int i = 0; i < 8; ++i) {
      const double y = f.b0 * x[i] + R_s0_[i];
      R_s0_[i] = f.b1 * x[i] - f.a1 * y + R_s1_[i];
      R_s1_[i] = f.b2 * x[i] - f.a2 * y;
      R_lp_[i] = y;
    }
    const Vec3 h0(R_lp_[0], R_lp_[1], R_lp_[2]);
    const Vec3 h1(R_lp_[3], R_lp_[4], R_lp_[5]);
    const Vec3 h2 = R.row(2).transpose();
    // The correction rate of the low-passed vertical measures the earth-frame drift R b (VQF
    // §4.3); the low-passed R b̂ accounts for the bias already removed during the filter delay.
    const double e0 = clipped(-acc_earth_.y() / Ts_ + R_lp_[6] - h0.dot(bias_));
    const double e1 = clipped(acc_earth_.x() / Ts_ + R_lp_[7] - h1.dot(bias_));
    const double e2 = clipped(-h2.dot(bias_));
    const Vec3 b0 = bias_;
    scalar_bias_update(h0, e0, w_motion_);
    scalar_bias_update(h1, e1 - h1.dot(bias_ - b0), w_motion_);
    scalar_bias_update(h2, e2 - h2.dot(bias_ - b0), w_vertical_);
  }
  bias_ = bias_.cwiseMax(-clip).cwiseMin(clip);
}

void AntposeFilter::update_mag(const Vec3& mag) {
  const Vec3 m = q_E_I_ * (q_I_device_ * mag);  // 6-D earth frame
  double k = k_mag_;
  if (p_.mag_drift_budget > 0.0 && sigma_h_ < p_.mag_long_max_sigma) {
    // Long averaging only while the heading is known well: after the start or a clipped
    // gyroscope the heading must re-converge at tau_mag_s.
    const double sb = bias_sigma();
    const double tau = sb > 0.0 ? std::clamp(p_.mag_drift_budget / sb, p_.tau_mag_s, p_.tau_mag_max_s) : p_.tau_mag_max_s;
    k = gain(tau, Ts_);
  }
  if (p_.mag_rejection) {
    const double norm = m.norm();
    const double dip = -std::asin(std::clamp(m.z() / norm, -1.0, 1.0));
    if (!mag_init_) {
      norm_lp_ = norm, dip_lp_ = dip;
      cand_norm_ = norm, cand_dip_ = dip;
      mag_init_ = true;
    }
    norm_lp_ += k_mag_current_ * (norm - norm_lp_);
    dip_lp_ += k_mag_current_ * (dip - dip_lp_);
    // Disturbance detection against the learned reference (VQF §4.4).
    if (ref_norm_ > 0.0 && std::abs(norm_lp_ - ref_norm_) < p_.mag_norm_th * ref_norm_ &&
        std::abs(dip_lp_ - ref_dip_) < p_.mag_dip_th) {
      undisturbed_t_ += Ts_;
      if (undisturbed_t_ >= p_.mag_min_undisturbed_s) {
        mag_disturbed_ = false;
        ref_norm_ += k_mag_ref_ * (norm_lp_ - ref_norm_);
        ref_dip_ += k_mag_ref_ * (dip_lp_ - ref_dip_);
      }
    } else {
      undisturbed_t_ = 0.0;
      mag_disturbed_ = true;
    }
    // A consistent new field (seen while rotating, so not a local disturbance) becomes the reference.
    if (std::abs(norm_lp_ - cand_norm_) < p_.mag_norm_th * cand_norm_ && std::abs(dip_lp_ - cand_dip_) < p_.mag_dip_th) {
      if (gyro_lp_.norm() >= p_.mag_new_min_gyro) cand_t_ += Ts_;
      cand_norm_ += k_mag_ref_ * (norm_lp_ - cand_norm_);
      cand_dip_ += k_mag_ref_ * (dip_lp_ - cand_dip_);
      if (mag_disturbed_ && (cand_t_ >= p_.mag_new_s || (ref_norm_ == 0.0 && cand_t_ >= p_.mag_new_first_s))) {
        ref_norm_ = cand_norm_, ref_dip_ = cand_dip_;
        mag_disturbed_ = false;
        undisturbed_t_ = p_.mag_min_undisturbed_s;
      }
    } else {
      cand_t_ = 0.0;
      cand_norm_ = norm_lp_, cand_dip_ = dip_lp_;
    }
    if (ref_norm_ == 0.0) {
      // No reference yet: the first field is trusted (the initial attitude used it anyway),
      // and becomes the reference.
      ref_norm_ = norm_lp_, ref_dip_ = dip_lp_;
      mag_disturbed_ = false;
    }
    if (mag_disturbed_) {
      if (reject_t_ <= p_.mag_max_reject_s) {
        reject_t_ += Ts_;
        rejected_total_s_ += Ts_;
        k = 0.0;
      } else {
        k /= p_.mag_reject_factor;
      }
    } else {
      reject_t_ = std::max(reject_t_ - p_.mag_reject_factor * Ts_, 0.0);
    }
  }
  if (k > 0.0) {
    delta_ = wrap_pi(delta_ + k * wrap_pi(std::atan2(m.x(), m.y()) - delta_));
    sigma_h_ = std::sqrt((1.0 - k) * sigma_h_ * sigma_h_ + k * p_.heading_floor * p_.heading_floor);
  }
}

Quat AntposeFilter::q_world_device() const {
  const Quat heading(std::cos(0.5 * delta_), 0.0, 0.0, std::sin(0.5 * delta_));
  return (heading * (q_E_I_ * q_I_device_)).normalized();
}

std::optional<Mat3> AntposeFilter::covariance() const {
  Mat3 c = Mat3::Zero();
  c(0, 0) = c(1, 1) = sigma_i_ * sigma_i_;
  c(2, 2) = p_.use_magnetometer ? sigma_h_ * sigma_h_ : std::numeric_limits<double>::infinity();
  return c;
}

OrientationTrack AntposeEstimator::estimate(const ImuData& data, Diagnostics& diagnostics) const {
  if (p_.use_magnetometer && !data.has_magnetometer())
    throw MeasurementError("antpose: the capture has no magnetometer; use mag=0 for the 6-D filter (heading then drifts)");
  const double Ts = data.gyroscope.median_interval();
  if (!(Ts > 0.0)) throw MeasurementError("antpose: the gyroscope has no usable sample interval");
  AntposeFilter filter(p_, Ts);
  OrientationTrack track = run_gyro_driven(filter, data, initial_attitude(data), run_options(p_));
  track.method = name();
  if (filter.rejected_s() > 0.0)
    diagnostics.warn(data.source / "sensors",
                     0, fmt::format("antpose: magnetic disturbance detected (field norm or dip off the reference); heading "
                                    "correction suspended for {:.1f} s in all, heading follows the gyroscope there",
                                    filter.rejected_s()));
  if (filter.nonfinite_inputs() > 0)
    diagnostics.warn(fmt::format("antpose: {} non-finite sensor samples were skipped", filter.nonfinite_inputs()));
  return track;
}

std::vector<ParamSpec> antpose_filter_param_specs(bool offline) {
  const AntposeFilterParams d;
  return {{"tau_acc", d.tau_acc_s, "inclination low-pass time constant, s"},
          {"tau_mag", d.tau_mag_s, "heading correction time constant, s (the shortest one when adaptive)"},
          {"mag_drift_budget", offline ? kSmootherDriftBudgetDeg : 0.0,
           "adaptive heading time constant: gyroscope drift allowed over it, deg (0: fixed tau_mag)"},
          {"tau_mag_max", d.tau_mag_max_s, "longest adaptive heading time constant, s"},
          {"mag", 1.0, "1: use the magnetometer, 0: 6-D (heading drifts)"},
          {"motion_bias", 1.0, "1: estimate the gyroscope bias in motion"},
          {"rest_bias", 1.0, "1: estimate the gyroscope bias at rest"},
          {"bias_clip", rad2deg(d.bias_clip), "largest gyroscope bias, deg/s"},
          {"mag_rejection", 1.0, "1: detect and reject magnetic disturbances"},
          {"gyro_trapezoid", 0.0, "1: gyroscope samples are instantaneous rates (trapezoid), 0: interval means"}};
}

AntposeFilterParams antpose_filter_params(const EstimatorParams& p, const char* method) {
  auto positive = [&](const char* name) {
    const double v = p.at(name);
    if (!(v > 0.0)) throw InputError("--param", fmt::format("{}: {} must be > 0 (got {})", method, name, v));
    return v;
  };
  auto flag = [&](const char* name) {
    const double v = p.at(name);
    if (v != 0.0 && v != 1.0) throw InputError("--param", fmt::format("{}: {} must be 0 or 1 (got {})", method, name, v));
    return v != 0.0;
  };
  AntposeFilterParams a;
  a.tau_acc_s = positive("tau_acc");
  a.tau_mag_s = positive("tau_mag");
  a.mag_drift_budget = deg2rad(p.at("mag_drift_budget"));
  if (!(a.mag_drift_budget >= 0.0))
    throw InputError("--param", fmt::format("{}: mag_drift_budget must be >= 0 (got {})", method, p.at("mag_drift_budget")));
  a.tau_mag_max_s = positive("tau_mag_max");
  if (a.tau_mag_max_s < a.tau_mag_s)
    throw InputError("--param", fmt::format("{}: tau_mag_max ({} s) must be >= tau_mag ({} s)", method, a.tau_mag_max_s,
                                            a.tau_mag_s));
  a.use_magnetometer = flag("mag");
  a.motion_bias = flag("motion_bias");
  a.rest_bias = flag("rest_bias");
  a.bias_clip = deg2rad(positive("bias_clip"));
  a.mag_rejection = flag("mag_rejection");
  a.gyro_trapezoid = flag("gyro_trapezoid");
  return a;
}

}  // namespace antpose::orientation
