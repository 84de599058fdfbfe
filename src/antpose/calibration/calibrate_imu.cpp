#include "antpose/calibration/calibrate_imu.hpp"

#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "antpose/io/text_file.hpp"
#include "antpose/geomag/earth_model.hpp"

namespace antpose::calibration {
namespace fs = std::filesystem;

Method parse_method(const std::string& text) {
  if (text == "thesis") return Method::kThesis;
  if (text == "full") return Method::kFull;
  throw InputError({}, fmt::format("'{}' is not an IMU error model; expected 'thesis' or 'full'", text));
}

void parse_sensors(const std::string& list, CalibrateImuOptions& o) {
  o.accelerometer = o.gyroscope = o.magnetometer = false;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "acc" || item == "accelerometer") o.accelerometer = true;
    else if (item == "gyro" || item == "gyroscope") o.gyroscope = true;
    else if (item == "mag" || item == "magnetometer") o.magnetometer = true;
    else
      throw InputError({}, fmt::format("--sensors: '{}' is not a sensor; expected a comma-separated list of acc, gyro, "
                                       "mag (got '{}')",
                                       item, list));
  }
  if (!o.accelerometer && !o.gyroscope && !o.magnetometer)
    throw InputError({}, fmt::format("--sensors: '{}' selects no sensor; expected e.g. acc,gyro,mag", list));
}

CalibrateImuResult calibrate_imu(const Capture& capture, const CalibrateImuOptions& o, Diagnostics& diagnostics,
                                 const fs::path& source, const imu::ImuCalibration& base) {
  CalibrateImuResult r;
  r.calibration = base;
  if (r.calibration.device_model.empty()) r.calibration.device_model = capture.device_model;
  if (r.calibration.device_id.empty()) r.calibration.device_id = capture.device_id;
  r.gravity = o.gravity      ? *o.gravity
              : capture.site ? geomag::normal_gravity(capture.site->lat_deg, capture.site->alt_m)
                             : 9.80665;
  const std::string src = source.string();
  auto& cal = r.calibration;

  if (o.accelerometer || o.gyroscope) {
    capture.require(streams::kAccelerometer);
    if (o.gyroscope) capture.require(streams::kGyroscope);
    r.frames = collect_static_frames(capture, o.frames);
    std::vector<Vec3> means;
    for (const auto& f : r.frames) means.push_back(f.acc_mean);
    r.accelerometer_thesis = fit_accelerometer_thesis(means, r.gravity, src);
    r.accelerometer = o.method == Method::kFull ? fit_accelerometer_full(means, r.gravity, *r.accelerometer_thesis, src)
                                                : *r.accelerometer_thesis;
    if (r.accelerometer->rms_after > 0.05)
      diagnostics.warn(source, 0, fmt::format("accelerometer residual RMS {:.3f} m/s² is large (> 0.05): some static "
                                              "frames may not have been still",
                                              r.accelerometer->rms_after));
    if (o.accelerometer) {
      cal.acc_bias = r.accelerometer->bias;
      cal.acc_scale = r.accelerometer->scale;
      cal.acc_misalignment = r.accelerometer->misalignment;
      cal.acc_residual_rms_m_s2 = r.accelerometer->rms_after;
      r.wrote_accelerometer = true;
    }
  }
  if (o.gyroscope) {
    const Stream& gyro = capture.require(streams::kGyroscope);
    if (o.method == Method::kFull) {
      r.gyroscope = fit_gyroscope(gyro, r.frames, *r.accelerometer, o.gyroscope_options, src);
    } else {
      // Thesis: bias only; the fit still runs with T = I, k = 1 for the residual figures.
      GyroscopeOptions go = o.gyroscope_options;
      go.fit_misalignment = false;
      r.gyroscope = fit_gyroscope(gyro, r.frames, *r.accelerometer, go, src);
      r.gyroscope->scale = Vec3::Ones();
      r.gyroscope->rms_after = r.gyroscope->rms_bias_only;
      r.gyroscope->sigma.setZero();
    }
    cal.gyro_bias = r.gyroscope->bias;
    cal.gyro_scale = r.gyroscope->scale;
    cal.gyro_misalignment = r.gyroscope->misalignment;
    cal.gyro_residual_rms_deg = r.gyroscope->rms_after * 180.0 / M_PI;
    r.wrote_gyroscope = true;
  }
  if (o.magnetometer) {
    const Stream& mag = capture.require(streams::kMagnetometer);
    if (o.method == Method::kFull) {
      r.magnetometer = fit_magnetometer(mag, o.magnetometer_options, diagnostics, source);
      cal.mag_hard_iron_uT = r.magnetometer->hard_iron_uT;
      cal.mag_soft_iron = r.magnetometer->soft_iron;
      cal.mag_field_uT = r.magnetometer->field_uT;
      cal.mag_residual_rel = r.magnetometer->residual_rel;
      cal.mag_hard_iron_sigma_uT = r.magnetometer->hard_iron_sigma_uT;
      cal.mag_soft_iron_sigma = r.magnetometer->soft_iron_sigma;
      cal.mag_alignment = Mat3::Identity();
      cal.mag_alignment_sigma_rad.reset();
      if (!cal.acc_residual_rms_m_s2 || !capture.streams.count(std::string(streams::kAccelerometer))) {
        diagnostics.warn(source, 0,
                         "the magnetometer's axes were not aligned to the accelerometer's (no accelerometer "
                         "calibration yet): calibrate the accelerometer first, then the magnetometer, or the compass "
                         "may be off by tenths of a degree");
      } else {
        // The accelerometer and the field as calibrated so far, then the field's axes turned onto the
        // accelerometer's.
        Capture corrected = capture;
        imu::apply(cal, corrected);
        try {
          r.magnetometer_alignment = fit_magnetometer_alignment(corrected.require(streams::kAccelerometer),
                                                                corrected.require(streams::kMagnetometer), r.gravity,
                                                                o.magnetometer_alignment_options, source);
          cal.mag_alignment = r.magnetometer_alignment->R_calibrated_magnetometer;
          cal.mag_alignment_sigma_rad = r.magnetometer_alignment->sigma_rad;
        } catch (const MeasurementError& e) {
          diagnostics.warn(source, 0,
                           fmt::format("{}; the magnetometer's axes are taken as the accelerometer's", e.what()));
        }
      }
    } else {
      r.hard_iron = imu::estimate_hard_iron(mag, {}, source);
      cal.mag_hard_iron_uT = r.hard_iron->hard_iron_uT;
      cal.mag_soft_iron = Mat3::Identity();
      cal.mag_hard_iron_sigma_uT.reset(), cal.mag_soft_iron_sigma.reset(), cal.mag_alignment_sigma_rad.reset();
      cal.mag_field_uT = r.hard_iron->field_uT;
      cal.mag_residual_rel = r.hard_iron->radius_spread;
    }
    r.wrote_magnetometer = true;
  }
  return r;
}

