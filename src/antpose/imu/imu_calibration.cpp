#include "antpose/imu/imu_calibration.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose::imu {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "antpose-device";

using io::line_of;
using io::show;

double number(const YAML::Node& node, const fs::path& file, const std::string& key) {
  return io::yaml_number(node, file, key);
}
Vec3 vec3(const YAML::Node& node, const fs::path& file, const std::string& key) { return io::yaml_vec3(node, file, key); }
Mat3 mat3(const YAML::Node& node, const fs::path& file, const std::string& key) { return io::yaml_mat3(node, file, key); }
YAML::Node section(const YAML::Node& parent, const char* key, const fs::path& file, const std::string& path) {
  return io::yaml_section(parent, key, file, path);
}

Vec3 scale(const YAML::Node& node, const fs::path& file, const std::string& key) {
  const Vec3 k = vec3(node, file, key);
  if (k.minCoeff() < 0.5 || k.maxCoeff() > 2.0)
    throw InputError(file, line_of(node), fmt::format("{} = [{}], expected factors between 0.5 and 2", key, fmt::join(k, ", ")));
  return k;
}

// A misalignment matrix has a unit diagonal and small off-diagonal entries (≈ angles in rad);
// 0.2 rad (11°) is far beyond any real sensor's non-orthogonality.
Mat3 misalignment(const YAML::Node& node, const fs::path& file, const std::string& key) {
  const Mat3 T = mat3(node, file, key);
  const Mat3 off = T - Mat3::Identity();
  if ((T.diagonal() - Vec3::Ones()).cwiseAbs().maxCoeff() > 1e-9 || off.cwiseAbs().maxCoeff() > 0.2)
    throw InputError(file, line_of(node),
                     fmt::format("{} has diagonal [{}] and largest off-diagonal {:.3g}; expected a unit diagonal and "
                                 "off-diagonal entries below 0.2 (small angles in rad)",
                                 key, fmt::join(T.diagonal(), ", "), off.cwiseAbs().maxCoeff()));
  return T;
}

// A 1σ per axis: each entry from 0 to `limit`, in `unit`.
Vec3 sigma_per_axis(const YAML::Node& node, const fs::path& file, const std::string& key, const char* unit,
                    double limit) {
  const Vec3 sigma = vec3(node, file, key);
  if (!(sigma.minCoeff() >= 0.0 && sigma.maxCoeff() < limit))
    throw InputError(file, line_of(node),
                     fmt::format("{} is ({:.3g}, {:.3g}, {:.3g}); expected 1σ per axis in {}, each from 0 to {:g}", key,
                                 sigma.x(), sigma.y(), sigma.z(), unit, limit));
  return sigma;
}

YAML::Node flow_vector(const Vec3& v) { return io::yaml_flow_vector(v); }
YAML::Node flow_matrix(const Mat3& M) { return io::yaml_flow_matrix(M); }

}  // namespace

