#include "antpose/store/device_profile.hpp"

#include <cmath>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose::store {
namespace fs = std::filesystem;
using io::line_of;
using io::show;

namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

// A photo's capture-clock timestamp and the IMU samples share one clock (capture format); what
// remains is the camera pipeline's latency, tens of milliseconds on phones. An offset of a second
// or more means the two clocks were never aligned (wrong epoch, milliseconds read as seconds),
// which no camera–IMU calibration can repair: the capture must be converted again.
constexpr double kMaxTimeOffsetS = 1.0;
// Orthonormality tolerance of R_device_camera: the file keeps round-trip digits, so a real
// rotation is orthonormal to ~1e-15; 1e-6 leaves room for hand-typed 7-digit values.
constexpr double kRotationTolerance = 1e-6;

double non_negative(const YAML::Node& node, const fs::path& file, const std::string& key) {
  const double v = io::yaml_number(node, file, key);
  if (v < 0) throw InputError(file, line_of(node), fmt::format("{} = {}, expected a value ≥ 0", key, v));
  return v;
}

int positive_int(const YAML::Node& node, const fs::path& file, const std::string& key) {
  const long long v = io::yaml_integer(node, file, key);
  if (v <= 0 || v > 100000)
    throw InputError(file, line_of(node), fmt::format("{} = {}, expected a positive image size in pixels", key, v));
  return static_cast<int>(v);
}

CameraCalibrationInfo parse_camera(const YAML::Node& cam, const fs::path& file) {
  CameraCalibrationInfo info;
  camera::CameraIntrinsics& k = info.intrinsics;
  k.width = positive_int(io::yaml_required(cam, "width_px", file, "camera"), file, "camera.width_px");
  k.height = positive_int(io::yaml_required(cam, "height_px", file, "camera"), file, "camera.height_px");
  k.fx = io::yaml_number(io::yaml_required(cam, "fx_px", file, "camera"), file, "camera.fx_px");
  k.fy = io::yaml_number(io::yaml_required(cam, "fy_px", file, "camera"), file, "camera.fy_px");
  k.cx = io::yaml_number(io::yaml_required(cam, "cx_px", file, "camera"), file, "camera.cx_px");
  k.cy = io::yaml_number(io::yaml_required(cam, "cy_px", file, "camera"), file, "camera.cy_px");
  if (const YAML::Node d = cam["distortion"]) {
    if (!d.IsSequence() || d.size() != 5)
      throw InputError(file, line_of(d),
                       fmt::format("camera.distortion is {}, expected a list of 5 numbers [k1, k2, p1, p2, k3] (OpenCV "
                                   "order)",
                                   show(d)));
    for (std::size_t i = 0; i < 5; ++i)
      k.distortion[i] = io::yaml_number(d[i], file, fmt::format("camera.distortion[{}]", i));
  }
  if (cam["rms_px"]) info.rms_px = non_negative(cam["rms_px"], file, "camera.rms_px");
  if (const YAML::Node s = cam["principal_point_sigma_px"]) {
    if (!s.IsSequence() || s.size() != 2)
      throw InputError(file, line_of(s),
                       fmt::format("camera.principal_point_sigma_px is {}, expected [sigma_cx, sigma_cy] in px", show(s)));
    info.principal_point_sigma_px = Vec2(non_negative(s[0], file, "camera.principal_point_sigma_px[0]"),
                                         non_negative(s[1], file, "camera.principal_point_sigma_px[1]"));
  }
  if (const auto reason = k.invalid_reason())
    throw InputError(file, line_of(cam),
                     fmt::format("camera intrinsics are {}; expected a positive size and focal length and the principal "
                                 "point inside the image",
                                 *reason));
  return info;
}

CameraImuCalibration parse_camera_imu(const YAML::Node& ci, const fs::path& file) {
  CameraImuCalibration c;
  if (const YAML::Node r = ci["R_device_camera"]) {
    c.R_device_camera = io::yaml_mat3(r, file, "camera_imu.R_device_camera");
    const double ortho = (c.R_device_camera.transpose() * c.R_device_camera - Mat3::Identity()).cwiseAbs().maxCoeff();
    const double det = c.R_device_camera.determinant();
    if (ortho > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance)
      throw InputError(file, line_of(r),
                       fmt::format("camera_imu.R_device_camera is not a rotation: max |RᵀR − I| = {:.3g}, det = {:.6g}; "
                                   "expected an orthonormal matrix (within {:g}) with determinant +1{}",
                                   ortho, det, kRotationTolerance,
                                   det < 0 ? " (a negative determinant is a reflection: an axis sign is flipped)" : ""));
  }
  if (const YAML::Node s = ci["rotation_sigma_deg"]) {
    const Vec3 sigma = io::yaml_vec3(s, file, "camera_imu.rotation_sigma_deg");
    if (sigma.minCoeff() < 0)
      throw InputError(file, line_of(s),
                       fmt::format("camera_imu.rotation_sigma_deg = [{}], expected standard deviations ≥ 0",
                                   fmt::join(sigma, ", ")));
    c.rotation_sigma_rad = sigma * kRadPerDeg;
  }
  if (const YAML::Node t = ci["time_offset_s"]) {
    c.time_offset_s = io::yaml_number(t, file, "camera_imu.time_offset_s");
    if (!(std::abs(c.time_offset_s) < kMaxTimeOffsetS))
      throw InputError(file, line_of(t),
                       fmt::format("camera_imu.time_offset_s = {} s, expected |offset| < {:g} s: photos and IMU share "
                                   "the capture clock, so only the camera latency (tens of ms) remains; a larger "
                                   "offset means the clocks were not aligned (re-convert the capture)",
                                   c.time_offset_s, kMaxTimeOffsetS));
  }
  if (ci["time_offset_sigma_s"]) c.time_offset_sigma_s = non_negative(ci["time_offset_sigma_s"], file, "camera_imu.time_offset_sigma_s");
  if (ci["method"]) c.method = io::yaml_string(ci["method"], file, "camera_imu.method");
  return c;
}

}  // namespace

