#include "antpose/calibration/static_frames.hpp"

#include <algorithm>

namespace antpose::calibration {

std::pair<Vec3, std::size_t> stream_mean(const Stream& s, double t0, double t1) {
  const auto b = std::lower_bound(s.t.begin(), s.t.end(), t0);
  const auto e = std::upper_bound(s.t.begin(), s.t.end(), t1);
  Vec3 sum = Vec3::Zero();
  std::size_t n = 0;
  for (auto it = b; it < e; ++it, ++n) sum += s.xyz(static_cast<std::size_t>(it - s.t.begin()));
  return {n ? Vec3(sum / static_cast<double>(n)) : Vec3(Vec3::Zero()), n};
}

std::vector<StaticFrame> collect_static_frames(const Capture& capture, const StaticFrameOptions& options) {
  const Stream& acc = capture.require(streams::kAccelerometer);
  const Stream* gyro = capture.find(streams::kGyroscope);
  const imu::StaticDetection detection = imu::detect_static(capture, options.detector);
  std::vector<StaticFrame> frames;
  for (imu::StaticWindow w : detection.windows) {
    w.t0 += options.trim_s;
    w.t1 -= options.trim_s;
    if (w.duration() < options.min_duration_s) continue;
    StaticFrame f;
    f.t0 = w.t0;
    f.t1 = w.t1;
    std::tie(f.acc_mean, f.acc_samples) = stream_mean(acc, w.t0, w.t1);
    if (f.acc_samples < 2) continue;
    Vec3 var = Vec3::Zero();
    const auto b = std::lower_bound(acc.t.begin(), acc.t.end(), w.t0);
    const auto e = std::upper_bound(acc.t.begin(), acc.t.end(), w.t1);
    for (auto it = b; it < e; ++it) var += (acc.xyz(static_cast<std::size_t>(it - acc.t.begin())) - f.acc_mean).array().square().matrix();
    f.acc_std = (var / static_cast<double>(f.acc_samples - 1)).cwiseSqrt();
    if (gyro && gyro->has_xyz()) std::tie(f.gyro_mean, f.gyro_samples) = stream_mean(*gyro, w.t0, w.t1);
    frames.push_back(f);
  }
  std::sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.t0 < b.t0; });
  return frames;
}

}  // namespace antpose::calibration
