// antpose calibrate: per-device sensor calibration.
//   antpose calibrate imu CAPTURE -o device.yaml [--sensors acc,gyro,mag] [--error-model thesis|full] [--force]
//   antpose calibrate imu CAPTURE --device ID|FILE [--db PATH] [-o device.yaml] ...   (stored with the device)
//   antpose calibrate allan CAPTURE [--stream gyroscope] [--json OUT] [--plot OUT.svg]
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/calibration/allan.hpp"
#include "antpose/calibration/calibrate_imu.hpp"
#include "antpose/io/text_file.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "option_checks.hpp"
#include "json_output.hpp"
#include "device_calibration.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct ImuArgs {
  std::string capture, output;
  std::string sensors = "acc,gyro,mag";
  std::string error_model = "full";
  std::optional<double> gravity;
  bool force = false;
  DeviceOption device;
};

// calibrate imu --device ID|FILE: the device's current profile is the base (sections of sensors
// not calibrated now are kept); only the imu section is this run's. -o, when also given,
// receives the whole new profile.
void run_imu_device(const ImuArgs& args, const calibration::CalibrateImuOptions& options,
                    const store::DeviceRef& device) {
  if (!args.output.empty() && fs::exists(args.output) && !args.force)
    throw InputError(args.output,
                     "-o: exists; with --device the file receives the device's whole profile. Use "
                     "--force to replace it, or another name");
  nlohmann::json settings = {{"sensors", args.sensors}, {"error_model", args.error_model}, {"capture", args.capture}};
  if (args.gravity) settings["gravity_m_s2"] = *args.gravity;
  Diagnostics diagnostics;
  run_calibration(device, "imu", settings, {args.capture}, diagnostics, [&] {
    const Capture capture = read_capture(args.capture, diagnostics);
    if (capture.kind != "imu-calibration")
      diagnostics.warn(args.capture, 0, fmt::format("capture kind is '{}', not 'imu-calibration'", capture.kind));
    const auto result = calibration::calibrate_imu(capture, options, diagnostics, args.capture, device.profile.imu);
    CalibrationOutcome outcome;
    const auto& c = result.calibration;
    outcome.residuals = {{"gravity_m_s2", result.gravity}, {"static_frames", result.frames.size()}};
    if (c.acc_residual_rms_m_s2) outcome.residuals["acc_residual_rms_m_s2"] = *c.acc_residual_rms_m_s2;
    if (c.gyro_residual_rms_deg) outcome.residuals["gyro_residual_rms_deg"] = *c.gyro_residual_rms_deg;
    if (c.mag_residual_rel) outcome.residuals["mag_residual_rel"] = *c.mag_residual_rel;
    if (c.mag_field_uT) outcome.residuals["mag_field_uT"] = *c.mag_field_uT;
    outcome.apply = [imu = result.calibration](store::DeviceProfile& current) {
      YAML::Node document = YAML::Clone(current.imu.document);
      if (!document.IsMap()) document = YAML::Node(YAML::NodeType::Map);
      if (imu.document.IsMap() && imu.document["imu"]) document["imu"] = YAML::Clone(imu.document["imu"]);
      current.imu = imu;
      current.imu.document = document;
      current.imu.device_id = current.id;
      current.has_imu = true;
    };
    fmt::print("IMU calibration of {} (error model {})\n{}", args.capture, args.error_model,
               calibration::describe(result));
    if (!args.output.empty()) {
      store::DeviceProfile after = device.profile;
      outcome.apply(after);
      store::write_device_profile(after, args.output);
      fmt::print("wrote {}\n", args.output);
    }
    return outcome;
  });
}

void run_imu(const ImuArgs& args) {
  calibration::CalibrateImuOptions options;
  calibration::parse_sensors(args.sensors, options);
  options.method = calibration::parse_method(args.error_model);
  options.gravity = args.gravity;
  if (const auto device = args.device.resolve()) return run_imu_device(args, options, *device);
  if (args.output.empty()) throw InputError("-o", "no output given: pass -o device.yaml and/or --device ID|FILE");
  Diagnostics diagnostics;
  calibration::CalibrateImuResult result;
  try {
    result = calibration::calibrate_imu_file(args.capture, args.output, options, args.force, diagnostics);
  } catch (...) {
    print_warnings(diagnostics);
    throw;
  }
  print_warnings(diagnostics);
  fmt::print("IMU calibration of {} (error model {})\n{}wrote {}\n", args.capture, args.error_model,
             calibration::describe(result), args.output);
}

struct AllanArgs {
  std::string capture, stream = "gyroscope", json, plot;
  int per_decade = 10;
};