CalibrateImuResult calibrate_imu_file(const fs::path& capture_path, const fs::path& output, const CalibrateImuOptions& o,
                                      bool force, Diagnostics& diagnostics) {
  // Check the output before the (slower) fits, so a typo costs nothing.
  if (output.empty()) throw InputError(output, "-o: no output file given (expected e.g. -o device.yaml)");
  if (fs::is_directory(output))
    throw InputError(output, "-o: is a folder; expected the path of a device YAML file (e.g. device.yaml)");
  const fs::path parent = output.has_parent_path() ? output.parent_path() : fs::path(".");
  if (!fs::is_directory(parent))
    throw InputError(output, fmt::format("-o: the folder '{}' does not exist; create it first", parent.string()));
  imu::ImuCalibration base;
  const bool existed = fs::exists(output);
  if (existed && !force) {
    try {
      base = imu::read_imu_calibration(output);
    } catch (const InputError& e) {
      throw InputError(output, fmt::format("-o: the existing file is not a valid antpose device calibration ({}); it "
                                           "was not changed. Use --force to replace it",
                                           e.detail()));
    }
  }
  const std::string kept = existed ? fmt::format("; the existing {} was kept unchanged", output.string())
                                   : fmt::format("; {} was not written", output.string());
  CalibrateImuResult result;
  try {
    const Capture capture = read_capture(capture_path, diagnostics);
    if (capture.kind != "imu-calibration")
      diagnostics.warn(capture_path, 0, fmt::format("capture kind is '{}', not 'imu-calibration'", capture.kind));
    result = calibrate_imu(capture, o, diagnostics, capture_path, base);
  } catch (const InputError& e) {
    throw InputError(e.file(), e.line(), e.detail() + kept);
  } catch (const MeasurementError& e) {
    throw MeasurementError(std::string(e.what()) + kept);
  }
  try {
    imu::write_imu_calibration(result.calibration, output);
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    throw InputError(output, fmt::format("-o: cannot write the calibration: {}", e.what()));
  }
  return result;
}

