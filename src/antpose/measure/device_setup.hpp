// The phone's part of a non-contact setup, from its device profile (docs/devices.md): what every
// verb that measures from photos needs of the calibrations, checked once.
#pragma once

#include <filesystem>

#include "antpose/measure/non_contact.hpp"
#include "antpose/store/device_profile.hpp"

namespace antpose::measure {

/// A setup with the device's intrinsics and camera–IMU rotation (with its σ where the calibration
/// gave one); board, models and rectangles left to the caller. InputError naming `where` (the
/// profile's file, or "--device ID") when the camera or the camera–IMU calibration is missing,
/// with the verb that makes it.
NonContactSetup device_setup(const store::DeviceProfile& device, const std::filesystem::path& where);

}  // namespace antpose::measure
