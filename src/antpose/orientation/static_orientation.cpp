#include "antpose/orientation/static_orientation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/core.h>

namespace antpose::orientation {
namespace {

struct Samples {
  std::vector<double> t;
  std::vector<Vec3> v;
};

Samples slice(const Stream& s, double t0, double t1) {
  Samples out;
  const auto b = std::lower_bound(s.t.begin(), s.t.end(), t0) - s.t.begin();
  const auto e = std::upper_bound(s.t.begin(), s.t.end(), t1) - s.t.begin();
  for (auto i = b; i < e; ++i) {
    out.t.push_back(s.t[static_cast<std::size_t>(i)]);
    out.v.push_back(s.xyz(static_cast<std::size_t>(i)));
  }
  return out;
}

Vec3 mean_of(const std::vector<Vec3>& v) {
  Vec3 m = Vec3::Zero();
  for (const auto& x : v) m += x;
  return v.empty() ? m : Vec3(m / static_cast<double>(v.size()));
}

// Sample variance (n − 1) of a list of numbers.
double variance(const std::vector<double>& x) {
  if (x.size() < 2) return 0.0;
  double m = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  double s = 0.0;
  for (double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size() - 1);
}

}  // namespace

Mat3 triad_world_device(const Vec3& specific_force, const Vec3& magnetic_field) {
  const double f = specific_force.norm(), m = magnetic_field.norm();
  if (!(f > 0.0) || !(m > 0.0) || !std::isfinite(f) || !std::isfinite(m))
    throw MeasurementError("static orientation: the mean specific force or magnetic field is zero or not finite");
  const Vec3 up = specific_force / f;
  const Vec3 east_raw = magnetic_field.cross(up);
  if (east_raw.norm() < 1e-9 * m)
    throw MeasurementError("static orientation: the magnetic field is parallel to gravity; heading is undefined");
  const Vec3 east = east_raw.normalized();
  const Vec3 north = up.cross(east);
  Mat3 R_world_device;
  R_world_device.row(0) = east.transpose();
  R_world_device.row(1) = north.transpose();
  R_world_device.row(2) = up.transpose();
  return R_world_device;
}

AndroidOrientation android_orientation(const Mat3& R) {
  AndroidOrientation a;
  a.azimuth = wrap_2pi(std::atan2(R(0, 1), R(1, 1)));
  a.pitch = std::asin(std::clamp(-R(2, 1), -1.0, 1.0));
  a.roll = std::atan2(-R(2, 0), R(2, 2));
  return a;
}

StaticOrientation estimate_static_orientation(const Capture& capture, double t0, double t1,
                                              const StaticOrientationOptions& options) {
  const Stream& acc_stream = capture.require(streams::kAccelerometer);
  const Stream& mag_stream = capture.require(streams::kMagnetometer);
  if (!(t1 > t0)) throw MeasurementError(fmt::format("static orientation: empty window [{}, {}] s", t0, t1));
  const Samples acc = slice(acc_stream, t0, t1);
  const Samples mag = slice(mag_stream, t0, t1);
  if (acc.v.size() < options.min_samples || mag.v.size() < options.min_samples)
    throw MeasurementError(fmt::format(
        "static orientation: the window [{:.3f}, {:.3f}] s holds {} accelerometer and {} magnetometer samples; "
        "at least {} of each are needed",
        t0, t1, acc.v.size(), mag.v.size(), options.min_samples));

  StaticOrientation out;
  out.t0 = t0;
  out.t1 = t1;
  out.acc_samples = acc.v.size();
  out.mag_samples = mag.v.size();
  out.acc_mean_mps2 = mean_of(acc.v);
  out.mag_mean_uT = mean_of(mag.v);
  out.gravity_mps2 = out.acc_mean_mps2.norm();
  out.field_uT = out.mag_mean_uT.norm();
  const Mat3 R = triad_world_device(out.acc_mean_mps2, out.mag_mean_uT);
  out.R_world_device = R;
  out.android = android_orientation(R);
  const Vec3 east = R.row(0).transpose(), north = R.row(1).transpose(), up = R.row(2).transpose();

  const double vertical = out.mag_mean_uT.dot(up);
  out.horizontal_field_uT = (out.mag_mean_uT - vertical * up).norm();
  out.dip = std::atan2(-vertical, out.horizontal_field_uT);
  if (out.horizontal_field_uT < options.min_horizontal_fraction * out.field_uT)
    throw MeasurementError(fmt::format(
        "static orientation: the horizontal magnetic field is only {:.2f} µT of {:.1f} µT (dip {:.1f}°); "
        "heading is undefined (magnetic pole or a strong disturbance)",
        out.horizontal_field_uT, out.field_uT, rad2deg(out.dip)));
  const double g = out.gravity_mps2, H = out.horizontal_field_uT;
  const double tan_dip = std::tan(std::abs(out.dip));

  // Per-sample scatter (white-noise part).
  std::vector<double> acc_e, acc_n, mag_e;
  double acc_angle2 = 0.0, mag_angle2 = 0.0;
  for (const auto& a : acc.v) {
    acc_e.push_back(a.dot(east) / g);
    acc_n.push_back(a.dot(north) / g);
    const double ang = angle_between(a, out.acc_mean_mps2);
    acc_angle2 += ang * ang;
  }
  for (const auto& m : mag.v) {
    mag_e.push_back(m.dot(east));
    const double ang = angle_between(m, out.mag_mean_uT);
    mag_angle2 += ang * ang;
  }
  const double na = static_cast<double>(acc.v.size()), nm = static_cast<double>(mag.v.size());
  out.acc_direction_std = std::sqrt(acc_angle2 / na);
  out.mag_direction_std = std::sqrt(mag_angle2 / nm);
  const double tilt_var_sample = 0.5 * (variance(acc_e) + variance(acc_n));
  const double tilt_var_white = tilt_var_sample / na;
  const double mag_e_var_sample = variance(mag_e);
  const double heading_var_white = mag_e_var_sample / (nm * H * H) + variance(acc_e) / na * tan_dip * tan_dip;

  // Batch means over B time blocks: the block results carry the correlated part.
  const std::size_t B = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::floor(std::sqrt(static_cast<double>(std::min(acc.v.size(), mag.v.size()))))), 1, 64);
  std::vector<double> blk_e, blk_n, blk_heading, blk_mag_e;
  const double dt = (t1 - t0) / static_cast<double>(B);
  std::size_t ia = 0, im = 0;
  for (std::size_t b = 0; b < B; ++b) {
    const double end = b + 1 == B ? std::numeric_limits<double>::infinity() : t0 + dt * static_cast<double>(b + 1);
    Vec3 sa = Vec3::Zero(), sm = Vec3::Zero();
    std::size_t ca = 0, cm = 0;
    for (; ia < acc.t.size() && acc.t[ia] < end; ++ia, ++ca) sa += acc.v[ia];
    for (; im < mag.t.size() && mag.t[im] < end; ++im, ++cm) sm += mag.v[im];
    if (ca == 0 || cm == 0) continue;
    const Vec3 a = sa / static_cast<double>(ca), m = sm / static_cast<double>(cm);
    const Vec3 u = a.normalized();
    blk_e.push_back(u.dot(east));
    blk_n.push_back(u.dot(north));
    blk_mag_e.push_back(m.dot(east));
    out.max_block_tilt = std::max(out.max_block_tilt, angle_between(u, up));
    try {
      const Mat3 Rb = triad_world_device(a, m);
      const Vec3 north_b_world = R * Rb.row(1).transpose();
      const double dpsi = std::atan2(north_b_world.x(), north_b_world.y());
      blk_heading.push_back(dpsi);
      out.max_block_heading = std::max(out.max_block_heading, std::abs(dpsi));
    } catch (const MeasurementError&) {
      // A block whose field is parallel to gravity has no heading; the others still count.
    }
  }
  out.blocks = blk_e.size();
  double tilt_var = tilt_var_white, heading_var = heading_var_white;
  double acc_mean_var = tilt_var_white, mag_mean_var = mag_e_var_sample / nm;
  if (blk_e.size() >= 2) {
    const double nb = static_cast<double>(blk_e.size());
    acc_mean_var = std::max(acc_mean_var, 0.5 * (variance(blk_e) + variance(blk_n)) / nb);
    mag_mean_var = std::max(mag_mean_var, variance(blk_mag_e) / nb);
    tilt_var = acc_mean_var;
  }
  if (blk_heading.size() >= 2)
    heading_var = std::max(heading_var, variance(blk_heading) / static_cast<double>(blk_heading.size()));
  out.acc_n_eff = acc_mean_var > 0.0 ? std::min(na, tilt_var_sample / acc_mean_var) : na;
  out.mag_n_eff = mag_mean_var > 0.0 ? std::min(nm, mag_e_var_sample / mag_mean_var) : nm;

  out.tilt_sigma_scatter = std::sqrt(tilt_var);
  out.heading_sigma_scatter = std::sqrt(heading_var);
  const double tilt_floor = options.acc_bias_floor_mps2 / g;
  const double heading_floor_mag = options.mag_residual_uT / (std::sqrt(3.0) * H);
  out.tilt_sigma = std::hypot(out.tilt_sigma_scatter, tilt_floor);
  out.heading_sigma = std::sqrt(heading_var + heading_floor_mag * heading_floor_mag +
                                tilt_floor * tilt_floor * tan_dip * tan_dip);
  return out;
}

}  // namespace antpose::orientation
