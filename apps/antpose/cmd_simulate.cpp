// antpose simulate imu: writes a simulated capture (sensor streams + truth) for tests and demos.
#include <cmath>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "antpose/geomag/wmm.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "antpose/geomag/earth_model.hpp"
#include "commands.hpp"
#include "option_checks.hpp"

namespace antpose::cli {
namespace {

struct SimulateOptions {
  std::string output;
  bool force = false;
  std::uint64_t seed = 1;
  std::string preset = "static-poses";
  std::optional<double> duration_s;
  std::string phone = "typical";
  std::string hard_iron;
  std::string disturbance;
  std::string disturbance_window;
  std::optional<double> lat_deg, lon_deg;
  double alt_m = 0.0;
  std::string date;
  double azimuth_deg = 0.0, downtilt_deg = 0.0, roll_deg = 0.0;
  std::string placement = "top-up";
  std::optional<double> tremor_deg;
};

// "X,Y,Z" → numbers; `what` names the option in the message.
std::vector<double> parse_list(const std::string& text, std::size_t count, const std::string& what, const std::string& expected) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw InputError(what, fmt::format("'{}' is not a list of numbers, expected {}", text, expected));
    }
  }
  if (out.size() != count) throw InputError(what, fmt::format("'{}' has {} values, expected {}", text, out.size(), expected));
  return out;
}

Vec3 parse_vec3(const std::string& text, const std::string& what) {
  const auto v = parse_list(text, 3, what, "three numbers X,Y,Z in µT");
  return {v[0], v[1], v[2]};
}