namespace {
std::string vec(const Vec3& v, int digits = 5) {
  return fmt::format("({:.{}f}, {:.{}f}, {:.{}f})", v.x(), digits, v.y(), digits, v.z(), digits);
}
double deg(double rad) { return rad * 180.0 / M_PI; }
}  // namespace

std::string describe(const CalibrateImuResult& r) {
  std::string s;
  if (r.accelerometer) {
    const auto& a = *r.accelerometer;
    s += fmt::format("accelerometer ({} static frames, g = {:.5f} m/s², method {})\n", a.frames, a.gravity, a.method);
    s += fmt::format("  residual RMS(|a| - g)  before {:.4f} m/s²   thesis {:.4f} m/s²   after {:.4f} m/s² (max {:.4f})\n",
                     a.rms_before, r.accelerometer_thesis->rms_after, a.rms_after, a.max_after);
    s += fmt::format("  bias   {} m/s²\n  scale  {}\n", vec(a.bias), vec(a.scale, 6));
    s += fmt::format("  misalignment (upper triangular) t01 {:.4f}°  t02 {:.4f}°  t12 {:.4f}°\n", deg(a.misalignment(0, 1)),
                     deg(a.misalignment(0, 2)), deg(a.misalignment(1, 2)));
    if (!r.wrote_accelerometer) s += "  (used for the gyroscope fit only; not written)\n";
  }
  if (r.gyroscope) {
    const auto& g = *r.gyroscope;
    s += fmt::format("gyroscope ({} moves between static frames)\n", g.transitions);
    s += fmt::format("  residual RMS gravity direction  raw {:.3f}°   bias removed {:.3f}°   after {:.3f}°\n", deg(g.rms_raw),
                     deg(g.rms_bias_only), deg(g.rms_after));
    s += fmt::format("  bias   {} rad/s = {} °/s\n  scale  {}\n", vec(g.bias, 6), vec(g.bias * 180.0 / M_PI, 4),
                     vec(g.scale, 6));
    const Mat3& T = g.misalignment;
    s += fmt::format("  misalignment t01 {:.4f}° t02 {:.4f}° t10 {:.4f}° t12 {:.4f}° t20 {:.4f}° t21 {:.4f}°\n",
                     deg(T(0, 1)), deg(T(0, 2)), deg(T(1, 0)), deg(T(1, 2)), deg(T(2, 0)), deg(T(2, 1)));
  }
  if (r.magnetometer) {
    const auto& m = *r.magnetometer;
    s += fmt::format("magnetometer ({} samples, direction coverage {:.0f}%)\n", m.samples, 100 * m.direction_coverage);
    s += fmt::format("  residual std(|m|)/mean  raw {:.2f}%   hard iron (max+min)/2 {:.2f}%   ellipsoid {:.3f}% "
                     "(RMS {:.3f} µT)\n",
                     100 * m.residual_rel_raw, 100 * m.residual_rel_hard_iron, 100 * m.residual_rel, m.residual_rms_uT);
    s += fmt::format("  hard iron {} µT ((max+min)/2: {} µT)\n", vec(m.hard_iron_uT, 3), vec(m.max_min_hard_iron_uT, 3));
    s += fmt::format("  field strength {:.3f} µT, ellipsoid semi-axes {} µT\n", m.field_uT, vec(m.semi_axes_uT, 2));
    s += fmt::format("  soft iron [{}; {}; {}]\n", vec(m.soft_iron.row(0).transpose()), vec(m.soft_iron.row(1).transpose()),
                     vec(m.soft_iron.row(2).transpose()));
  }
  if (r.magnetometer_alignment) {
    const auto& a = *r.magnetometer_alignment;
    const Eigen::AngleAxisd turn(a.R_calibrated_magnetometer);
    s += fmt::format("magnetometer axes onto the accelerometer's ({} samples at rest-like acceleration)\n", a.samples);
    s += fmt::format("  rotation {} ° (1σ {} °), dip {:.3f}°, angle residual RMS {:.3f}°\n",
                     vec(deg(turn.angle()) * turn.axis(), 4), vec(a.sigma_rad * 180.0 / M_PI, 4), deg(a.dip_rad),
                     deg(a.residual_rms_rad));
  }
  if (r.hard_iron) {
    const auto& h = *r.hard_iron;
    s += fmt::format("magnetometer hard iron (max+min)/2 {} µT, field {:.2f} µT, radius spread {:.2f}%\n",
                     vec(h.hard_iron_uT, 3), h.field_uT, 100 * h.radius_spread);
  }
  return s;
}

}  // namespace antpose::calibration
