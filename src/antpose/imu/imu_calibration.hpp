// Per-device IMU calibration and its YAML file.
//
// Model (device frame, SI units), correction form of imu_tk (Tedaldi, Pretto, Menegatti,
// "A Robust and Easy to Implement Method for IMU Calibration without External Equipments",
// ICRA 2014, eqs. 8 and 14):
//   magnetometer  m = R_m · S · (m_raw − b_hard)            b_hard µT, S soft iron (identity by default),
//                                                           R_m its axes turned onto the accelerometer's
//   accelerometer a = T_a · diag(k_a) · (a_raw − b_acc)     b_acc m/s², k_a per-axis scale,
//   gyroscope     ω = T_g · diag(k_g) · (ω_raw − b_gyro)    T misalignment (unit diagonal), rad/s
// The seed/lecture sensor model y = T_m K_m x + b is the same map inverted:
// T_m K_m = (T diag(k))⁻¹. For the accelerometer T_a is upper triangular (3 angles: the
// calibrated frame is defined by the accelerometer's own x axis and xy plane); for the
// gyroscope T_g is full (6 angles), because the gyroscope is aligned to that frame.
// Version-1 files without `misalignment` (and a gyroscope without `scale`) read as T = I,
// k = 1, which is the earlier model a = k ⊙ (a_raw − b), ω = ω_raw − b.
//
// File (`format: antpose-device`, `version: 1`):
//   format: antpose-device
//   version: 1
//   device: {model: ..., id: ...}          optional
//   imu:
//     magnetometer:  {hard_iron_uT: [x, y, z], soft_iron: [[..], [..], [..]], field_uT: F,
//                     residual_rel: r, alignment: [[..], [..], [..]]}   alignment = R_m, a rotation
//     accelerometer: {bias_m_s2: [x, y, z], scale: [x, y, z], misalignment: [[..], [..], [..]],
//                     residual_rms_m_s2: r}
//     gyroscope:     {bias_rad_s: [x, y, z], scale: [x, y, z], misalignment: [[..], [..], [..]],
//                     residual_rms_deg: r}
// field_uT / residual_* are fit diagnostics (written when known). Every entry is optional
// (missing = neutral). Unknown keys are kept and written back, so a
// later version can add sections without breaking older files.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "antpose/io/capture.hpp"

namespace antpose::imu {

struct ImuCalibration {
  static constexpr int kFormatVersion = 1;

  Vec3 mag_hard_iron_uT = Vec3::Zero();
  Mat3 mag_soft_iron = Mat3::Identity();
  /// R_calibrated_magnetometer: the corrected field from the magnetometer's axes into the
  /// calibrated (accelerometer) frame (calibration::fit_magnetometer_alignment).
  Mat3 mag_alignment = Mat3::Identity();
  /// 1σ of the hard iron (µT), of each soft-iron entry, and per axis of mag_alignment's rotation
  /// vector (rad), as the fits measured them: the compass's calibration error, which
  /// measure::heading_from_field carries to the heading.
  std::optional<Vec3> mag_hard_iron_sigma_uT;
  std::optional<Mat3> mag_soft_iron_sigma;
  std::optional<Vec3> mag_alignment_sigma_rad;
  Vec3 acc_bias = Vec3::Zero();   // m/s²
  Vec3 acc_scale = Vec3::Ones();
  Mat3 acc_misalignment = Mat3::Identity();  // T_a, unit diagonal
  Vec3 gyro_bias = Vec3::Zero();  // rad/s
  Vec3 gyro_scale = Vec3::Ones();
  Mat3 gyro_misalignment = Mat3::Identity();  // T_g, unit diagonal
  // Fit diagnostics (informative; not used by apply()).
  std::optional<double> mag_field_uT;         // fitted field strength F (|m| after correction)
  std::optional<double> mag_residual_rel;     // std(|m_corrected|) / F
  std::optional<double> acc_residual_rms_m_s2;  // RMS(|a_corrected| − g) over static frames
  std::optional<double> gyro_residual_rms_deg;  // RMS gravity-direction error after integration

  /// Correction matrices T · diag(k) (apply as C (raw − b)).
  Mat3 acc_correction() const { return acc_misalignment * acc_scale.asDiagonal(); }
  Mat3 gyro_correction() const { return gyro_misalignment * gyro_scale.asDiagonal(); }
  Vec3 correct_acc(const Vec3& raw) const { return acc_correction() * (raw - acc_bias); }
  Vec3 correct_gyro(const Vec3& raw) const { return gyro_correction() * (raw - gyro_bias); }
  Vec3 correct_mag(const Vec3& raw) const { return mag_alignment * (mag_soft_iron * (raw - mag_hard_iron_uT)); }
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
