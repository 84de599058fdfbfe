#include "antpose/measure/contact.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "antpose/geomag/wmm.hpp"

namespace antpose::measure {
namespace {

bool is_iso_date(const std::string& s) {
  if (s.size() < 10) return false;
  try {
    geomag::decimal_year_from_iso(s.substr(0, 10));
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

// The declination and the expected field at the capture's site (WMM), and the measured field
// checked against it: a field or dip off the model's marks a disturbed compass. Without a site, the
// field is only checked against the Earth's range.
void add_site_field(const Capture& input, const ContactOptions& options, ContactResult& r) {
  if (input.site) {
    Site site = *input.site;
    if (site.date.empty()) {
      if (input.time_origin && is_iso_date(*input.time_origin)) {
        site.date = input.time_origin->substr(0, 10);
      } else {
        site.date = geomag::today_utc_iso();
        r.warnings.push_back("the site has no date and the capture no time_origin: the magnetic model was "
                             "evaluated for today, " + site.date);
      }
    }
    geomag::SiteField field;
    try {
      field = geomag::site_field(geomag::MagneticModel::wmm2025(), site);
    } catch (const std::invalid_argument& e) {
      throw InputError(input.root / "capture.yaml", std::string("site: ") + e.what());
    }
    if (field.validity_warning) r.warnings.push_back(*field.validity_warning);
    r.declination = field.declination;
    r.expected_field_uT = field.elements.f_nT / 1000.0;
    r.expected_dip = field.inclination;
    r.sigma.declination = field.declination_sigma;
    if (r.azimuth_magnetic) {
      r.azimuth_true = wrap_2pi(*r.azimuth_magnetic + field.declination);
      r.sigma.azimuth_true = std::hypot(r.sigma.azimuth, *r.sigma.declination);
    }
    const double rel = std::abs(r.field_uT - *r.expected_field_uT) / *r.expected_field_uT;
    const double ddip = std::abs(r.dip - *r.expected_dip);
    if (rel > options.field_tolerance) {
      r.magnetic_disturbance = true;
      r.warnings.push_back(fmt::format(
          "magnetic disturbance: the measured field {:.1f} µT differs from the WMM's {:.1f} µT at the site by {:.0f}% "
          "(limit {:.0f}%); the azimuth is unreliable (steel nearby, or an uncalibrated magnetometer: give "
          "--imu-calibration)",
          r.field_uT, *r.expected_field_uT, 100.0 * rel, 100.0 * options.field_tolerance));
    }
    if (ddip > options.dip_tolerance) {
      r.magnetic_disturbance = true;
      r.warnings.push_back(fmt::format(
          "magnetic disturbance: the measured dip {:.1f}° differs from the WMM's inclination {:.1f}° at the site by "
          "{:.1f}° (limit {:.1f}°); the azimuth is unreliable",
          rad2deg(r.dip), rad2deg(*r.expected_dip), rad2deg(ddip), rad2deg(options.dip_tolerance)));
    }
  } else {
    r.warnings.push_back(fmt::format(
        "no site in the capture: no declination (true azimuth unavailable) and the field is only checked against "
        "the Earth's range {:.0f}–{:.0f} µT",
        options.plausible_field_min_uT, options.plausible_field_max_uT));
    if (r.field_uT < options.plausible_field_min_uT || r.field_uT > options.plausible_field_max_uT) {
      r.magnetic_disturbance = true;
      r.warnings.push_back(fmt::format(
          "magnetic disturbance: the measured field {:.1f} µT is outside the Earth's range {:.0f}–{:.0f} µT; the "
          "azimuth is unreliable (steel nearby, or an uncalibrated magnetometer: give --imu-calibration)",
          r.field_uT, options.plausible_field_min_uT, options.plausible_field_max_uT));
    }
  }
}

}  // namespace

ContactResult measure_contact(const Capture& input, const ContactOptions& options) {
  // Fail on missing streams before anything else, with the capture's own message.
  input.require(streams::kAccelerometer);
  input.require(streams::kMagnetometer);
  require_android_frame(input, "the contact measurement");

  const Capture* capture = &input;
  Capture calibrated;
  if (options.calibration) {
    calibrated = input;
    imu::apply(*options.calibration, calibrated);
    capture = &calibrated;
  }

  ContactResult r;
  r.placement = options.placement;

  const imu::StaticDetection detection = imu::detect_static(*capture, options.detector);
  r.static_windows = detection.windows.size();
  if (detection.windows.empty())
    throw MeasurementError(fmt::format(
        "no static window in the capture ({}): the phone never stayed still for {:.1f} s (accelerometer std below "
        "{:.1f}% of g{}); press the phone flat on the antenna's back plate and hold it still for a few seconds",
        input.root.empty() ? std::string("in memory") : input.root.string(), options.detector.window_s,
        100.0 * options.detector.acc_rel_std_max,
        detection.used_gyroscope ? fmt::format(", gyroscope std below {:.2f} rad/s", options.detector.gyro_std_max)
                                 : std::string()));
  imu::StaticWindow window = detection.windows.front();
  if (window.duration() - 2.0 * options.trim_s >= options.min_window_s) {
    window.t0 += options.trim_s;
    window.t1 -= options.trim_s;
  }
  r.t0 = window.t0;
  r.t1 = window.t1;
  for (const auto& note : detection.notes) r.warnings.push_back(note);
  if (window.duration() < options.min_window_s)
    r.warnings.push_back(fmt::format("static window short: the longest still interval is {:.1f} s (< {:.1f} s); "
                                     "hold the phone still on the plate longer",
                                     detection.windows.front().duration(), options.min_window_s));

  // The uncertainty floors must reflect what was calibrated, or an uncalibrated phone would
  // report a confident σ it cannot have.
  orientation::StaticOrientationOptions floors = options.orientation;
  const auto* cal = options.calibration ? &*options.calibration : nullptr;
  const YAML::Node imu_section = cal && cal->document.IsMap() ? cal->document["imu"] : YAML::Node();
  const bool acc_calibrated = cal && (imu_section["accelerometer"] || !cal->acc_bias.isZero() || cal->acc_scale != Vec3::Ones());
  const bool mag_calibrated = cal && (imu_section["magnetometer"] || !cal->mag_hard_iron_uT.isZero());
  if (!acc_calibrated) floors.acc_bias_floor_mps2 = std::max(floors.acc_bias_floor_mps2, options.uncalibrated_acc_bias_mps2);
  if (!mag_calibrated) floors.mag_residual_uT = std::max(floors.mag_residual_uT, options.uncalibrated_mag_residual_uT);
  r.phone = orientation::estimate_static_orientation(*capture, window.t0, window.t1, floors);
  const auto& phone = r.phone;
  r.field_uT = phone.field_uT;
  r.dip = phone.dip;

  r.R_world_antenna_magnetic = phone.R_world_device * contact_rotation(options.placement);
  const AntennaAttitude attitude = attitude_from_rotation(r.R_world_antenna_magnetic);
  r.azimuth_magnetic = attitude.azimuth;
  r.downtilt = attitude.downtilt;
  r.roll = attitude.roll;
  if (!attitude.azimuth)
    r.warnings.push_back(fmt::format("boresight within {:.0f}° of vertical (downtilt {:.1f}°): azimuth and roll "
                                     "are undefined",
                                     rad2deg(kDefaultVerticalLimit), rad2deg(r.downtilt)));
  else if (std::abs(r.downtilt) > std::numbers::pi / 2 - options.horizontal_plate_limit)
    r.warnings.push_back(fmt::format(
        "plate nearly horizontal: gravity is within {:.0f}° of the phone's z axis (downtilt {:.1f}°), implausible "
        "for a panel antenna; check that the phone lies on the back plate and the placement ({})",
        90.0 - std::abs(rad2deg(r.downtilt)), rad2deg(r.downtilt), to_string(options.placement)));

  // Uncertainties.
  const double cos_tilt = std::max(std::cos(r.downtilt), std::sin(kDefaultVerticalLimit));
  r.sigma.downtilt = phone.tilt_sigma;
  r.sigma.roll = phone.tilt_sigma / cos_tilt;
  r.sigma.azimuth = std::hypot(phone.heading_sigma, phone.tilt_sigma * std::abs(std::tan(r.downtilt)));

  add_site_field(input, options, r);

  if (phone.max_block_tilt > options.max_block_tilt || phone.max_block_heading > options.max_block_heading)
    r.warnings.push_back(fmt::format(
        "phone not flat on the plate / moved: during the window its tilt wandered by up to {:.2f}° (limit {:.2f}°) "
        "and its heading by up to {:.1f}° (limit {:.1f}°)",
        rad2deg(phone.max_block_tilt), rad2deg(options.max_block_tilt), rad2deg(phone.max_block_heading),
        rad2deg(options.max_block_heading)));

  if (r.sigma.azimuth > options.uncertain_azimuth || r.sigma.downtilt > options.uncertain_tilt ||
      (r.roll && r.sigma.roll > options.uncertain_tilt))
    r.warnings.push_back(fmt::format("uncertain: 1σ azimuth {:.1f}°, downtilt {:.2f}°, roll {:.2f}° (limits {:.1f}°, "
                                     "{:.2f}°){}",
                                     rad2deg(r.sigma.azimuth), rad2deg(r.sigma.downtilt), rad2deg(r.sigma.roll),
                                     rad2deg(options.uncertain_azimuth), rad2deg(options.uncertain_tilt),
                                     acc_calibrated && mag_calibrated ? std::string()
                                     : fmt::format("; not calibrated: {} (see --imu-calibration)",
                                                   acc_calibrated   ? "magnetometer"
                                                   : mag_calibrated ? "accelerometer"
                                                                    : "accelerometer, magnetometer")));
  return r;
}

imu::HardIronEstimate calibrate_from_recording(const Capture& recording, ContactOptions& options) {
  const imu::HardIronEstimate hard =
      imu::estimate_hard_iron(recording.require(streams::kMagnetometer), {}, recording.root);
  imu::ImuCalibration calibration;
  calibration.mag_hard_iron_uT = hard.hard_iron_uT;
  calibration.device_model = recording.device_model;
  calibration.device_id = recording.device_id;
  calibration.document["imu"]["magnetometer"]["hard_iron_uT"] =
      std::vector<double>{hard.hard_iron_uT.x(), hard.hard_iron_uT.y(), hard.hard_iron_uT.z()};
  options.calibration = std::move(calibration);
  options.orientation.mag_residual_uT = std::max(options.orientation.mag_residual_uT, hard.residual_uT);
  return hard;
}

nlohmann::json to_json(const ContactResult& r) {
  using nlohmann::json;
  auto deg = [](const std::optional<double>& v) -> json { return v ? json(rad2deg(*v)) : json(nullptr); };
  json j;
  j["azimuth_magnetic_deg"] = deg(r.azimuth_magnetic);
  j["azimuth_true_deg"] = deg(r.azimuth_true);
  j["declination_deg"] = deg(r.declination);
  j["downtilt_deg"] = rad2deg(r.downtilt);
  j["roll_deg"] = deg(r.roll);
  // 1σ of each angle, under the angle's own key.
  j["sigma"] = {{"azimuth_magnetic_deg", rad2deg(r.sigma.azimuth)},
                {"azimuth_true_deg", deg(r.sigma.azimuth_true)},
                {"downtilt_deg", rad2deg(r.sigma.downtilt)},
                {"roll_deg", rad2deg(r.sigma.roll)}};
  j["warnings"] = r.warnings;
  j["window_s"] = {r.t0, r.t1};
  j["field"] = {{"measured_uT", r.field_uT},
                {"expected_uT", r.expected_field_uT ? json(*r.expected_field_uT) : json(nullptr)},
                {"dip_deg", rad2deg(r.dip)},
                {"expected_dip_deg", deg(r.expected_dip)}};
  j["placement"] = std::string(to_string(r.placement));
  j["phone_attitude"] = {{"yaw_deg", rad2deg(r.phone.android.azimuth)},
                         {"pitch_deg", rad2deg(r.phone.android.pitch)},
                         {"roll_deg", rad2deg(r.phone.android.roll)}};
  return j;
}

}  // namespace antpose::measure
