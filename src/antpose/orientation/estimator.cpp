#include "antpose/orientation/estimator.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/orientation/static_orientation.hpp"

namespace antpose::orientation {
namespace {

SensorSeries copy_series(const Stream& s, const std::filesystem::path& where) {
  if (!s.has_xyz())
    throw InputError(where, fmt::format("stream '{}' has no x, y, z columns (has: {})", s.name,
                                        fmt::join(s.columns, ", ")));
  SensorSeries out;
  out.t = s.t;
  out.v.resize(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) out.v[i] = s.xyz(i);
  return out;
}

void check_gaps(const SensorSeries& s, const char* name, const ImuCheckOptions& o, Diagnostics& d) {
  const double med = s.median_interval();
  if (!(med > 0.0)) return;
  std::size_t count = 0;
  double longest = 0.0, at = 0.0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double dt = s.t[i] - s.t[i - 1];
    if (dt > o.gap_factor * med) {
      ++count;
      if (dt > longest) longest = dt, at = s.t[i - 1];
    }
  }
  if (count > 0)
    d.warn(fmt::format("orientation: {} gap(s) in the {} stream, longest {:.3f} s at t = {:.3f} s (median interval "
                       "{:.4f} s); the filters run without this sensor there",
                       count, name, longest, at, med));
}

}  // namespace

double SensorSeries::median_interval() const {
  if (t.size() < 2) return 0.0;
  std::vector<double> dt(t.size() - 1);
  for (std::size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  return median(std::move(dt));
}

ImuData imu_data_from_capture(const Capture& capture, Diagnostics& diagnostics, const ImuCheckOptions& options) {
  const std::filesystem::path where = capture.root / "capture.yaml";
  ImuData data;
  data.source = capture.root;
  data.gyroscope = copy_series(capture.require(streams::kGyroscope), where);
  data.accelerometer = copy_series(capture.require(streams::kAccelerometer), where);
  if (const Stream* mag = capture.find(streams::kMagnetometer); mag && !mag->empty())
    data.magnetometer = copy_series(*mag, where);
  if (data.gyroscope.size() < 2 || data.accelerometer.size() < 2)
    throw InputError(where, fmt::format("orientation needs at least 2 gyroscope and 2 accelerometer samples (has {} "
                                        "and {})",
                                        data.gyroscope.size(), data.accelerometer.size()));
  check_imu_data(data, diagnostics, options);
  return data;
}

std::vector<GyroSaturation> gyro_saturation(const SensorSeries& g, const ImuCheckOptions& o) {
  std::vector<GyroSaturation> out;
  for (int axis = 0; axis < 3; ++axis) {
    double extreme = 0.0;
    for (const auto& v : g.v) extreme = std::max(extreme, std::abs(v[axis]));
    if (extreme < o.saturation_min_rad_s) continue;
    std::size_t run = 0, flagged = 0;
    double first = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t i = 0; i < g.size(); ++i) {
      run = std::abs(g.v[i][axis]) == extreme ? run + 1 : 0;
      if (run >= o.saturation_run) {
        ++flagged;
        if (std::isnan(first)) first = g.t[i + 1 - run];
      }
    }
    if (flagged > 0) out.push_back({axis, extreme, flagged + o.saturation_run - 1, first});
  }
  return out;
}

