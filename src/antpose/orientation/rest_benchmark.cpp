#include "antpose/orientation/rest_benchmark.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "antpose/orientation/static_orientation.hpp"

namespace antpose::orientation {
namespace {

// O(1) window means of a 3-axis stream (sums offset by the first sample).
class PrefixMean {
 public:
  explicit PrefixMean(const Stream& s) : t_(&s.t), offset_(s.xyz(0)), sum_(s.size() + 1, Vec3::Zero()) {
    for (std::size_t i = 0; i < s.size(); ++i) sum_[i + 1] = sum_[i] + (s.xyz(i) - offset_);
  }
  // Mean over t in [t0, t1]; false when no sample lies there.
  bool mean(double t0, double t1, Vec3& out) const {
    const auto b = static_cast<std::size_t>(std::lower_bound(t_->begin(), t_->end(), t0) - t_->begin());
    const auto e = static_cast<std::size_t>(std::upper_bound(t_->begin(), t_->end(), t1) - t_->begin());
    if (e <= b) return false;
    out = (sum_[e] - sum_[b]) / static_cast<double>(e - b) + offset_;
    return true;
  }

 private:
  const std::vector<double>* t_;
  Vec3 offset_;
  std::vector<Vec3> sum_;
};

std::size_t column_of(const Stream& s, const char* name, const std::filesystem::path& where) {
  const auto it = std::find(s.columns.begin(), s.columns.end(), name);
  if (it == s.columns.end())
    throw InputError(where, fmt::format("the truth has no '{}' column (needs t,qw,qx,qy,qz,valid,moving)", name));
  return static_cast<std::size_t>(it - s.columns.begin());
}

}  // namespace

BroadErrors broad_errors(const Quat& q_est, const Quat& q_ref) {
  const Quat e = (q_est.normalized() * q_ref.normalized().conjugate()).normalized();
  const double w = e.w(), z = e.z();
  BroadErrors out;
  out.total = 2.0 * std::acos(std::min(1.0, std::abs(w)));
  out.heading = 2.0 * std::atan2(std::abs(z), std::abs(w));
  out.inclination = 2.0 * std::acos(std::min(1.0, std::sqrt(w * w + z * z)));
  return out;
}

RestBenchmarkTrial evaluate_rest_orientation(const Capture& capture, const std::string& name,
                                             const RestBenchmarkOptions& options) {
  const std::filesystem::path where = capture.root / "capture.yaml";
  if (!capture.truth_orientation) throw InputError(where, "no truth orientation (truth: orientation:) to score against");
  if (capture.truth_world != "enu-magnetic")
    throw InputError(where, fmt::format("truth world is '{}'; the rest-phase benchmark compares the eCompass "
                                        "directly and needs 'enu-magnetic' truth",
                                        capture.truth_world));
  const Stream& truth = *capture.truth_orientation;
  const std::size_t c_qw = column_of(truth, "qw", where), c_qx = column_of(truth, "qx", where),
                    c_qy = column_of(truth, "qy", where), c_qz = column_of(truth, "qz", where),
                    c_valid = column_of(truth, "valid", where), c_moving = column_of(truth, "moving", where);
  const Stream& acc_stream = capture.require(streams::kAccelerometer);
  const Stream& mag_stream = capture.require(streams::kMagnetometer);
  if (acc_stream.empty() || mag_stream.empty())
    throw InputError(where, "the accelerometer or magnetometer stream is empty");
  const PrefixMean acc(acc_stream), mag(mag_stream);

  auto value = [&](std::size_t i, std::size_t c) { return truth.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)); };
  const std::size_t n = truth.size();
  auto resting = [&](std::size_t i) { return value(i, c_moving) == 0.0; };
  auto valid = [&](std::size_t i) { return value(i, c_valid) != 0.0 && std::isfinite(value(i, c_qw)); };

  // Rest phase [start, end] (indices) of every sample.
  std::vector<std::size_t> phase_start(n), phase_end(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && resting(j + 1) == resting(i)) ++j;
    for (std::size_t k = i; k <= j; ++k) {
      phase_start[k] = i;
      phase_end[k] = j;
    }
    i = j + 1;
  }

  RestBenchmarkTrial out;
  out.name = name;
  double sum_tot = 0.0, sum_head = 0.0, sum_inc = 0.0;
  std::size_t first = n;
  for (std::size_t i = 0; i < n; ++i)
    if (resting(i) && valid(i)) {
      first = i;
      break;
    }
  if (first == n) throw MeasurementError(fmt::format("{}: no rest sample (moving = 0) with valid truth", name));

  std::size_t last_phase = n;
  for (std::size_t i = first; i < n && out.rest_s < options.rest_s; ++i) {
    if (!resting(i)) continue;
    const double dt = i + 1 < n ? truth.t[i + 1] - truth.t[i] : 0.0;
    out.rest_s += dt;
    if (phase_start[i] != last_phase) {
      last_phase = phase_start[i];
      ++out.rest_phases;
    }
    if (!valid(i)) continue;
    const double t = truth.t[i];
    const double lo = std::max(t - options.window_s / 2, truth.t[phase_start[i]]);
    const double hi = std::min(t + options.window_s / 2, truth.t[phase_end[i]]);
    Vec3 a, m;
    if (!acc.mean(lo, hi, a) || !mag.mean(lo, hi, m)) continue;
    const Quat q_est(triad_world_device(a, m));
    const Quat q_ref(value(i, c_qw), value(i, c_qx), value(i, c_qy), value(i, c_qz));
    const BroadErrors e = broad_errors(q_est, q_ref);
    sum_tot += e.total * e.total;
    sum_head += e.heading * e.heading;
    sum_inc += e.inclination * e.inclination;
    ++out.samples;
  }
  if (out.samples == 0) throw MeasurementError(fmt::format("{}: no scored rest sample", name));
  const double k = static_cast<double>(out.samples);
  out.rmse = {std::sqrt(sum_tot / k), std::sqrt(sum_head / k), std::sqrt(sum_inc / k)};
  return out;
}

BroadErrors mean_rmse(const std::vector<RestBenchmarkTrial>& trials) {
  BroadErrors m;
  if (trials.empty()) return m;
  for (const auto& t : trials) {
    m.total += t.rmse.total;
    m.heading += t.rmse.heading;
    m.inclination += t.rmse.inclination;
  }
  const double k = static_cast<double>(trials.size());
  return {m.total / k, m.heading / k, m.inclination / k};
}

}  // namespace antpose::orientation
