// antpose orientation CAPTURE --method NAME [--param k=v ...] -o orientation.csv
// The phone's orientation over a capture (q_world_device, ENU magnetic north unless --true-north).
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "antpose/geomag/wmm.hpp"
#include "antpose/orientation/estimator.hpp"
#include "commands.hpp"
#include "option_checks.hpp"

namespace antpose::cli {
namespace {

struct OrientationArgs {
  std::string capture;
  std::string method = "madgwick";
  std::vector<std::string> params;
  std::string output;
  bool true_north = false;
  std::string wmm;
};

void run_orientation(const OrientationArgs& args) {
  Diagnostics diagnostics;
  const auto estimator = orientation::make_estimator(args.method, orientation::parse_params(args.params));
  const Capture capture = read_capture(args.capture, diagnostics);
  const orientation::ImuData data = orientation::imu_data_from_capture(capture, diagnostics);
  orientation::OrientationTrack track = estimator->estimate(data, diagnostics);
  if (args.true_north) {
    const std::filesystem::path where = capture.root / "capture.yaml";
    if (!capture.site) throw InputError(where, "--true-north needs the capture's site (lat/lon/alt/date)");
    const auto model = args.wmm.empty() ? geomag::MagneticModel::wmm2025() : geomag::MagneticModel::from_file(args.wmm);
    geomag::SiteField field;
    try {
      field = geomag::site_field(model, *capture.site);
    } catch (const std::invalid_argument& e) {
      throw InputError(where, fmt::format("site: {}", e.what()));
    }
    if (field.validity_warning) diagnostics.warn(where, 0, *field.validity_warning);
    track = orientation::apply_declination(track, field.declination);
    fmt::print("declination {:.3f}° ({}) applied: world enu-true\n", rad2deg(field.declination), model.name());
  }
  orientation::write_track_csv(track, args.output);
  fmt::print("{}: {} samples, t = [{:.3f}, {:.3f}] s, world {}{} -> {}\n", estimator->name(), track.size(),
             track.empty() ? 0.0 : track.t.front(), track.empty() ? 0.0 : track.t.back(), track.world,
             track.has_uncertainty() ? ", with uncertainty" : "", args.output);
  print_warnings(diagnostics);
}

}  // namespace

void add_orientation_command(CLI::App& app) {
  auto args = std::make_shared<OrientationArgs>();
  auto* cmd = app.add_subcommand("orientation", "estimate the phone's orientation over a capture");
  cmd->add_option("capture", args->capture, "capture folder")->required();
  add_orientation_method_option(*cmd, args->method, "estimator")->capture_default_str();
  cmd->add_option("--param", args->params, "estimator parameter name=value (repeatable), e.g. beta=0.1");
  cmd->add_option("-o,--output", args->output, "output CSV: t,qw,qx,qy,qz[,tilt_sigma_deg,heading_sigma_deg]")
      ->required();
  cmd->add_flag("--true-north", args->true_north, "rotate to true north with the WMM declination at the capture's site");
  cmd->add_option("--wmm", args->wmm, "WMM coefficient file (default: the built-in WMM2025)");
  cmd->callback([args] { run_orientation(*args); });
}

}  // namespace antpose::cli