void check_imu_data(const ImuData& data, Diagnostics& d, const ImuCheckOptions& o) {
  const std::pair<const SensorSeries*, const char*> all[] = {
      {&data.gyroscope, "gyroscope"}, {&data.accelerometer, "accelerometer"}, {&data.magnetometer, "magnetometer"}};
  for (const auto& [s, name] : all) {
    for (std::size_t i = 0; i < s->size(); ++i)
      if (!s->v[i].allFinite() || !std::isfinite(s->t[i]))
        throw InputError(data.source, fmt::format("{} sample {} (t = {}) is not finite", name, i + 1, s->t[i]));
    check_gaps(*s, name, o, d);
  }

  // Saturation: the same extreme value repeated on one axis.
  for (const GyroSaturation& sat : gyro_saturation(data.gyroscope, o))
    d.warn(fmt::format("orientation: the gyroscope {} axis sits at ±{:.3f} rad/s ({:.0f} °/s) for {} samples from t = "
                       "{:.3f} s: saturated; rotation beyond the range is lost",
                       "xyz"[sat.axis], sat.level, rad2deg(sat.level), sat.samples, sat.first_t));

  // Bias at rest: mean gyroscope rate over windows where the accelerometer is still.
  const SensorSeries& g = data.gyroscope;
  const SensorSeries& a = data.accelerometer;
  double worst = 0.0, worst_t = 0.0;
  std::size_t gi = 0;
  for (std::size_t b = 0; b < a.size();) {
    std::size_t e = b;
    while (e < a.size() && a.t[e] < a.t[b] + o.rest_window_s) ++e;
    if (e - b >= 5 && a.t[e - 1] - a.t[b] > 0.5 * o.rest_window_s) {
      Vec3 m = Vec3::Zero(), m2 = Vec3::Zero();
      for (std::size_t i = b; i < e; ++i) m += a.v[i], m2 += a.v[i].cwiseProduct(a.v[i]);
      const double n = static_cast<double>(e - b);
      m /= n;
      const Vec3 var = (m2 / n - m.cwiseProduct(m)).cwiseMax(0.0);
      if (var.maxCoeff() < o.rest_acc_std_mps2 * o.rest_acc_std_mps2) {
        while (gi < g.size() && g.t[gi] < a.t[b]) ++gi;
        Vec3 wm = Vec3::Zero();
        std::size_t k = 0;
        for (std::size_t j = gi; j < g.size() && g.t[j] <= a.t[e - 1]; ++j, ++k) wm += g.v[j];
        if (k >= 5 && (wm / static_cast<double>(k)).norm() > worst)
          worst = (wm / static_cast<double>(k)).norm(), worst_t = a.t[b];
      }
    }
    b = e;
  }
  if (worst > o.bias_warning_rad_s)
    d.warn(fmt::format("orientation: the gyroscope reads {:.2f} °/s while the accelerometer is still (t = {:.1f} s): a "
                       "gyroscope bias this large needs calibration or a bias-estimating filter",
                       rad2deg(worst), worst_t));

  // Magnetic disturbance: runs where the field norm leaves its median.
  const SensorSeries& m = data.magnetometer;
  if (m.size() >= 2) {
    std::vector<double> norms(m.size());
    for (std::size_t i = 0; i < m.size(); ++i) norms[i] = m.v[i].norm();
    const double med = median(norms);
    std::size_t runs = 0;
    double longest = 0.0, at = 0.0, largest = 0.0;
    for (std::size_t i = 0; i < m.size();) {
      if (std::abs(norms[i] - med) <= o.field_deviation * med) {
        ++i;
        continue;
      }
      std::size_t j = i;
      double dev = 0.0;
      while (j < m.size() && std::abs(norms[j] - med) > o.field_deviation * med)
        dev = std::max(dev, std::abs(norms[j] - med)), ++j;
      const double len = m.t[j - 1] - m.t[i];
      if (len >= o.field_min_run_s) {
        ++runs;
        largest = std::max(largest, dev);
        if (len > longest) longest = len, at = m.t[i];
      }
      i = j;
    }
    if (runs > 0)
      d.warn(fmt::format("orientation: magnetic disturbance: the field norm departs from its median {:.1f} µT by more "
                         "than {:.0f} % in {} run(s), longest {:.2f} s from t = {:.2f} s (up to {:.1f} µT); heading is "
                         "unreliable there",
                         med, 100.0 * o.field_deviation, runs, longest, at, largest));
  }
}

std::vector<SensorEvent> merge_events(const ImuData& data) {
  const SensorSeries* series[3] = {&data.accelerometer, &data.magnetometer, &data.gyroscope};
  std::vector<SensorEvent> out;
  out.reserve(data.accelerometer.size() + data.magnetometer.size() + data.gyroscope.size());
  std::size_t idx[3] = {0, 0, 0};
  for (;;) {
    int best = -1;
    double bt = 0.0;
    for (int s = 0; s < 3; ++s) {  // strict < keeps the tie order acc, mag, gyro
      if (idx[s] < series[s]->size() && (best < 0 || series[s]->t[idx[s]] < bt)) best = s, bt = series[s]->t[idx[s]];
    }
    if (best < 0) break;
    out.push_back({bt, static_cast<Sensor>(best), static_cast<std::uint32_t>(idx[best]++)});
  }
  return out;
}

