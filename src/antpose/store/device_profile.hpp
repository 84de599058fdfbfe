// A device profile: everything antpose knows about one phone (unit), as a YAML file and as a
// record of the device database (device_db.hpp).
//
// It extends the IMU calibration file (imu/imu_calibration.hpp, `format: antpose-device`):
//   format: antpose-device
//   version: 1
//   device: {model: ..., id: ...}
//   imu: {...}                                  as imu_calibration.hpp
//   camera:                                     intrinsics (camera/camera_model.hpp)
//     width_px: 4000
//     height_px: 3000
//     fx_px: ..  fy_px: ..  cx_px: ..  cy_px: ..
//     distortion: [k1, k2, p1, p2, k3]
//     rms_px: 0.41                              fit diagnostic
//     principal_point_sigma_px: [0.4, 0.4]      1σ of cx, cy (optional)
//   camera_imu:
//     R_device_camera: [[..], [..], [..]]       rotates camera-frame vectors into the device frame
//     rotation_sigma_deg: [sx, sy, sz]          1σ of the rotation error vector (device frame), optional
//     time_offset_s: 0.012                      IMU-clock instant of a photo = shots.csv t + time_offset_s
//     time_offset_sigma_s: 0.002                optional
//     method: reference-free | thesis           how it was obtained
// Every section is optional; unknown keys are kept when the file is rewritten.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "antpose/camera/camera_model.hpp"
#include "antpose/imu/imu_calibration.hpp"

namespace antpose::store {

struct CameraImuCalibration {
  Mat3 R_device_camera = camera::nominal_R_device_camera();
  std::optional<Vec3> rotation_sigma_rad;  // 1σ per axis of the error rotation vector, device frame
  double time_offset_s = 0.0;
  std::optional<double> time_offset_sigma_s;
  std::string method;
};

struct CameraCalibrationInfo {
  camera::CameraIntrinsics intrinsics;
  std::optional<double> rms_px;
  std::optional<Vec2> principal_point_sigma_px;  // 1σ of cx, cy: bounds the rotation bias of every pose
};

struct DeviceProfile {
  std::string id;     // key in the database; device.id in YAML
  std::string model;  // device.model
  imu::ImuCalibration imu;  // neutral when never calibrated; also carries the YAML document
  bool has_imu = false;
  std::optional<CameraCalibrationInfo> camera;
  std::optional<CameraImuCalibration> camera_imu;
};

/// Reads a device YAML (an IMU calibration file is a profile with only `imu`). InputError naming
/// the file and line for every bad value, with what was expected.
DeviceProfile read_device_profile(const std::filesystem::path& file);
DeviceProfile parse_device_profile(const std::string& text, const std::filesystem::path& file);
/// YAML text (unknown keys kept); write_device_profile writes it atomically.
std::string format_device_profile(const DeviceProfile& profile);
void write_device_profile(const DeviceProfile& profile, const std::filesystem::path& file);

}  // namespace antpose::store
