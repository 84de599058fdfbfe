#include "antpose/orientation/smoother.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

namespace antpose::orientation {
namespace {

// `shift` (interval-mean gyroscope samples): the sample at t_k is the rate over (t_{k-1}, t_k],
// an interval that in reversed time ends at −t_{k-1}, so the reversed sample there carries −ω_k;
// otherwise the backward pass lags by one sample.
SensorSeries reversed(const SensorSeries& s, double sign, bool shift) {
  SensorSeries r;
  r.t.resize(s.size());
  r.v.resize(s.size());
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) {
    r.t[i] = -s.t[n - 1 - i];
    r.v[i] = sign * s.v[(shift && i > 0) ? n - i : n - 1 - i];
  }
  return r;
}

// Rotation vector of a unit quaternion (shortest rotation).
Vec3 log_quat(Quat q) {
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vn = q.vec().norm();
  if (vn < 1e-12) return 2.0 * q.vec();
  return (2.0 * std::atan2(vn, q.w()) / vn) * q.vec();
}

Quat exp_rotvec(const Vec3& r) {
  const double a = r.norm();
  if (a < 1e-12) return Quat(1.0, 0.5 * r.x(), 0.5 * r.y(), 0.5 * r.z()).normalized();
  const Vec3 v = (std::sin(0.5 * a) / a) * r;
  return Quat(std::cos(0.5 * a), v.x(), v.y(), v.z());
}

double weight(double var_self, double var_other) {
  // Weight of the OTHER estimate; infinite or NaN variances fall back to the finite one.
  const bool fs = std::isfinite(var_self), fo = std::isfinite(var_other);
  if (!fo) return 0.0;
  if (!fs) return 1.0;
  const double s = var_self + var_other;
  return s > 0.0 ? var_self / s : 0.5;
}

double fused_var(double a, double b) {
  if (!std::isfinite(a)) return b;
  if (!std::isfinite(b)) return a;
  const double s = a + b;
  return s > 0.0 ? a * b / s : 0.0;
}

}  // namespace

ImuData time_reversed(const ImuData& data, bool interval_mean_gyro) {
  ImuData r;
  r.gyroscope = reversed(data.gyroscope, -1.0, interval_mean_gyro);
  r.accelerometer = reversed(data.accelerometer, 1.0, false);
  r.magnetometer = reversed(data.magnetometer, 1.0, false);
  r.source = data.source;
  return r;
}

OrientationTrack fuse_forward_backward(const OrientationTrack& f, const OrientationTrack& b, bool fuse_heading) {
  const std::size_t n = f.size();
  if (b.size() != n || f.covariance.size() != n || b.covariance.size() != n)
    throw std::invalid_argument("fuse_forward_backward: tracks of different lengths or without covariance");
  OrientationTrack out;
  out.method = f.method;
  out.world = f.world;
  out.t.reserve(n);
  out.q_world_device.reserve(n);
  out.covariance.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = n - 1 - i;
    const Mat3& cf = f.covariance[i];
    const Mat3& cb = b.covariance[j];
    const Quat& qf = f.q_world_device[i];
    const Vec3 d = log_quat(b.q_world_device[j] * qf.conjugate());  // world frame
    const double wi = weight(cf(0, 0), cb(0, 0));
    const double wh = fuse_heading ? weight(cf(2, 2), cb(2, 2)) : 0.0;
    const Quat q = (exp_rotvec(Vec3(wi * d.x(), wi * d.y(), wh * d.z())) * qf).normalized();
    Mat3 c = Mat3::Zero();
    c(0, 0) = c(1, 1) = fused_var(cf(0, 0), cb(0, 0));
    c(2, 2) = fuse_heading ? fused_var(cf(2, 2), cb(2, 2)) : cf(2, 2);
    out.push_back(f.t[i], q, c);
  }
  return out;
}

OrientationTrack AntposeSmoother::estimate(const ImuData& data, Diagnostics& diagnostics) const {
  if (p_.use_magnetometer && !data.has_magnetometer())
    throw MeasurementError(
        "antpose-smoother: the capture has no magnetometer; use mag=0 for the 6-D smoother (heading then drifts)");
  const double Ts = data.gyroscope.median_interval();
  if (!(Ts > 0.0)) throw MeasurementError("antpose-smoother: the gyroscope has no usable sample interval");

  AntposeFilterParams p = p_;
  if (p.gyro_clip_rad_s <= 0.0) {
    const auto sat = gyro_saturation(data.gyroscope);
    for (const auto& s : sat) p.gyro_clip_rad_s = p.gyro_clip_rad_s > 0.0 ? std::min(p.gyro_clip_rad_s, s.level) : s.level;
  }
  AntposeFilter fwd(p, Ts);
  const OrientationTrack forward = run_gyro_driven(fwd, data, initial_attitude(data), run_options(fwd.params()));

  const ImuData rev = time_reversed(data, !p_.gyro_trapezoid);
  AntposeFilter bwd(p, Ts);
  if (fwd.mag_reference_norm() > 0.0) bwd.set_initial_mag_reference(fwd.mag_reference_norm(), fwd.mag_reference_dip());
  bwd.set_initial_bias(-fwd.gyro_bias(), std::max(fwd.bias_sigma(), p_.bias_sigma_motion));
  const OrientationTrack backward = run_gyro_driven(bwd, rev, initial_attitude(rev), run_options(bwd.params()));

  OrientationTrack track = fuse_forward_backward(forward, backward, p_.use_magnetometer);
  track.method = name();
  const double rejected = std::max(fwd.rejected_s(), bwd.rejected_s());
  if (rejected > 0.0)
    diagnostics.warn(data.source / "sensors", 0,
                     fmt::format("antpose-smoother: magnetic disturbance detected (field norm or dip off the "
                                 "reference); heading correction suspended for {:.1f} s in one pass, the other pass "
                                 "and the gyroscope carry the heading there",
                                 rejected));
  if (fwd.nonfinite_inputs() > 0)
    diagnostics.warn(fmt::format("antpose-smoother: {} non-finite sensor samples were skipped", fwd.nonfinite_inputs()));
  return track;
}

}  // namespace antpose::orientation