// ---- track -------------------------------------------------------------------------------

double OrientationTrack::Sample::tilt_sigma() const {
  if (!covariance) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(0.5 * ((*covariance)(0, 0) + (*covariance)(1, 1)));
}

double OrientationTrack::Sample::heading_sigma() const {
  if (!covariance) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt((*covariance)(2, 2));
}

OrientationTrack::Sample OrientationTrack::at(double time) const {
  if (!contains(time))
    throw MeasurementError(fmt::format("orientation track '{}' covers t = [{}, {}] s; t = {} s is outside", method,
                                       t.empty() ? 0.0 : t.front(), t.empty() ? 0.0 : t.back(), time));
  const auto it = std::lower_bound(t.begin(), t.end(), time);
  const auto i = static_cast<std::size_t>(it - t.begin());
  Sample s;
  s.t = time;
  if (t[i] == time) {
    s.q_world_device = q_world_device[i];
    if (has_uncertainty()) s.covariance = covariance[i];
    return s;
  }
  const double u = (time - t[i - 1]) / (t[i] - t[i - 1]);
  s.q_world_device = q_world_device[i - 1].slerp(u, q_world_device[i]).normalized();
  if (has_uncertainty()) s.covariance = (1.0 - u) * covariance[i - 1] + u * covariance[i];
  return s;
}

void OrientationTrack::push_back(double time, const Quat& q, const std::optional<Mat3>& cov) {
  Quat qn = q.normalized();
  if (!q_world_device.empty() && q_world_device.back().coeffs().dot(qn.coeffs()) < 0.0) qn.coeffs() *= -1.0;
  t.push_back(time);
  q_world_device.push_back(qn);
  if (cov) covariance.push_back(*cov);
}

Quat magnetic_to_true(double declination) { return Quat(Eigen::AngleAxisd(-declination, Vec3::UnitZ())); }

OrientationTrack apply_declination(const OrientationTrack& track, double declination) {
  if (track.world != "enu-magnetic")
    throw std::invalid_argument(fmt::format("apply_declination: track is '{}', not enu-magnetic", track.world));
  const Quat r = magnetic_to_true(declination);
  const Mat3 R = r.toRotationMatrix();
  OrientationTrack out = track;
  out.world = "enu-true";
  for (auto& q : out.q_world_device) q = (r * q).normalized();
  for (auto& c : out.covariance) c = R * c * R.transpose();
  return out;
}

// ---- gyro-driven runner -----------------------------------------------------------------

OrientationTrack run_gyro_driven(GyroDrivenFilter& filter, const ImuData& data, const Quat& q0,
                                 const GyroDrivenOptions& options) {
  const double gyro_dt = data.gyroscope.median_interval();
  auto hold_for = [&](const SensorSeries& s) {
    return options.max_hold_s > 0.0 ? options.max_hold_s : std::max(0.02, 5.0 * s.median_interval());
  };
  const double hold_acc = hold_for(data.accelerometer), hold_mag = hold_for(data.magnetometer);
  const double gap = options.gap_factor * gyro_dt;

  OrientationTrack track;
  track.t.reserve(data.gyroscope.size());
  track.q_world_device.reserve(data.gyroscope.size());
  filter.reset(q0);
  const Vec3* acc = nullptr;
  const Vec3* mag = nullptr;
  double t_acc = -std::numeric_limits<double>::infinity(), t_mag = t_acc;

  // The three-way merge inline (no event vector): this loop is the hot path of every filter.
  const auto& A = data.accelerometer;
  const auto& M = data.magnetometer;
  const auto& G = data.gyroscope;
  std::size_t ia = 0, im = 0;
  for (std::size_t ig = 0; ig < G.size(); ++ig) {
    const double t = G.t[ig];
    while (ia < A.size() && A.t[ia] <= t) acc = &A.v[ia], t_acc = A.t[ia], ++ia;
    while (im < M.size() && M.t[im] <= t) mag = &M.v[im], t_mag = M.t[im], ++im;
    double dt = ig == 0 ? gyro_dt : t - G.t[ig - 1];
    const bool regular = ig > 0 && dt > 0.0 && dt <= gap;
    if (!regular) dt = gyro_dt;  // a gap is not integrated: the corrections pull the filter back
    const Vec3 w = options.gyro_trapezoid && regular && G.v[ig - 1].allFinite() ? Vec3(0.5 * (G.v[ig] + G.v[ig - 1]))
                                                                               : G.v[ig];
    const double age_a = t - t_acc, age_m = t - t_mag;
    filter.update_with_ages(dt, w, (acc && age_a <= hold_acc) ? acc : nullptr, age_a,
                            (mag && age_m <= hold_mag) ? mag : nullptr, age_m);
    track.push_back(t, filter.q_world_device(), filter.covariance());
  }
  return track;
}