ImuCalibration parse_imu_calibration(const std::string& text, const fs::path& file) {
  ImuCalibration c;
  c.document = io::load_yaml(text, file);
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
    if (dev["model"]) c.device_model = io::yaml_string(dev["model"], file, "device.model");
    if (dev["id"]) c.device_id = io::yaml_string(dev["id"], file, "device.id");
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
    if (mag["field_uT"]) c.mag_field_uT = number(mag["field_uT"], file, "imu.magnetometer.field_uT");
    if (mag["residual_rel"]) c.mag_residual_rel = number(mag["residual_rel"], file, "imu.magnetometer.residual_rel");
    if (mag["soft_iron"]) {
      c.mag_soft_iron = mat3(mag["soft_iron"], file, "imu.magnetometer.soft_iron");
      const double det = c.mag_soft_iron.determinant();
      if (!(det > 0.1 && det < 10.0))
        throw InputError(file, line_of(mag["soft_iron"]),
                         fmt::format("imu.magnetometer.soft_iron has determinant {:.3g}; expected a correction close "
                                     "to the identity (determinant between 0.1 and 10)",
                                     det));
    }
    if (mag["alignment"]) {
      c.mag_alignment = mat3(mag["alignment"], file, "imu.magnetometer.alignment");
      const double off = (c.mag_alignment * c.mag_alignment.transpose() - Mat3::Identity()).norm();
      const double angle = std::acos(std::clamp((c.mag_alignment.trace() - 1.0) / 2.0, -1.0, 1.0));
      if (off > 1e-3 || c.mag_alignment.determinant() < 0.0 || angle > deg2rad(10.0))
        throw InputError(
            file, line_of(mag["alignment"]),
            fmt::format("imu.magnetometer.alignment is not a small rotation (RᵀR − I off by {:.2g}, "
                        "determinant {:.3f}, angle {:.1f}°); expected a rotation within 10° of the identity",
                        off, c.mag_alignment.determinant(), rad2deg(angle)));
      // Rounded entries (a file written by hand): the nearest rotation.
      c.mag_alignment = nearest_rotation(c.mag_alignment);
    }
    if (mag["hard_iron_sigma_uT"])
      c.mag_hard_iron_sigma_uT =
          sigma_per_axis(mag["hard_iron_sigma_uT"], file, "imu.magnetometer.hard_iron_sigma_uT", "µT", 100.0);
    if (mag["soft_iron_sigma"]) {
      const Mat3 sigma = mat3(mag["soft_iron_sigma"], file, "imu.magnetometer.soft_iron_sigma");
      if (!(sigma.minCoeff() >= 0.0 && sigma.maxCoeff() < 1.0) || !sigma.isApprox(sigma.transpose(), 1e-9))
        throw InputError(file, line_of(mag["soft_iron_sigma"]),
                         fmt::format("imu.magnetometer.soft_iron_sigma has entries from {:.3g} to {:.3g}; expected "
                                     "a symmetric 3×3 of 1σ per soft-iron entry, each from 0 to 1",
                                     sigma.minCoeff(), sigma.maxCoeff()));
      c.mag_soft_iron_sigma = sigma;
    }
    if (mag["alignment_sigma_deg"])
      c.mag_alignment_sigma_rad =
          deg2rad(1.0) *
          sigma_per_axis(mag["alignment_sigma_deg"], file, "imu.magnetometer.alignment_sigma_deg", "degrees", 10.0);
  }
  if (const auto acc = section(imu, "accelerometer", file, "imu.accelerometer")) {
    if (acc["bias_m_s2"]) c.acc_bias = vec3(acc["bias_m_s2"], file, "imu.accelerometer.bias_m_s2");
    if (acc["scale"]) c.acc_scale = scale(acc["scale"], file, "imu.accelerometer.scale");
    if (acc["misalignment"]) c.acc_misalignment = misalignment(acc["misalignment"], file, "imu.accelerometer.misalignment");
    if (acc["residual_rms_m_s2"])
      c.acc_residual_rms_m_s2 = number(acc["residual_rms_m_s2"], file, "imu.accelerometer.residual_rms_m_s2");
  }
  if (const auto gyr = section(imu, "gyroscope", file, "imu.gyroscope")) {
    if (gyr["bias_rad_s"]) c.gyro_bias = vec3(gyr["bias_rad_s"], file, "imu.gyroscope.bias_rad_s");
    if (gyr["scale"]) c.gyro_scale = scale(gyr["scale"], file, "imu.gyroscope.scale");
    if (gyr["misalignment"]) c.gyro_misalignment = misalignment(gyr["misalignment"], file, "imu.gyroscope.misalignment");
    if (gyr["residual_rms_deg"])
      c.gyro_residual_rms_deg = number(gyr["residual_rms_deg"], file, "imu.gyroscope.residual_rms_deg");
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
  // A sensor's section is written when it was in the file or holds a calibration, so that a
  // file calibrating only some sensors does not claim the others (readers such as the contact
  // measurement test for the section's presence).
  YAML::Node old_imu;
  if (c.document.IsMap()) {
    const YAML::Node n = c.document["imu"];
    if (n && n.IsMap()) old_imu = n;
  }
  auto keep = [&](const char* key, bool calibrated) { return calibrated || (old_imu.IsMap() && old_imu[key]); };
  if (keep("magnetometer", !c.mag_hard_iron_uT.isZero() || c.mag_soft_iron != Mat3::Identity() ||
                               c.mag_alignment != Mat3::Identity() || c.mag_field_uT)) {
    imu["magnetometer"]["hard_iron_uT"] = flow_vector(c.mag_hard_iron_uT);
    imu["magnetometer"]["soft_iron"] = flow_matrix(c.mag_soft_iron);
    if (c.mag_alignment != Mat3::Identity()) imu["magnetometer"]["alignment"] = flow_matrix(c.mag_alignment);
    // σ keys are written with their fit and dropped without it, so that a refit never keeps an old σ.
    const auto sigma = [&](const char* key, const auto& value, const auto& flow) {
      if (value)
        imu["magnetometer"][key] = flow(*value);
      else
        imu["magnetometer"].remove(key);
    };
    sigma("hard_iron_sigma_uT", c.mag_hard_iron_sigma_uT, flow_vector);
    sigma("soft_iron_sigma", c.mag_soft_iron_sigma, flow_matrix);
    sigma("alignment_sigma_deg",
          c.mag_alignment_sigma_rad ? std::optional<Vec3>(rad2deg(1.0) * *c.mag_alignment_sigma_rad) : std::nullopt,
          flow_vector);
    if (c.mag_field_uT) imu["magnetometer"]["field_uT"] = io::format_number(*c.mag_field_uT);
    if (c.mag_residual_rel) imu["magnetometer"]["residual_rel"] = io::format_number(*c.mag_residual_rel);
  }
  if (keep("accelerometer", !c.acc_bias.isZero() || c.acc_scale != Vec3::Ones() || c.acc_misalignment != Mat3::Identity() ||
                                c.acc_residual_rms_m_s2)) {
    imu["accelerometer"]["bias_m_s2"] = flow_vector(c.acc_bias);
    imu["accelerometer"]["scale"] = flow_vector(c.acc_scale);
    imu["accelerometer"]["misalignment"] = flow_matrix(c.acc_misalignment);
    if (c.acc_residual_rms_m_s2) imu["accelerometer"]["residual_rms_m_s2"] = io::format_number(*c.acc_residual_rms_m_s2);
  }
  if (keep("gyroscope", !c.gyro_bias.isZero() || c.gyro_scale != Vec3::Ones() || c.gyro_misalignment != Mat3::Identity() ||
                            c.gyro_residual_rms_deg)) {
    imu["gyroscope"]["bias_rad_s"] = flow_vector(c.gyro_bias);
    imu["gyroscope"]["scale"] = flow_vector(c.gyro_scale);
    imu["gyroscope"]["misalignment"] = flow_matrix(c.gyro_misalignment);
    if (c.gyro_residual_rms_deg) imu["gyroscope"]["residual_rms_deg"] = io::format_number(*c.gyro_residual_rms_deg);
  }
  if (!imu.IsMap() || imu.size() == 0) d["imu"] = YAML::Node(YAML::NodeType::Map);
  return io::yaml_document(d);
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
  correct(streams::kMagnetometer, [&](const Vec3& m) -> Vec3 { return c.correct_mag(m); });
  correct(streams::kAccelerometer, [&](const Vec3& a) -> Vec3 { return c.correct_acc(a); });
  correct(streams::kGyroscope, [&](const Vec3& w) -> Vec3 { return c.correct_gyro(w); });
}

}  // namespace antpose::imu
