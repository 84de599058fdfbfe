#include "antpose/imu/static_detector.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "antpose/core/statistics.hpp"

namespace antpose::imu {
namespace {

// Running sums of a 3-axis stream for O(1) window mean and std. Values are offset by the first
// sample so that the sums of squares do not lose the small variances to cancellation.
class PrefixStats {
 public:
  explicit PrefixStats(const Stream& s) : t_(&s.t) {
    const std::size_t n = s.size();
    offset_ = s.xyz(0);
    sum_.assign(n + 1, Vec3::Zero());
    sq_.assign(n + 1, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 v = s.xyz(i) - offset_;
      sum_[i + 1] = sum_[i] + v;
      sq_[i + 1] = sq_[i] + v.cwiseProduct(v);
    }
    std::vector<double> dt;
    for (std::size_t i = 1; i < n; ++i) dt.push_back(s.t[i] - s.t[i - 1]);
    median_dt_ = median(std::move(dt));
  }

  struct Window {
    std::size_t n = 0;
    Vec3 mean = Vec3::Zero();
    Vec3 std = Vec3::Zero();
  };

  Window window(double t0, double t1) const {
    const auto b = static_cast<std::size_t>(std::lower_bound(t_->begin(), t_->end(), t0) - t_->begin());
    const auto e = static_cast<std::size_t>(std::lower_bound(t_->begin(), t_->end(), t1) - t_->begin());
    Window w;
    w.n = e > b ? e - b : 0;
    if (w.n == 0) return w;
    const double n = static_cast<double>(w.n);
    const Vec3 m = (sum_[e] - sum_[b]) / n;
    const Vec3 var = ((sq_[e] - sq_[b]) / n - m.cwiseProduct(m)).cwiseMax(0.0);
    w.mean = m + offset_;
    w.std = (var * (n / std::max(1.0, n - 1.0))).cwiseSqrt();
    return w;
  }

  double front() const { return t_->front(); }
  double back() const { return t_->back(); }
  double median_dt() const { return median_dt_; }

 private:
  const std::vector<double>* t_;
  Vec3 offset_;
  std::vector<Vec3> sum_, sq_;
  double median_dt_ = 0.0;
};

bool enough(const PrefixStats::Window& w, const PrefixStats& s, const StaticDetectorParams& p) {
  if (w.n < p.min_samples) return false;
  if (s.median_dt() <= 0.0) return true;
  return static_cast<double>(w.n) >= p.min_fill * p.window_s / s.median_dt();
}

bool relative_std_ok(const PrefixStats::Window& w, double limit) {
  const double norm = w.mean.norm();
  return norm > 0.0 && w.std.maxCoeff() <= limit * norm;
}

}  // namespace

StaticDetection detect_static(const Capture& capture, const StaticDetectorParams& params) {
  if (!(params.window_s > 0.0) || !(params.step_s > 0.0))
    throw Error("static detector: window_s and step_s must be positive");
  const Stream& acc_stream = capture.require(streams::kAccelerometer);
  const Stream* gyro_stream = capture.find(streams::kGyroscope);
  const Stream* mag_stream = capture.find(streams::kMagnetometer);
  if (gyro_stream && (gyro_stream->empty() || !gyro_stream->has_xyz())) gyro_stream = nullptr;
  if (mag_stream && (mag_stream->empty() || !mag_stream->has_xyz())) mag_stream = nullptr;

  StaticDetection out;
  out.used_gyroscope = gyro_stream != nullptr;
  const bool want_mag = params.magnetometer == StaticDetectorParams::Magnetometer::kAlways ||
                        (params.magnetometer == StaticDetectorParams::Magnetometer::kWhenNoGyroscope && !gyro_stream);
  out.used_magnetometer = want_mag && mag_stream != nullptr;
  if (!gyro_stream) {
    out.notes.push_back(out.used_magnetometer
                            ? "no gyroscope stream: static windows from accelerometer + magnetometer criteria only"
                            : "no gyroscope or magnetometer stream: static windows from the accelerometer only "
                              "(a rotation about gravity is not detected)");
  }
  if (acc_stream.empty() || !acc_stream.has_xyz()) return out;

  const PrefixStats acc(acc_stream);
  std::optional<PrefixStats> gyro, mag;
  if (gyro_stream) gyro.emplace(*gyro_stream);
  if (out.used_magnetometer) mag.emplace(*mag_stream);

  double begin = acc.front(), end = acc.back();
  for (const auto* s : {gyro ? &*gyro : nullptr, mag ? &*mag : nullptr}) {
    if (!s) continue;
    begin = std::max(begin, s->front());
    end = std::min(end, s->back());
  }

  struct Candidate {
    double t0;
    Vec3 gyro_mean;
  };
  std::vector<Candidate> candidates;
  const auto steps = end - begin >= params.window_s
                         ? static_cast<std::size_t>(std::floor((end - begin - params.window_s) / params.step_s)) + 1
                         : 0;
  for (std::size_t k = 0; k < steps; ++k) {
    const double t0 = begin + static_cast<double>(k) * params.step_s;
    const double t1 = t0 + params.window_s;
    const auto a = acc.window(t0, t1);
    if (!enough(a, acc, params) || !relative_std_ok(a, params.acc_rel_std_max)) continue;
    Candidate c{t0, Vec3::Zero()};
    if (gyro) {
      const auto g = gyro->window(t0, t1);
      if (!enough(g, *gyro, params) || g.std.maxCoeff() > params.gyro_std_max) continue;
      c.gyro_mean = g.mean;
    }
    if (mag) {
      const auto m = mag->window(t0, t1);
      if (!enough(m, *mag, params) || !relative_std_ok(m, params.mag_rel_std_max)) continue;
    }
    candidates.push_back(c);
  }

  if (gyro && !candidates.empty()) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> v;
      v.reserve(candidates.size());
      for (const auto& c : candidates) v.push_back(c.gyro_mean[axis]);
      out.gyro_bias[axis] = median(std::move(v));
    }
    std::erase_if(candidates, [&](const Candidate& c) {
      return (c.gyro_mean - out.gyro_bias).norm() > params.gyro_rate_max;
    });
  }

  // Union of the passing windows [t0, t0 + window_s].
  for (const auto& c : candidates) {
    const double t1 = c.t0 + params.window_s;
    if (!out.windows.empty() && c.t0 <= out.windows.back().t1 + 1e-9) {
      out.windows.back().t1 = std::max(out.windows.back().t1, t1);
    } else {
      out.windows.push_back({c.t0, t1});
    }
  }
  std::stable_sort(out.windows.begin(), out.windows.end(),
                   [](const StaticWindow& a, const StaticWindow& b) { return a.duration() > b.duration(); });
  return out;
}

}  // namespace antpose::imu