Quat initial_attitude(const ImuData& data, double average_s) {
  auto mean_of = [&](const SensorSeries& s) {
    Vec3 sum = Vec3::Zero();
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size() && (n == 0 || s.t[i] <= s.t[0] + average_s); ++i) sum += s.v[i], ++n;
    return Vec3(sum / static_cast<double>(std::max<std::size_t>(n, 1)));
  };
  const Vec3 f = mean_of(data.accelerometer);
  if (data.has_magnetometer()) {
    const Vec3 m = mean_of(data.magnetometer);
    if (f.norm() > 0.0 && m.cross(f).norm() > 1e-6 * m.norm() * f.norm())
      return Quat(triad_world_device(f, m)).normalized();
  }
  // Tilt only: the smallest rotation taking the measured up direction to the world's up.
  if (!(f.norm() > 0.0)) return Quat::Identity();
  return Quat::FromTwoVectors(f.normalized(), Vec3::UnitZ()).normalized();
}

// ---- params and output ------------------------------------------------------------------

EstimatorParams parse_params(const std::vector<std::string>& name_value) {
  EstimatorParams out;
  for (const auto& kv : name_value) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--param", fmt::format("'{}' is not name=value (e.g. beta=0.1)", kv));
    const std::string name = kv.substr(0, eq);
    const std::string text = kv.substr(eq + 1);
    double v = 0.0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || !std::isfinite(v))
      throw InputError("--param", fmt::format("'{}': value '{}' is not a finite number", name, text));
    if (!out.emplace(name, v).second) throw InputError("--param", fmt::format("'{}' is given twice", name));
  }
  return out;
}

std::vector<std::string> estimator_names() {
  std::vector<std::string> names;
  for (const auto& e : estimator_registry()) names.push_back(e.name);
  return names;
}

std::unique_ptr<OrientationEstimator> make_estimator(std::string_view name, const EstimatorParams& params) {
  for (const auto& e : estimator_registry()) {
    if (e.name != name) continue;
    EstimatorParams full;
    std::vector<std::string> known;
    for (const auto& p : e.params) full[p.name] = p.default_value, known.push_back(p.name);
    for (const auto& [k, v] : params) {
      if (!full.count(k))
        throw InputError("--param", fmt::format("unknown parameter '{}' for method {} (expected {})", k, e.name,
                                                known.empty() ? std::string("none") : fmt::format("{}", fmt::join(known, ", "))));
      full[k] = v;
    }
    return e.create(full);
  }
  throw InputError({}, fmt::format("unknown orientation method '{}' (expected one of {})", name,
                                   fmt::join(estimator_names(), ", ")));
}

void write_track_csv(const OrientationTrack& track, const std::filesystem::path& file) {
  std::string out;
  out.reserve(track.size() * 96);
  out += track.has_uncertainty() ? "t,qw,qx,qy,qz,tilt_sigma_deg,heading_sigma_deg\n" : "t,qw,qx,qy,qz\n";
  for (std::size_t i = 0; i < track.size(); ++i) {
    const Quat& q = track.q_world_device[i];
    out += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g}", io::format_number(track.t[i]), q.w(), q.x(), q.y(), q.z());
    if (track.has_uncertainty()) {
      const Mat3& c = track.covariance[i];
      out += fmt::format(",{:.4g},{:.4g}", rad2deg(std::sqrt(0.5 * (c(0, 0) + c(1, 1)))), rad2deg(std::sqrt(c(2, 2))));
    }
    out += '\n';
  }
  io::write_text_atomic(file, out);
}

}  // namespace antpose::orientation
