// Automatic collection of the static frames of a multi-position calibration recording
// (thesis §4.3; Tedaldi et al. ICRA 2014 §III-A): the still intervals found by
// imu::detect_static, each reduced to the mean accelerometer (and gyroscope) reading.
#pragma once

#include <cstddef>
#include <vector>

#include "antpose/imu/static_detector.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::calibration {

struct StaticFrame {
  double t0 = 0.0, t1 = 0.0;       // s, capture clock
  Vec3 acc_mean = Vec3::Zero();    // raw accelerometer, sensor frame
  Vec3 acc_std = Vec3::Zero();
  std::size_t acc_samples = 0;
  Vec3 gyro_mean = Vec3::Zero();   // raw gyroscope (zero when there is none)
  std::size_t gyro_samples = 0;
};

struct StaticFrameOptions {
  imu::StaticDetectorParams detector{};
  /// Removed from both ends of each still interval: the detector's 1 s windows accept the slow
  /// start and end of a smooth move (a minimum-jerk rotation of 2 s turns ≈ 1.5° in its first
  /// 0.2 s), which would tilt the frame's mean gravity direction.
  double trim_s = 0.5;
  double min_duration_s = 1.0;  // shorter intervals (after trimming) are dropped
};

/// The static frames of `capture` in time order. Requires an accelerometer (InputError naming
/// the capture otherwise); returns an empty list when nothing was still (callers say how many
/// they need).
std::vector<StaticFrame> collect_static_frames(const Capture& capture, const StaticFrameOptions& options = {});

/// Mean of rows of `stream` with t0 ≤ t ≤ t1 (and the count).
std::pair<Vec3, std::size_t> stream_mean(const Stream& stream, double t0, double t1);

}  // namespace antpose::calibration
