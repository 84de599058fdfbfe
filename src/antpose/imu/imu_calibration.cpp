#include "antpose/imu/imu_calibration.hpp"

#include <cmath>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose::imu {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "antpose-device";

std::size_t line_of(const YAML::Node& node) {
  return node.Mark().is_null() ? 0 : static_cast<std::size_t>(node.Mark().line) + 1;
}

std::string show(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return fmt::format("a list of {}", node.size());
  if (node.IsMap()) return "a map";
  return "empty";
}

double number(const YAML::Node& node, const fs::path& file, const std::string& key) {
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, line_of(node), fmt::format("{}: {} is not a number", key, show(node)));
  }
  if (!std::isfinite(v)) throw InputError(file, line_of(node), fmt::format("{}: {} is not a finite number", key, show(node)));
  return v;
}

Vec3 vec3(const YAML::Node& node, const fs::path& file, const std::string& key) {
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(file, line_of(node), fmt::format("{} is {}, expected a list of 3 numbers [x, y, z]", key, show(node)));
  Vec3 v;
  for (std::size_t k = 0; k < 3; ++k) v[static_cast<Eigen::Index>(k)] = number(node[k], file, fmt::format("{}[{}]", key, k));
  return v;
}

Mat3 mat3(const YAML::Node& node, const fs::path& file, const std::string& key) {
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(file, line_of(node),
                     fmt::format("{} is {}, expected 3 rows of 3 numbers [[..], [..], [..]]", key, show(node)));
  Mat3 M;
  for (std::size_t r = 0; r < 3; ++r)
    M.row(static_cast<Eigen::Index>(r)) = vec3(node[r], file, fmt::format("{}[{}]", key, r)).transpose();
  return M;
}

const YAML::Node section(const YAML::Node& parent, const char* key, const fs::path& file, const std::string& path) {
  const YAML::Node node = parent[key];
  if (node && !node.IsMap())
    throw InputError(file, line_of(node), fmt::format("'{}' is {}, expected a map", path, show(node)));
  return node;
}

YAML::Node flow_vector(const Vec3& v) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (int k = 0; k < 3; ++k) n.push_back(io::format_number(v[k]));
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

}  // namespace

ImuCalibration parse_imu_calibration(const std::string& text, const fs::path& file) {
  ImuCalibration c;
  try {
    c.document = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.is_null() ? 0 : static_cast<std::size_t>(e.mark.line) + 1, "not valid YAML: " + e.msg);
  }
  const YAML::Node& d = c.document;
  if (!d.IsMap()) throw InputError(file, "expected a YAML map with 'format: antpose-device' (an IMU calibration file)");
  if (!d["format"]) throw InputError(file, "no 'format' key: not an IMU calibration file (expected 'format: antpose-device')");
  if (!d["format"].IsScalar() || d["format"].Scalar() != kFormatName)
    throw InputError(file, line_of(d["format"]), fmt::format("format is {}, expected '{}'", show(d["format"]), kFormatName));
  if (!d["version"]) throw InputError(file, "no 'version' key (expected 'version: 1')");
  int version = 0;
  try {
    version = d["version"].as<int>();
  } catch (const YAML::Exception&) {
    throw InputError(file, line_of(d["version"]), fmt::format("version is {}, expected an integer", show(d["version"])));
  }
  if (version < 1 || version > ImuCalibration::kFormatVersion)
    throw InputError(file, line_of(d["version"]),
                     fmt::format("format version {} is not supported; this antpose reads version 1 to {}", version,
                                 ImuCalibration::kFormatVersion));
  if (const auto dev = section(d, "device", file, "device")) {
    if (dev["model"]) c.device_model = dev["model"].as<std::string>();
    if (dev["id"]) c.device_id = dev["id"].as<std::string>();
  }
  const auto imu = section(d, "imu", file, "imu");
  if (!imu) throw InputError(file, "no 'imu' section (expected imu: {magnetometer: ..., accelerometer: ..., gyroscope: ...})");

  if (const auto mag = section(imu, "magnetometer", file, "imu.magnetometer")) {
    if (mag["hard_iron_uT"]) {
      c.mag_hard_iron_uT = vec3(mag["hard_iron_uT"], file, "imu.magnetometer.hard_iron_uT");
      if (c.mag_hard_iron_uT.norm() > 5000.0)
        throw InputError(file, line_of(mag["hard_iron_uT"]),
                         fmt::format("imu.magnetometer.hard_iron_uT has magnitude {:.0f} µT; expected µT (below 5000): "
                                     "was it written in nT?",
                                     c.mag_hard_iron_uT.norm()));
    }
    if (mag["soft_iron"]) {
      c.mag_soft_iron = mat3(mag["soft_iron"], file, "imu.magnetometer.soft_iron");
      const double det = c.mag_soft_iron.determinant();
      if (!(det > 0.1 && det < 10.0))
        throw InputError(file, line_of(mag["soft_iron"]),
                         fmt::format("imu.magnetometer.soft_iron has determinant {:.3g}; expected a correction close "
                                     "to the identity (determinant between 0.1 and 10)",
                                     det));
    }
  }
  if (const auto acc = section(imu, "accelerometer", file, "imu.accelerometer")) {
    if (acc["bias_m_s2"]) c.acc_bias = vec3(acc["bias_m_s2"], file, "imu.accelerometer.bias_m_s2");
    if (acc["scale"]) {
      c.acc_scale = vec3(acc["scale"], file, "imu.accelerometer.scale");
      if (c.acc_scale.minCoeff() < 0.5 || c.acc_scale.maxCoeff() > 2.0)
        throw InputError(file, line_of(acc["scale"]),
                         fmt::format("imu.accelerometer.scale = [{}], expected factors between 0.5 and 2",
                                     fmt::join(c.acc_scale, ", ")));
    }
  }
  if (const auto gyr = section(imu, "gyroscope", file, "imu.gyroscope")) {
    if (gyr["bias_rad_s"]) c.gyro_bias = vec3(gyr["bias_rad_s"], file, "imu.gyroscope.bias_rad_s");
  }
  return c;
}

