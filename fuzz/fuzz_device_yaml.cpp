// A device profile (store/device_profile.hpp) and an IMU calibration file (imu/imu_calibration.hpp).
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/store/device_profile.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const std::string text(fuzz::view(data, size));
  fuzz::expect_clean([&] { store::parse_device_profile(text, "device.yaml"); });
  fuzz::expect_clean([&] { imu::parse_imu_calibration(text, "device.yaml"); });
  return 0;
}
