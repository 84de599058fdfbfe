// antpose contact: antenna attitude from a phone held flat on the antenna's back plate.
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "antpose/imu/hard_iron.hpp"
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/measure/contact.hpp"
#include "antpose/store/device_ref.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"
#include "usable.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct ContactArgs {
  std::string capture;
  std::string calibration;
  std::string placement = "top-up";
  std::string json;
  std::optional<std::string> device, db;
  double max_sigma_deg = kDefaultMaxSigmaDeg;
  bool no_unit_repair = false;
};

// --imu-calibration: a device YAML file, or a recording of the phone turned in all directions.
void load_calibration(const fs::path& path, const CaptureReadOptions& read_options, Diagnostics& diagnostics,
                      measure::ContactOptions& options) {
  if (!fs::exists(path))
    throw InputError(path, "--imu-calibration: no such file or folder (expected a calibration capture folder or an "
                           "antpose-device YAML file)");
  if (!fs::is_directory(path)) {
    options.calibration = imu::read_imu_calibration(path);
    return;
  }
  const imu::HardIronEstimate hard =
      measure::calibrate_from_recording(read_capture(path, diagnostics, read_options), options);
  fmt::print("hard iron from {}: ({:.2f}, {:.2f}, {:.2f}) µT ± {:.1f} µT, field {:.1f} µT, axis coverage "
             "{:.0f}/{:.0f}/{:.0f}%\n",
             path.string(), hard.hard_iron_uT.x(), hard.hard_iron_uT.y(), hard.hard_iron_uT.z(), hard.residual_uT,
             hard.field_uT, 100 * hard.coverage.x(), 100 * hard.coverage.y(), 100 * hard.coverage.z());
}

std::string angle(const std::optional<double>& value, double sigma, int digits) {
  if (!value) return "undefined";
  return fmt::format("{:.{}f}° ± {:.{}f}°", rad2deg(*value), digits, rad2deg(sigma), digits);
}

// The azimuth that is reported (true with a site, else magnetic), the downtilt and the roll.
std::vector<AngleReading> readings(const measure::ContactResult& r) {
  const bool truth = r.azimuth_true.has_value();
  return {{truth ? "azimuth" : "magnetic azimuth", truth ? r.azimuth_true : r.azimuth_magnetic,
           truth ? r.sigma.azimuth_true : std::optional<double>(r.sigma.azimuth)},
          {"downtilt", r.downtilt, r.sigma.downtilt},
          {"roll", r.roll, r.sigma.roll}};
}

// --device: the phone's profile, whose IMU calibration is applied as --imu-calibration's would be.
std::optional<store::DeviceRef> device_calibration(const ContactArgs& args, Diagnostics& diagnostics,
                                                   measure::ContactOptions& options) {
  if (!args.device) return std::nullopt;
  if (!args.calibration.empty())
    throw InputError("--device", "give --device or --imu-calibration, not both: each brings an IMU calibration");
  auto ref = store::resolve_device_ref(*args.device, args.db ? std::optional<fs::path>(*args.db) : std::nullopt);
  if (ref.profile.has_imu)
    options.calibration = ref.profile.imu;
  else
    diagnostics.warn(ref.file ? *ref.file : fs::path("--device " + ref.profile.id), 0, kNoImuCalibrationWarning);
  return ref;
}