DeviceProfile parse_device_profile(const std::string& text, const fs::path& file) {
  const YAML::Node d = io::load_yaml(text, file);
  // parse_imu_calibration checks format/version/device/imu; a profile without an `imu` section
  // (camera only) is parsed with an empty one appended at the end, which leaves every line
  // number of the original text unchanged.
  const bool has_imu = d.IsMap() && d["imu"];
  DeviceProfile p;
  std::string imu_text = text;
  if (!has_imu && d.IsMap()) {
    if (d.Style() == YAML::EmitterStyle::Flow) {  // "{format: ..., camera: {...}}": no line to keep
      YAML::Node with_imu = YAML::Clone(d);
      with_imu["imu"] = YAML::Node(YAML::NodeType::Map);
      YAML::Emitter out;
      out << with_imu;
      imu_text = out.c_str();
    } else {
      imu_text += "\nimu: {}\n";
    }
  }
  p.imu = imu::parse_imu_calibration(imu_text, file);
  p.has_imu = has_imu;
  if (!has_imu) p.imu.document.remove("imu");
  p.id = p.imu.device_id;
  p.model = p.imu.device_model;
  if (const auto cam = io::yaml_section(d, "camera", file, "camera")) p.camera = parse_camera(cam, file);
  if (const auto ci = io::yaml_section(d, "camera_imu", file, "camera_imu")) p.camera_imu = parse_camera_imu(ci, file);
  return p;
}

DeviceProfile read_device_profile(const fs::path& file) { return parse_device_profile(io::read_text(file), file); }

std::string format_device_profile(const DeviceProfile& profile) {
  imu::ImuCalibration calibration = profile.imu;
  calibration.device_id = profile.id;
  calibration.device_model = profile.model;
  // The IMU writer keeps every unknown key of the document (also those inside camera sections).
  YAML::Node d = YAML::Load(imu::format_imu_calibration(calibration));
  if (!profile.has_imu && d["imu"] && d["imu"].IsMap() && d["imu"].size() == 0) d.remove("imu");
  if (profile.camera) {
    const auto& k = profile.camera->intrinsics;
    YAML::Node cam = d["camera"];
    if (!cam.IsMap()) cam = YAML::Node(YAML::NodeType::Map);
    cam["width_px"] = k.width;
    cam["height_px"] = k.height;
    cam["fx_px"] = io::format_number(k.fx);
    cam["fy_px"] = io::format_number(k.fy);
    cam["cx_px"] = io::format_number(k.cx);
    cam["cy_px"] = io::format_number(k.cy);
    YAML::Node dist(YAML::NodeType::Sequence);
    for (double v : k.distortion) dist.push_back(io::format_number(v));
    dist.SetStyle(YAML::EmitterStyle::Flow);
    cam["distortion"] = dist;
    if (profile.camera->rms_px) cam["rms_px"] = io::format_number(*profile.camera->rms_px);
    else cam.remove("rms_px");
    if (const auto& s = profile.camera->principal_point_sigma_px) {
      YAML::Node n(YAML::NodeType::Sequence);
      n.push_back(io::format_number(s->x()));
      n.push_back(io::format_number(s->y()));
      n.SetStyle(YAML::EmitterStyle::Flow);
      cam["principal_point_sigma_px"] = n;
    } else {
      cam.remove("principal_point_sigma_px");
    }
    d["camera"] = cam;
  } else {
    d.remove("camera");
  }
  if (profile.camera_imu) {
    const auto& c = *profile.camera_imu;
    YAML::Node ci = d["camera_imu"];
    if (!ci.IsMap()) ci = YAML::Node(YAML::NodeType::Map);
    ci["R_device_camera"] = io::yaml_flow_matrix(c.R_device_camera);
    if (c.rotation_sigma_rad) ci["rotation_sigma_deg"] = io::yaml_flow_vector(*c.rotation_sigma_rad / kRadPerDeg);
    else ci.remove("rotation_sigma_deg");
    ci["time_offset_s"] = io::format_number(c.time_offset_s);
    if (c.time_offset_sigma_s) ci["time_offset_sigma_s"] = io::format_number(*c.time_offset_sigma_s);
    else ci.remove("time_offset_sigma_s");
    if (!c.method.empty()) ci["method"] = c.method;
    else ci.remove("method");
    d["camera_imu"] = ci;
  } else {
    d.remove("camera_imu");
  }
  return io::yaml_document(d);
}

void write_device_profile(const DeviceProfile& profile, const fs::path& file) {
  io::write_text_atomic(file, format_device_profile(profile));
}

}  // namespace antpose::store
