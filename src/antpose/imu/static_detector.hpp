// Static (still) windows of a capture: the thesis's §4.3 detector.
//
// The thesis declares the phone still when, over a sliding window, the standard deviation of
// every accelerometer axis is small compared with the mean. We read "relative to the mean" as
// relative to the magnitude of the mean vector, σ_k / |mean(a)| (≈ σ_k / g), because the mean
// of a single axis can be zero at rest and would make a per-axis ratio meaningless.
// Added to that (the thesis uses the accelerometer only):
//   - gyroscope, when present: every axis std ≤ gyro_std_max AND |mean(ω) − bias| ≤
//     gyro_rate_max, the bias being the per-axis median of the means of the windows that pass
//     every other test (a slow steady rotation has a small std but a large mean rate);
//   - magnetometer: every axis σ_k / |mean(m)| ≤ mag_rel_std_max. It is used when the
//     gyroscope is missing (then a rotation about gravity is only seen by it, from about
//     0.2 rad/s at mid latitudes) or when `magnetometer` is kAlways.
// Streams may be asynchronous: windows are laid on a common time grid and each stream's
// samples inside a window are used. Windows that pass are merged into maximal intervals.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "antpose/io/capture.hpp"

namespace antpose::imu {

struct StaticDetectorParams {
  double window_s = 1.0;             // sliding window length
  double step_s = 0.05;              // window start spacing
  double acc_rel_std_max = 0.01;     // per-axis acc std / |mean acc| (0.01·g ≈ 0.1 m/s²)
  double gyro_std_max = 0.05;        // rad/s (≈ 2.9°/s), per axis: hand tremor on the plate passes
  double gyro_rate_max = 0.01;       // rad/s (≈ 0.6°/s), |mean rate − bias|: the slow end of a move fails
  double mag_rel_std_max = 0.02;     // per-axis mag std / |mean mag| (≈ 1 µT at 50 µT)
  enum class Magnetometer { kWhenNoGyroscope, kAlways, kNever };
  Magnetometer magnetometer = Magnetometer::kWhenNoGyroscope;
  std::size_t min_samples = 5;       // per stream and window
  double min_fill = 0.5;             // a window needs this fraction of its expected samples (gaps)
};

struct StaticWindow {
  double t0 = 0.0;  // s, capture clock
  double t1 = 0.0;
  double duration() const { return t1 - t0; }
};

struct StaticDetection {
  std::vector<StaticWindow> windows;  // maximal static intervals, longest first
  bool used_gyroscope = false;
  bool used_magnetometer = false;
  Vec3 gyro_bias = Vec3::Zero();      // rad/s, median over static windows (zero without gyroscope)
  std::vector<std::string> notes;     // e.g. "no gyroscope: accelerometer + magnetometer criteria only"

  const StaticWindow* longest() const { return windows.empty() ? nullptr : &windows.front(); }
};

/// Finds the static intervals of a capture. Requires an accelerometer stream (InputError
/// otherwise); gyroscope and magnetometer are optional. An empty `windows` means nothing
/// was still long enough (not an error here; callers decide).
StaticDetection detect_static(const Capture& capture, const StaticDetectorParams& params = {});

}  // namespace antpose::imu