int run_contact(const ContactArgs& args, const CLI::App& verb) {
  measure::ContactOptions options;
  try {
    options.placement = parse_contact_placement(args.placement);
  } catch (const std::invalid_argument& e) {
    throw InputError({}, std::string("--placement: ") + e.what());
  }
  CaptureReadOptions read_options;
  read_options.repair_units = !args.no_unit_repair;
  Diagnostics diagnostics;
  if (!args.calibration.empty()) load_calibration(args.calibration, read_options, diagnostics, options);
  const auto device = device_calibration(args, diagnostics, options);
  const Capture capture = read_capture(args.capture, diagnostics, read_options);
  print_warnings(diagnostics);

  const measure::ContactResult r = measure::measure_contact(capture, options);

  fmt::print("contact measurement: {} (placement {}{})\n", args.capture, to_string(r.placement),
             options.calibration ? ", IMU calibration applied" : "");
  fmt::print("  static window      {:.2f} – {:.2f} s ({:.1f} s; {} acc / {} mag samples)\n", r.t0, r.t1, r.t1 - r.t0,
             r.phone.acc_samples, r.phone.mag_samples);
  fmt::print("  azimuth magnetic   {}\n", angle(r.azimuth_magnetic, r.sigma.azimuth, 1));
  if (r.declination) {
    fmt::print("  declination        {:.2f}° ± {:.2f}° (WMM2025, east positive)\n", rad2deg(*r.declination),
               rad2deg(r.sigma.declination.value_or(0.0)));
    fmt::print("  azimuth true       {}\n", angle(r.azimuth_true, r.sigma.azimuth_true.value_or(0.0), 1));
  } else {
    fmt::print("  azimuth true       unavailable (no site in the capture)\n");
  }
  fmt::print("  downtilt           {}\n", angle(r.downtilt, r.sigma.downtilt, 2));
  fmt::print("  roll               {}\n", angle(r.roll, r.sigma.roll, 2));
  if (r.expected_field_uT)
    fmt::print("  field check        |B| {:.1f} µT (WMM {:.1f} µT), dip {:.1f}° (WMM {:.1f}°){}\n", r.field_uT,
               *r.expected_field_uT, rad2deg(r.dip), rad2deg(r.expected_dip.value_or(0.0)),
               r.magnetic_disturbance ? "  DISTURBED" : "  ok");
  else
    fmt::print("  field check        |B| {:.1f} µT, dip {:.1f}° (no site: band 25–65 µT){}\n", r.field_uT,
               rad2deg(r.dip), r.magnetic_disturbance ? "  DISTURBED" : "");
  fmt::print("  phone (thesis)     azimuth {:.1f}°, pitch {:.1f}°, roll {:.1f}° (Android getOrientation)\n",
             rad2deg(r.phone.android.azimuth), rad2deg(r.phone.android.pitch), rad2deg(r.phone.android.roll));

  Diagnostics result_warnings;
  for (const auto& w : r.warnings) result_warnings.warn(w);
  print_warnings(result_warnings);

  if (!args.json.empty()) {
    store::Provenance provenance = provenance_of(verb).input("capture", args.capture);
    if (!args.calibration.empty()) provenance.input("IMU calibration", args.calibration);
    if (device) add_device(provenance, *device);
    provenance.site = capture.site;
    write_json(args.json, measure::to_json(r), provenance);
  }
  if (const std::string why = unusable_reason(readings(r), args.max_sigma_deg); !why.empty()) {
    fmt::print(stderr, "warning: the result is not usable: {}\n", why);
    return kExitPartial;
  }
  return kExitOk;
}

}  // namespace

void add_contact_command(CLI::App& app) {
  auto args = std::make_shared<ContactArgs>();
  auto* cmd = app.add_subcommand("contact", "antenna azimuth, downtilt and roll from a phone held on the back plate");
  cmd->add_option("capture", args->capture, "native capture folder of the contact recording")->required();
  cmd->add_option("--imu-calibration", args->calibration,
                  "IMU calibration: a capture folder (the phone turned in all directions: hard iron (max+min)/2) "
                  "or an antpose-device YAML file");
  cmd->add_option("--device", args->device,
                  "the phone: a device id in the database or a profile YAML file, whose IMU calibration is applied "
                  "(instead of --imu-calibration)");
  cmd->add_option("--db", args->db, "device database (default as 'antpose device')");
  cmd->add_option("--placement", args->placement, "how the phone lies on the plate: top-up, top-down, top-right, top-left")
      ->capture_default_str();
  add_json_option(cmd, args->json, "write the result");
  add_max_sigma_option(cmd, args->max_sigma_deg);
  cmd->add_flag("--no-unit-repair", args->no_unit_repair, "treat streams in the wrong unit as errors");
  cmd->callback([args, cmd] {
    if (const int status = run_contact(*args, *cmd); status != kExitOk) throw CLI::RuntimeError(status);
  });
}

}  // namespace antpose::cli