ImuCalibration read_imu_calibration(const fs::path& file) { return parse_imu_calibration(io::read_text(file), file); }

std::string format_imu_calibration(const ImuCalibration& c) {
  YAML::Node d = c.document.IsMap() ? YAML::Clone(c.document) : YAML::Node(YAML::NodeType::Map);
  d["format"] = kFormatName;
  d["version"] = ImuCalibration::kFormatVersion;
  if (!c.device_model.empty()) d["device"]["model"] = c.device_model;
  if (!c.device_id.empty()) d["device"]["id"] = c.device_id;
  YAML::Node imu = d["imu"];
  imu["magnetometer"]["hard_iron_uT"] = flow_vector(c.mag_hard_iron_uT);
  YAML::Node soft(YAML::NodeType::Sequence);
  for (int r = 0; r < 3; ++r) soft.push_back(flow_vector(c.mag_soft_iron.row(r).transpose()));
  imu["magnetometer"]["soft_iron"] = soft;
  imu["accelerometer"]["bias_m_s2"] = flow_vector(c.acc_bias);
  imu["accelerometer"]["scale"] = flow_vector(c.acc_scale);
  imu["gyroscope"]["bias_rad_s"] = flow_vector(c.gyro_bias);
  YAML::Emitter out;
  out << d;
  return std::string(out.c_str()) + "\n";
}

void write_imu_calibration(const ImuCalibration& calibration, const fs::path& file) {
  io::write_text_atomic(file, format_imu_calibration(calibration));
}

void apply(const ImuCalibration& c, Capture& capture) {
  auto correct = [&](std::string_view name, auto&& f) {
    auto it = capture.streams.find(std::string(name));
    if (it == capture.streams.end() || !it->second.has_xyz()) return;
    Stream& s = it->second;
    for (Eigen::Index i = 0; i < s.values.rows(); ++i) {
      const Vec3 v = s.values.row(i).head<3>().transpose();
      s.values.row(i).head<3>() = f(v).transpose();
    }
  };
  correct(streams::kMagnetometer, [&](const Vec3& m) -> Vec3 { return c.mag_soft_iron * (m - c.mag_hard_iron_uT); });
  correct(streams::kAccelerometer, [&](const Vec3& a) -> Vec3 { return c.acc_scale.cwiseProduct(a - c.acc_bias); });
  correct(streams::kGyroscope, [&](const Vec3& w) -> Vec3 { return w - c.gyro_bias; });
}

}  // namespace antpose::imu
