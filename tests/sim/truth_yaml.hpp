// Shared by the simulator tests: the values of a simulated capture's truth files
// (truth/device.yaml, truth/scene.yaml), read without the library's checks, which these files
// need not pass through.
#pragma once

#include <cstddef>

#include <yaml-cpp/yaml.h>

#include "antpose/camera/camera_model.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose::test {

/// A rotation written as three rows.
inline Mat3 mat(const YAML::Node& rows) {
  Mat3 M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = rows[i][j].as<double>();
  return M;
}

inline Vec3 vec(const YAML::Node& n) { return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()}; }

/// The camera of truth/device.yaml.
inline camera::CameraIntrinsics intrinsics_of(const YAML::Node& device) {
  const auto c = device["camera"];
  camera::CameraIntrinsics K;
  K.width = c["width_px"].as<int>(), K.height = c["height_px"].as<int>();
  K.fx = c["fx_px"].as<double>(), K.fy = c["fy_px"].as<double>(), K.cx = c["cx_px"].as<double>(),
  K.cy = c["cy_px"].as<double>();
  for (std::size_t i = 0; i < 5; ++i) K.distortion[i] = c["distortion"][i].as<double>();
  return K;
}

}  // namespace antpose::test
