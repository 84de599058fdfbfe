// `antpose calibrate imu`: every IMU calibration of an imu-calibration capture, assembled into
// the device calibration (imu::ImuCalibration) with the residuals before and after.
//
//  method thesis: accelerometer normalization (thesis §4.3), gyroscope bias from the static
//                 frames, magnetometer hard iron (max + min)/2 (thesis §4.4);
//  method full:   accelerometer and gyroscope 9-parameter models (Tedaldi et al. ICRA 2014),
//                 magnetometer ellipsoid (hard + soft iron).
// The gyroscope fit needs the accelerometer's gravity directions, so selecting the gyroscope
// calibrates the accelerometer too (it is written only when selected).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "antpose/calibration/accelerometer.hpp"
#include "antpose/calibration/gyroscope.hpp"
#include "antpose/calibration/magnetometer.hpp"
#include "antpose/calibration/static_frames.hpp"
#include "antpose/imu/hard_iron.hpp"
#include "antpose/imu/imu_calibration.hpp"

namespace antpose::calibration {

enum class Method { kThesis, kFull };
Method parse_method(const std::string& text);  // "thesis" | "full"; InputError otherwise

struct CalibrateImuOptions {
  bool accelerometer = true;
  bool gyroscope = true;
  bool magnetometer = true;
  Method method = Method::kFull;
  /// m/s²; default: normal gravity at the capture's site, else 9.80665.
  std::optional<double> gravity;
  StaticFrameOptions frames{};
  GyroscopeOptions gyroscope_options{};
  MagnetometerOptions magnetometer_options{};
  MagnetometerAlignmentOptions magnetometer_alignment_options{};
};

/// Parses "acc,gyro,mag" (any subset, also accelerometer/gyroscope/magnetometer) into the three
/// flags of `options`; InputError naming the value otherwise.
void parse_sensors(const std::string& list, CalibrateImuOptions& options);

struct CalibrateImuResult {
  imu::ImuCalibration calibration;
  double gravity = 0.0;
  std::vector<StaticFrame> frames;
  std::optional<AccelerometerCalibration> accelerometer_thesis;
  std::optional<AccelerometerCalibration> accelerometer;  // the one used (thesis or full)
  std::optional<GyroscopeCalibration> gyroscope;
  std::optional<MagnetometerCalibration> magnetometer;   // method full
  std::optional<MagnetometerAlignment> magnetometer_alignment;  // method full, the accelerometer calibrated
  std::optional<imu::HardIronEstimate> hard_iron;         // method thesis
  bool wrote_accelerometer = false, wrote_gyroscope = false, wrote_magnetometer = false;
};

/// Runs the selected calibrations on `capture` and returns the calibration with the sections of
/// the selected sensors set on top of `base` (other sections and unknown keys kept). Errors:
/// InputError for a missing stream, MeasurementError when the data cannot support a fit; both
/// name `source`.
CalibrateImuResult calibrate_imu(const Capture& capture, const CalibrateImuOptions& options, Diagnostics& diagnostics,
                                 const std::filesystem::path& source, const imu::ImuCalibration& base = {});

/// The whole command: reads the capture, calibrates, writes `output` atomically. An existing
/// `output` is read first and its other sections are kept (with `force`, it is ignored and
/// replaced, even when it is not a valid device file). If anything fails the existing file is
/// left untouched and the error says so.
CalibrateImuResult calibrate_imu_file(const std::filesystem::path& capture, const std::filesystem::path& output,
                                      const CalibrateImuOptions& options, bool force, Diagnostics& diagnostics);

/// Human-readable summary: residuals before/after and parameters per sensor.
std::string describe(const CalibrateImuResult& result);

}  // namespace antpose::calibration
