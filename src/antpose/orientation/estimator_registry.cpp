// The estimators by name. To add one: implement OrientationEstimator (or a GyroDrivenFilter run by
// run_gyro_driven) and append an EstimatorInfo below.
#include <cmath>

#include <fmt/core.h>

#include "antpose/orientation/estimator.hpp"
#include "antpose/orientation/antpose_filter.hpp"
#include "antpose/orientation/filters.hpp"
#include "antpose/orientation/smoother.hpp"

namespace antpose::orientation {
namespace {

bool flag(const EstimatorParams& p, const char* name, const char* method) {
  const double v = p.at(name);
  if (v != 0.0 && v != 1.0)
    throw InputError("--param", fmt::format("{}: {} must be 0 or 1 (got {})", method, name, v));
  return v != 0.0;
}

double non_negative(const EstimatorParams& p, const char* name, const char* method) {
  const double v = p.at(name);
  if (!(v >= 0.0)) throw InputError("--param", fmt::format("{}: {} must be >= 0 (got {})", method, name, v));
  return v;
}

void require_magnetometer(const ImuData& data, bool needed, const std::string& method) {
  if (needed && !data.has_magnetometer())
    throw MeasurementError(fmt::format("{}: the capture has no magnetometer; use mag=0 for the 6-D filter (heading "
                                       "then drifts)",
                                       method));
}

class MadgwickEstimator final : public OrientationEstimator {
 public:
  explicit MadgwickEstimator(const MadgwickParams& p) : p_(p) {}
  std::string name() const override { return "madgwick"; }
  bool causal() const override { return true; }
  OrientationTrack estimate(const ImuData& data, Diagnostics&) const override {
    require_magnetometer(data, p_.use_magnetometer, name());
    MadgwickFilter filter(p_);
    OrientationTrack track = run_gyro_driven(filter, data, initial_attitude(data));
    track.method = name();
    return track;
  }

 private:
  MadgwickParams p_;
};

class MadgwickBroadEstimator final : public OrientationEstimator {
 public:
  MadgwickBroadEstimator(double beta, double rate_hz) : beta_(beta), rate_hz_(rate_hz) {}
  std::string name() const override { return "madgwick-broad"; }
  bool causal() const override { return true; }
  OrientationTrack estimate(const ImuData& data, Diagnostics&) const override {
    require_magnetometer(data, true, name());
    const double rate = rate_hz_ > 0.0 ? rate_hz_ : 1.0 / data.gyroscope.median_interval();
    MadgwickBroadFilter filter(static_cast<float>(beta_), static_cast<float>(rate));
    // BROAD: state from the first samples, in Madgwick's frame; outputs rotated to ENU.
    const Quat q0 = q_enu_nwu() * broad_initial_state(data.accelerometer.v.front(), data.magnetometer.v.front());
    OrientationTrack track = run_gyro_driven(filter, data, q0);
    track.method = name();
    return track;
  }

 private:
  double beta_, rate_hz_;
};

class MahonyEstimator final : public OrientationEstimator {
 public:
  explicit MahonyEstimator(const MahonyParams& p) : p_(p) {}
  std::string name() const override { return "mahony"; }
  bool causal() const override { return true; }
  OrientationTrack estimate(const ImuData& data, Diagnostics&) const override {
    require_magnetometer(data, p_.use_magnetometer, name());
    MahonyFilter filter(p_);
    OrientationTrack track = run_gyro_driven(filter, data, initial_attitude(data));
    track.method = name();
    return track;
  }

 private:
  MahonyParams p_;
};

class EcompassEstimator final : public OrientationEstimator {
 public:
  explicit EcompassEstimator(const EcompassParams& p) : p_(p) {}
  std::string name() const override { return "ecompass"; }
  bool causal() const override { return p_.window_s == 0.0; }
  OrientationTrack estimate(const ImuData& data, Diagnostics&) const override { return ecompass_track(data, p_); }

 private:
  EcompassParams p_;
};

}  // namespace

std::vector<EstimatorInfo> estimator_registry() {
  std::vector<EstimatorInfo> r;
  r.push_back({"ecompass",
               "static eCompass (TRIAD of accelerometer and magnetometer, thesis §4.4) per accelerometer sample over a "
               "centred window",
               false,
               {{"window", 0.2, "averaging window, s (centred)"},
                {"acc_floor", 0.02, "accelerometer bias floor for the uncertainty, m/s^2"},
                {"mag_residual", 1.0, "residual hard iron for the uncertainty, uT"}},
               [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 EcompassParams e;
                 e.window_s = non_negative(p, "window", "ecompass");
                 e.acc_bias_floor_mps2 = non_negative(p, "acc_floor", "ecompass");
                 e.mag_residual_uT = non_negative(p, "mag_residual", "ecompass");
                 return std::make_unique<EcompassEstimator>(e);
               }});
  r.push_back({"madgwick",
               "Madgwick 2010 report, IMU (mag=0) or MARG, with gyroscope-bias gain zeta; field reference as the report "
               "defines it",
               true,
               {{"beta", 0.12, "gradient step gain, rad/s"},
                {"zeta", 0.0, "gyroscope bias drift gain, rad/s^2"},
                {"mag", 1.0, "1: MARG (magnetometer), 0: IMU"}},
               [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 MadgwickParams m;
                 m.beta = non_negative(p, "beta", "madgwick");
                 m.zeta = non_negative(p, "zeta", "madgwick");
                 m.use_magnetometer = flag(p, "mag", "madgwick");
                 return std::make_unique<MadgwickEstimator>(m);
               }});
  r.push_back({"madgwick-broad",
               "Madgwick's 2011/2012 C code as run by BROAD (float, (2bx,2bz) defect, BROAD initial state): only for "
               "validating the benchmark",
               true,
               {{"beta", 0.12, "gradient step gain, rad/s"},
                {"rate", 0.0, "sampleFreq of the C code, Hz (0: 1 / median gyroscope interval)"}},
               [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 return std::make_unique<MadgwickBroadEstimator>(non_negative(p, "beta", "madgwick-broad"),
                                                                 non_negative(p, "rate", "madgwick-broad"));
               }});
  r.push_back({"mahony",
               "Mahony et al. 2008 explicit complementary filter (MARG or mag=0), gains kp, ki",
               true,
               {{"kp", 0.74, "proportional gain, rad/s"},
                {"ki", 0.0012, "integral (bias) gain, rad/s^2"},
                {"mag", 1.0, "1: use the magnetometer, 0: IMU"}},
               [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 MahonyParams m;
                 m.kp = non_negative(p, "kp", "mahony");
                 m.ki = non_negative(p, "ki", "mahony");
                 m.use_magnetometer = flag(p, "mag", "mahony");
                 return std::make_unique<MahonyEstimator>(m);
               }});
  r.push_back({"antpose",
               "antpose's causal filter after VQF (Laidig & Seel 2023): Butterworth-filtered inclination, heading-only "
               "magnetometer, gyroscope bias at rest and in motion, magnetic disturbance rejection",
               true, antpose_filter_param_specs(), [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 return std::make_unique<AntposeEstimator>(antpose_filter_params(p, "antpose"));
               }});
  r.push_back({"antpose-smoother",
               "offline: the antpose filter forward and on the time-reversed log, fused per sample by uncertainty",
               false, antpose_filter_param_specs(true), [](const EstimatorParams& p) -> std::unique_ptr<OrientationEstimator> {
                 return std::make_unique<AntposeSmoother>(antpose_filter_params(p, "antpose-smoother"));
               }});
  return r;
}

}  // namespace antpose::orientation
