// Per-device IMU calibration and its YAML file.
//
// Model (device frame, SI units):
//   magnetometer  m = S · (m_raw − b_hard)          b_hard µT, S soft iron (identity by default)
//   accelerometer a = k ⊙ (a_raw − b_acc)           b_acc m/s², k per-axis scale
//   gyroscope     ω = ω_raw − b_gyro                rad/s
//
// File (`format: antpose-device`, `version: 1`):
//   format: antpose-device
//   version: 1
//   device: {model: ..., id: ...}          optional
//   imu:
//     magnetometer:  {hard_iron_uT: [x, y, z], soft_iron: [[..], [..], [..]]}
//     accelerometer: {bias_m_s2: [x, y, z], scale: [x, y, z]}
//     gyroscope:     {bias_rad_s: [x, y, z]}
// Every entry is optional (missing = neutral). Unknown keys are kept and written back, so a
// later version can add sections without breaking older files.
#pragma once

#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "antpose/io/capture.hpp"

namespace antpose::imu {

struct ImuCalibration {
  static constexpr int kFormatVersion = 1;

  Vec3 mag_hard_iron_uT = Vec3::Zero();
  Mat3 mag_soft_iron = Mat3::Identity();
  Vec3 acc_bias = Vec3::Zero();   // m/s²
  Vec3 acc_scale = Vec3::Ones();
  Vec3 gyro_bias = Vec3::Zero();  // rad/s
  std::string device_model;
  std::string device_id;
  /// The file as read; unknown keys survive write_imu_calibration.
  YAML::Node document;
};

/// Reads and validates a calibration file. Errors are InputError naming the file and the
/// 1-based line of the offending value, with what was expected.
ImuCalibration read_imu_calibration(const std::filesystem::path& file);
/// Same for YAML text; `file` only names the source in messages.
ImuCalibration parse_imu_calibration(const std::string& text, const std::filesystem::path& file);

/// YAML text of a calibration (unknown keys of `document` kept).
std::string format_imu_calibration(const ImuCalibration& calibration);
/// Writes the file atomically (io::write_text_atomic).
void write_imu_calibration(const ImuCalibration& calibration, const std::filesystem::path& file);

/// Corrects the accelerometer, gyroscope and magnetometer streams of `capture` in place with
/// the model above (streams that are missing are skipped).
void apply(const ImuCalibration& calibration, Capture& capture);

}  // namespace antpose::imu
