#include "antpose/measure/device_setup.hpp"

#include "antpose/core/error.hpp"

namespace antpose::measure {

NonContactSetup device_setup(const store::DeviceProfile& device, const std::filesystem::path& where) {
  if (!device.camera)
    throw InputError(where, "the device has no camera intrinsics: run 'antpose calibrate camera --device' first");
  if (!device.camera_imu)
    throw InputError(where,
                     "the device has no camera–IMU rotation (R_device_camera): run 'antpose calibrate joint "
                     "--device' first; the nominal layout is off by degrees on real phones");
  NonContactSetup s;
  s.intrinsics = device.camera->intrinsics;
  s.camera_imu.R_device_camera = device.camera_imu->R_device_camera;
  s.camera_imu.time_offset_s = device.camera_imu->time_offset_s;
  if (device.camera_imu->rotation_sigma_rad)
    s.camera_imu.covariance = device.camera_imu->rotation_sigma_rad->cwiseAbs2().asDiagonal();
  s.camera_imu.compass = compass_calibration(device.imu);
  return s;
}

}  // namespace antpose::measure