void run_simulate_imu(const SimulateOptions& o, const CLI::App& cmd) {
  sim::ImuSimulation s;
  s.seed = o.seed;
  std::mt19937_64 phone_rng(o.seed ^ 0x9e3779b97f4a7c15ULL);
  if (o.phone == "ideal") s.phone = sim::PhoneModel::ideal();
  else if (o.phone == "typical") s.phone = sim::PhoneModel::typical();
  else s.phone = sim::PhoneModel::random(phone_rng);
  if (!o.hard_iron.empty()) s.phone.magnetometer.hard_iron_uT = parse_vec3(o.hard_iron, "--hard-iron-uT");

  if (o.disturbance.empty() != o.disturbance_window.empty())
    throw InputError(o.disturbance.empty() ? "--disturbance-window" : "--disturbance-uT",
                     "--disturbance-uT and --disturbance-window go together; give both");
  if (!o.disturbance.empty()) {
    const auto w = parse_list(o.disturbance_window, 2, "--disturbance-window", "T0,T1 in seconds with T0 < T1");
    if (!(w[0] < w[1]))
      throw InputError("--disturbance-window", fmt::format("'{}': T0 must be before T1", o.disturbance_window));
    s.disturbances.push_back({w[0], w[1], parse_vec3(o.disturbance, "--disturbance-uT")});
  }

  if (o.lat_deg.has_value() != o.lon_deg.has_value())
    throw InputError(o.lat_deg ? "--lon" : "--lat", "--lat and --lon go together; give both for a site");
  if (o.lat_deg) {
    Site site{*o.lat_deg, *o.lon_deg, o.alt_m, o.date.empty() ? geomag::today_utc_iso() : o.date};
    geomag::SiteField field;
    try {
      field = geomag::site_field(geomag::MagneticModel::wmm2025(), site);
    } catch (const std::invalid_argument& e) {
      throw InputError("--lat/--lon/--alt-m/--date", e.what());
    }
    if (field.validity_warning) fmt::print(stderr, "warning: {}\n", *field.validity_warning);
    s.field_world_uT = field.field_enu_uT;
    s.gravity = geomag::normal_gravity(site.lat_deg, site.alt_m);
    s.time_origin = site.date + "T12:00:00Z";
    s.site = site;
  } else if (!o.date.empty() || cmd.count("--alt-m") > 0) {
    throw InputError(o.date.empty() ? "--alt-m" : "--date", "a site needs --lat and --lon as well");
  }

  const bool antenna_options = cmd.count("--antenna-azimuth-deg") + cmd.count("--antenna-downtilt-deg") +
                                   cmd.count("--antenna-roll-deg") + cmd.count("--placement") > 0;
  if (antenna_options && o.preset != "contact")
    throw InputError("--preset", fmt::format("the antenna options apply to '--preset contact' only, not '{}'", o.preset));
  if (o.duration_s && !(*o.duration_s > 0.0))
    throw InputError("--duration", fmt::format("{} s is not a positive duration", *o.duration_s));

  Capture capture;
  if (o.preset == "contact") {
    if (o.downtilt_deg <= -90.0 || o.downtilt_deg >= 90.0)
      throw InputError("--antenna-downtilt-deg", fmt::format("{} is out of range, expected (-90, 90)", o.downtilt_deg));
    ContactPlacement placement;
    try {
      placement = parse_contact_placement(o.placement);
    } catch (const std::invalid_argument& e) {
      throw InputError("--placement", e.what());
    }
    sim::ContactMotion motion;
    const double fixed = motion.before_s + motion.approach_s + motion.removal_s + motion.after_s;
    if (o.duration_s) {
      if (*o.duration_s < fixed + 1.0)
        throw InputError("--duration", fmt::format("{} s is too short for the contact preset: at least {} s ({} s of movement "
                                                   "and 1 s on the plate)", *o.duration_s, fixed + 1.0, fixed));
      motion.hold_s = *o.duration_s - fixed;
    }
    if (o.tremor_deg) motion.tremor_rotation_rms_rad = deg2rad(*o.tremor_deg);
    const Mat3 R_world_antenna = rotation_from_attitude(deg2rad(o.azimuth_deg), deg2rad(o.downtilt_deg), deg2rad(o.roll_deg));
    capture = sim::simulate_contact(s, R_world_antenna, placement, motion);
  } else {
    const double tremor = o.tremor_deg ? deg2rad(*o.tremor_deg) : 0.0;
    if (o.preset == "static-poses") {
      const auto poses = sim::calibration_poses();
      constexpr double kMove = 1.5;
      const double n = static_cast<double>(poses.size());
      const double total = o.duration_s.value_or(n * 3.0 + (n - 1) * kMove);
      const double hold = (total - (n - 1) * kMove) / n;
      if (hold < 0.5)
        throw InputError("--duration", fmt::format("{} s is too short for {} poses: at least {} s", total, poses.size(),
                                                   (n - 1) * kMove + n * 0.5));
      s.trajectory = sim::static_poses(poses, hold, kMove);
      s.kind = "imu-calibration";
    } else {
      if (o.duration_s && *o.duration_s < 3.0)
        throw InputError("--duration", fmt::format("{} s is too short for the tumble preset: at least 3 s", *o.duration_s));
      s.trajectory = sim::tumble(o.duration_s.value_or(30.0), 1.0, o.seed);
      s.kind = "imu-calibration";  // a phone turned through all directions: a magnetometer calibration
    }
    if (tremor > 0.0) s.trajectory.with_tremor(tremor, 1e-5, o.seed);
    capture = sim::simulate_imu(s);
  }

  write_capture(capture, o.output, CaptureWriteOptions{o.force});
  fmt::print("wrote {} ({} preset, {:.1f} s): ", o.output, o.preset, capture.truth_orientation->t.back());
  bool first = true;
  for (const auto& [name, stream] : capture.streams) {
    fmt::print("{}{} {} samples", first ? "" : ", ", stream.size(), name);
    first = false;
  }
  fmt::print("\n");
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto* simulate = app.add_subcommand("simulate", "Write simulated captures with ground truth");
  simulate->require_subcommand(1);
  auto* cmd = simulate->add_subcommand(
      "imu", "Simulate a phone's accelerometer, gyroscope and magnetometer along a trajectory (truth in truth/)");
  auto o = std::make_shared<SimulateOptions>();
  cmd->add_option("-o,--output", o->output, "Capture folder to create")->required();
  cmd->add_flag("--force", o->force, "Replace an existing output folder");
  cmd->add_option("--seed", o->seed, "Random seed (the same seed gives the same capture)");
  cmd->add_option("--preset", o->preset,
                  "static-poses: 18 held poses (multi-position calibration, kind imu-calibration); "
                  "tumble: continuous random rotations (magnetometer calibration, kind imu-calibration); contact: phone laid on an antenna's back plate (kind contact)")
      ->check(CLI::IsMember({"contact", "static-poses", "tumble"}))
      ->capture_default_str();
  cmd->add_option(
         "--duration", o->duration_s,
         "Total length, s (static-poses: 79.5; tumble: 30; contact: 14.5, of which all but 6.5 s on the plate)")
      ->check(finite_within(0.0, 86400.0, "s"));
  cmd->add_option("--phone", o->phone, "Sensor error model: ideal, typical (datasheet figures), random (a unit within tolerance)")
      ->check(CLI::IsMember({"ideal", "typical", "random"}))
      ->capture_default_str();
  cmd->add_option("--hard-iron-uT", o->hard_iron, "Magnetometer hard iron X,Y,Z in µT (replaces the phone model's)");
  cmd->add_option("--disturbance-uT", o->disturbance, "Extra magnetic field X,Y,Z (µT, ENU) during --disturbance-window");
  cmd->add_option("--disturbance-window", o->disturbance_window, "T0,T1: when the disturbance is present, s");
  cmd->add_option("--lat", o->lat_deg, "Site latitude, deg (with --lon: Earth field from WMM2025, normal gravity)")
      ->check(finite_within(-90.0, 90.0, "deg"));
  cmd->add_option("--lon", o->lon_deg, "Site longitude, deg east")->check(finite_within(-360.0, 360.0, "deg"));
  cmd->add_option("--alt-m", o->alt_m, "Site height above the WGS84 ellipsoid, m")
      ->check(finite_within(-1000.0, 850000.0, "m"));
  cmd->add_option("--date", o->date, "Date YYYY-MM-DD for the magnetic model (default today)");
  cmd->add_option("--antenna-azimuth-deg", o->azimuth_deg, "Contact preset: true azimuth of the antenna boresight, deg")
      ->check(finite_within(-360.0, 360.0, "deg"));
  cmd->add_option("--antenna-downtilt-deg", o->downtilt_deg, "Contact preset: mechanical downtilt, deg (positive down)")
      ->check(finite_within(-90.0, 90.0, "deg"));
  cmd->add_option("--antenna-roll-deg", o->roll_deg, "Contact preset: roll about the boresight, deg")
      ->check(finite_within(-180.0, 180.0, "deg"));
  cmd->add_option("--placement", o->placement, "Contact preset: top-up, top-down, top-right, top-left")->capture_default_str();
  cmd->add_option("--tremor-deg", o->tremor_deg, "Hand tremor, RMS rotation in deg (contact default 0.057)")
      ->check(finite_within(0.0, 10.0, "deg"));
  cmd->callback([o, cmd] { run_simulate_imu(*o, *cmd); });
  add_simulate_capture_command(*simulate);
}

}  // namespace antpose::cli
