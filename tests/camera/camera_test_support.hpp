// Reference data of ../shared/data/camera for the camera tests: stored corners and the
// reference values of reference.yaml.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "antpose/camera/calibrate_camera.hpp"
#include "antpose/io/csv.hpp"
#include "support/test_support.hpp"

namespace antpose::camera::test_data {

/// Views from corners.csv (image, id, u, v, x, y, z), one per image in file order.
inline std::vector<CalibrationView> read_corner_views(const std::filesystem::path& file) {
  const io::CsvText csv = io::read_csv(file);
  const std::size_t ci = csv.column("image"), cu = csv.column("u_px"), cv = csv.column("v_px"),
                    cx = csv.column("x_m"), cy = csv.column("y_m"), cz = csv.column("z_m");
  std::vector<CalibrationView> views;
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    const auto& row = csv.rows[r];
    if (views.empty() || views.back().name != row[ci]) views.push_back({row[ci], {}, {}});
    auto num = [&](std::size_t c) { return io::parse_number(row[c], file, csv.lines[r], csv.header[c]); };
    views.back().image_points.emplace_back(num(cu), num(cv));
    views.back().object_points.emplace_back(num(cx), num(cy), num(cz));
  }
  return views;
}

/// One calibration block of reference.yaml (published, measured_default, ...).
struct Reference {
  double fx, fy, cx, cy, rms;
  std::vector<double> distortion;
  YAML::Node node;
};

inline Reference reference(const std::string& set, const std::string& block) {
  const YAML::Node root = YAML::LoadFile(test::shared_path("data/camera/" + set + "/reference.yaml").string());
  const YAML::Node b = root[block];
  Reference r{b["fx"].as<double>(), b["fy"].as<double>(), b["cx"].as<double>(), b["cy"].as<double>(), 0.0, {}, b};
  r.rms = b["rms_px"] ? b["rms_px"].as<double>() : b["avg_reprojection_error_px"].as<double>();
  r.distortion = b["distortion"].as<std::vector<double>>();
  return r;
}

}  // namespace antpose::camera::test_data
