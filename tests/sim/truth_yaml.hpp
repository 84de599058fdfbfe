// Shared by the simulator tests: the values of a simulated capture's truth files
// (truth/device.yaml, truth/scene.yaml).
#pragma once

#include <cstddef>

#include <yaml-cpp/yaml.h>

#include "antpose/camera/camera_model.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose::test {

/// A rotation written as three rows, and a vector: io's readers, which name the truth file's
/// value in their message should the simulator write a bad one.
inline Mat3 mat(const YAML::Node& rows) { return io::yaml_mat3(rows, "truth", "rotation"); }
inline Vec3 vec(const YAML::Node& n) { return io::yaml_vec3(n, "truth", "vector"); }

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