void run_allan(const AllanArgs& args, const CLI::App& verb) {
  Diagnostics diagnostics;
  const Capture capture = read_capture(args.capture, diagnostics);
  const Stream& stream = capture.require(args.stream);
  const auto a = calibration::allan_of_stream(stream, diagnostics, args.capture, args.per_decade);
  print_warnings(diagnostics);
  const std::string_view known_unit = streams::unit_of(args.stream);
  const std::string unit = known_unit.empty() ? "unit" : std::string(known_unit);
  fmt::print("overlapping Allan deviation of '{}' ({} samples, tau0 {:.5f} s, {:.0f} s), unit {}\n", args.stream,
             stream.size(), a.tau0, stream.duration(), unit);
  fmt::print("{:<6} {:>14} {:>14} {:>10} {:>14}\n", "axis", "N (·√s)", "B", "tau_B s", "K (/√s)");
  auto opt = [](const std::optional<double>& v) { return v ? fmt::format("{:.4e}", *v) : std::string("-"); };
  nlohmann::json j;
  j["stream"] = args.stream;
  j["tau0_s"] = a.tau0;
  j["unit"] = unit;
  std::vector<calibration::AllanSeries> series;
  for (std::size_t k = 0; k < a.axes.size(); ++k) {
    const auto& f = a.fits[k];
    fmt::print("{:<6} {:>14} {:>14} {:>10} {:>14}\n", a.axes[k], opt(f.white), opt(f.bias_instability),
               f.bias_instability_tau ? fmt::format("{:.2f}", *f.bias_instability_tau) : "-", opt(f.random_walk));
    nlohmann::json axis;
    axis["axis"] = a.axes[k];
    for (const auto& p : a.curves[k])
      axis["curve"].push_back({{"m", p.m}, {"tau_s", p.tau}, {"n", p.n}, {"oadev", p.deviation}});
    if (f.white) axis["white_noise"] = *f.white;
    if (f.bias_instability) axis["bias_instability"] = *f.bias_instability;
    if (f.bias_instability_tau) axis["bias_instability_tau_s"] = *f.bias_instability_tau;
    if (f.random_walk) axis["random_walk"] = *f.random_walk;
    j["axes"].push_back(axis);
    series.push_back({args.stream + " " + a.axes[k], a.curves[k], f});
  }
  if (!args.json.empty()) write_json(args.json, j, provenance_of(verb).input("capture", args.capture));
  if (!args.plot.empty())
    io::write_text_atomic(args.plot,
                          calibration::allan_svg(series, "Overlapping Allan deviation: " + args.capture, unit));
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("calibrate", "per-device sensor calibration");
  cmd->require_subcommand(1);
  add_calibrate_camera_command(*cmd);
  add_calibrate_joint_command(*cmd);

  auto imu_args = std::make_shared<ImuArgs>();
  auto* imu = cmd->add_subcommand("imu",
                                  "accelerometer, gyroscope and magnetometer calibration from an "
                                  "imu-calibration capture; writes the device YAML");
  imu->add_option("capture", imu_args->capture, "imu-calibration capture folder")->required();
  imu->add_option("-o,--output", imu_args->output, "device calibration YAML to write (required without --device)");
  imu_args->device.add_to(*imu);
  imu->add_option("--sensors", imu_args->sensors, "comma-separated subset of acc,gyro,mag")->capture_default_str();
  imu->add_option("--error-model", imu_args->error_model,
                  "thesis (normalization, bias, hard iron) or full (9-parameter models, "
                  "ellipsoid)")
      ->capture_default_str()
      ->check(CLI::IsMember({"thesis", "full"}));
  add_renamed_option(*imu, "--method", "--error-model");
  imu->add_option("--gravity", imu_args->gravity,
                  "local gravity, m/s² (default: normal gravity at the capture's site, "
                  "else 9.80665)");
  imu->add_flag("--force", imu_args->force, "ignore (and replace) an existing output file instead of updating it");
  imu->callback([imu_args] { run_imu(*imu_args); });

  auto allan_args = std::make_shared<AllanArgs>();
  auto* allan = cmd->add_subcommand("allan", "overlapping Allan deviation and noise fit of a static log");
  allan->add_option("capture", allan_args->capture, "capture folder (a long static recording)")->required();
  allan->add_option("--stream", allan_args->stream, "stream to analyse")->capture_default_str();
  add_json_option(allan, allan_args->json, "write the curves and fits");
  allan->add_option("--plot", allan_args->plot, "write a log-log SVG plot");
  allan->add_option("--per-decade", allan_args->per_decade, "averaging times per decade")->capture_default_str();
  allan->callback([allan_args, allan] { run_allan(*allan_args, *allan); });
}

}  // namespace antpose::cli
