// antpose calibrate camera: intrinsic calibration from photos of a board.
//   antpose calibrate camera CAPTURE [--config FILE] [--fix-aspect-ratio] [--zero-tangent]
//       [--fix-principal-point] [--intrinsics-guess FILE] [--flip] [-o camera.yaml] [--force] [--json OUT]
//       [--device ID|FILE [--db PATH]]
// Command-line switches add to the config (they can only switch a constraint on).
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/camera/calibrate_camera.hpp"
#include "antpose/io/text_file.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "device_calibration.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct CameraArgs {
  std::string capture, config, guess, output, json;
  bool fix_aspect_ratio = false, zero_tangent = false, fix_principal_point = false, flip = false, force = false;
  DeviceOption device;
};

nlohmann::json to_json(const camera::CameraCalibrationResult& r) {
  nlohmann::json j;
  const auto& in = r.intrinsics;
  j["image_width_px"] = in.width;
  j["image_height_px"] = in.height;
  j["fx_px"] = in.fx;
  j["fy_px"] = in.fy;
  j["cx_px"] = in.cx;
  j["cy_px"] = in.cy;
  j["distortion"] = in.distortion;  // OpenCV's coefficients, unitless
  j["rms_px"] = r.rms_px;
  // 1σ of each value, under the value's own key.
  j["sigma"] = {{"fx_px", r.sigma.fx},
                {"fy_px", r.sigma.fy},
                {"cx_px", r.sigma.cx},
                {"cy_px", r.sigma.cy},
                {"distortion", r.sigma.distortion}};
  j["flags"] = r.flags;
  j["flag_names"] = r.flag_names;
  j["rounds"] = r.rounds;
  for (const auto& im : r.images) {
    nlohmann::json e{{"image", im.image}, {"used", im.used}, {"points", im.points}};
    if (im.rms_px) e["rms_px"] = *im.rms_px;
    if (!im.reason.empty()) e["reason"] = im.reason;
    if (im.used) {
      e["rvec"] = {im.rvec.x(), im.rvec.y(), im.rvec.z()};
      e["tvec_m"] = {im.tvec.x(), im.tvec.y(), im.tvec.z()};
    }
    j["images"].push_back(e);
  }
  return j;
}

void run_camera(const CameraArgs& args, const CLI::App& verb) {
  Diagnostics diagnostics;
  camera::CalibrationSettings settings;
  if (!args.config.empty()) settings = camera::read_calibration_settings(args.config, diagnostics);
  settings.fix_aspect_ratio = settings.fix_aspect_ratio || args.fix_aspect_ratio;
  settings.zero_tangent = settings.zero_tangent || args.zero_tangent;
  settings.fix_principal_point = settings.fix_principal_point || args.fix_principal_point;
  settings.flip_vertical = settings.flip_vertical || args.flip;
  if (!args.guess.empty()) settings.intrinsics_guess = camera::read_camera_file(args.guess).intrinsics;
  const auto device = args.device.resolve();
  if (args.output.empty() && !device)
    throw InputError("-o", "no output given: pass -o camera.yaml and/or --device ID|FILE");
  // Refuse an existing output before the (long) run rather than after it.
  if (!args.output.empty() && !args.force && fs::exists(args.output))
    throw InputError(args.output, "exists already; pass --force to replace it");

  nlohmann::json run_settings = {{"capture", args.capture},
                                 {"fix_aspect_ratio", settings.fix_aspect_ratio},
                                 {"zero_tangent", settings.zero_tangent},
                                 {"fix_principal_point", settings.fix_principal_point},
                                 {"flip_vertical", settings.flip_vertical},
                                 {"distortion_coefficients", settings.distortion_coefficients}};
  if (!args.config.empty()) run_settings["config"] = args.config;
  std::vector<fs::path> inputs{args.capture};
  if (!args.config.empty()) inputs.emplace_back(args.config);
  ProgressLine progress;
  const auto report = progress.callback();
  run_calibration(device, "camera", run_settings, inputs, diagnostics, [&] {
    // Each photo's outcome is in the table below; while it runs, only the count.
    const auto result =
        camera::calibrate_camera(fs::path(args.capture), settings, diagnostics,
                                 [&](const camera::CalibrationImage&, std::size_t done, std::size_t total) {
                                   if (report)
                                     report("board detection", static_cast<int>(done), static_cast<int>(total));
                                 });
    fmt::print("camera calibration of {} ({} {}x{})\n{}", args.capture, camera::to_string(result.board.type),
               result.board.cols, result.board.rows, camera::describe(result));
    if (!args.output.empty()) {
      camera::write_camera_file(args.output, result, args.force);
      fmt::print("wrote {}\n", args.output);
    }
    if (!args.json.empty()) {
      store::Provenance provenance = provenance_of(verb).input("capture", args.capture);
      if (!args.config.empty()) provenance.input("config", args.config);
      if (device) add_device(provenance, *device);
      write_json(args.json, to_json(result), provenance);
    }
    CalibrationOutcome outcome;
    outcome.residuals = {{"rms_px", result.rms_px},
                         {"photos_used", result.used_count()},
                         {"photos", result.images.size()},
                         {"flags", result.flag_names}};
    for (const auto& [image, reason] : result.rejected()) outcome.residuals["rejected"].push_back({image, reason});
    const auto pc = camera::profile_camera(result);
    outcome.apply = [pc](store::DeviceProfile& current) {
      current.camera = store::CameraCalibrationInfo{pc.intrinsics, pc.rms_px, pc.principal_point_sigma_px};
    };
    return outcome;
  });
}

}  // namespace

void add_calibrate_camera_command(CLI::App& calibrate) {
  auto args = std::make_shared<CameraArgs>();
  auto* cmd = calibrate.add_subcommand("camera",
                                       "intrinsic camera calibration from photos of a board "
                                       "(camera-calibration capture); writes an OpenCV camera YAML");
  cmd->add_option("capture", args->capture, "capture folder with shots.csv, images/ and board.yaml")->required();
  cmd->add_option("--config", args->config,
                  "settings: OpenCV calibration sample XML/YAML (<Settings>) or antpose "
                  "YAML; its board overrides board.yaml");
  cmd->add_flag("--fix-aspect-ratio", args->fix_aspect_ratio, "keep fx/fy fixed (1, or the config's/guess's ratio)");
  cmd->add_flag("--zero-tangent", args->zero_tangent, "assume zero tangential distortion (p1 = p2 = 0)");
  cmd->add_flag("--fix-principal-point", args->fix_principal_point,
                "keep the principal point at the image centre (or the guess's)");
  cmd->add_option("--intrinsics-guess", args->guess, "camera YAML to start from (CALIB_USE_INTRINSIC_GUESS)");
  cmd->add_flag("--flip", args->flip, "flip the photos around the horizontal axis before detection");
  cmd->add_option("-o,--output", args->output, "camera YAML to write (OpenCV FileStorage; required without --device)");
  args->device.add_to(*cmd);
  cmd->add_flag("--force", args->force, "replace an existing output file");
  add_json_option(cmd, args->json, "also write the result");
  cmd->callback([args, cmd] { run_camera(*args, *cmd); });
}

}  // namespace antpose::cli
