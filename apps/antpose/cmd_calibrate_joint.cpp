// antpose calibrate joint: camera–IMU rotation R_device_camera and time offset from photos of a
// board (docs/camera-imu.md).
//   antpose calibrate joint CAPTURE [--camera camera.yaml] [--device ID|FILE] [--solver reference-free|thesis|both]
//       [--method antpose[,antpose-smoother,...]] [--param k=v ...] [--time-offset S]
//       [--fixed-time-offset] [--json OUT]
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/calibration/board_reference.hpp"
#include "antpose/calibration/camera_imu.hpp"
#include "antpose/camera/board.hpp"
#include "antpose/camera/board_pose.hpp"
#include "antpose/camera/calibrate_camera.hpp"
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/io/report_text.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/orientation/estimator.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "option_checks.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "device_calibration.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct JointArgs {
  std::string capture, camera, json;
  DeviceOption device;
  std::string solver = "both";
  std::string orientation_methods = "antpose";
  std::vector<std::string> params;
  double time_offset = 0.0;
  bool fixed_time_offset = false;
};


nlohmann::json table_json(const calibration::AngleErrorTable& t) {
  auto row = [](const calibration::AngleErrorRow& r) {
    nlohmann::json j{{"placement", r.placement},
                     {"photos", r.photos},
                     {"g_lines", r.g_lines},
                     {"n_lines", r.n_lines},
                     {"n_lines_steep", r.n_lines_steep}};
    if (!std::isnan(r.downtilt_error_deg)) j["downtilt_error_deg"] = r.downtilt_error_deg;
    if (!std::isnan(r.azimuth_error_deg)) j["azimuth_error_deg"] = r.azimuth_error_deg;
    return j;
  };
  nlohmann::json j{{"method", t.method}, {"matrix", t.matrix}, {"overall", row(t.overall)}};
  for (const auto& r : t.placements) j["placements"].push_back(row(r));
  return j;
}

// Intrinsics (and their principal-point σ when known): --camera, else the device profile's.
store::CameraCalibrationInfo joint_intrinsics(const JointArgs& args, const std::optional<store::DeviceRef>& device) {
  if (!args.camera.empty()) {
    const auto file = camera::read_camera_file(args.camera);
    return {file.intrinsics, file.rms_px, file.principal_point_sigma_px};
  }
  if (device && device->profile.camera) return *device->profile.camera;
  throw InputError(
      device ? (device->file ? *device->file : fs::path("--device " + device->profile.id)) : fs::path("--camera"),
      "no camera intrinsics: pass --camera camera.yaml, or a --device whose profile has a camera section "
      "(antpose calibrate camera --device)");
}

CalibrationOutcome joint_calibration(const JointArgs& args, const CLI::App& verb,
                                     const std::optional<store::DeviceRef>& device,
                                     const std::vector<std::string>& methods, Diagnostics& diagnostics) {
  Capture capture = read_capture(args.capture, diagnostics);
  const bool imu_calibrated = device && device->profile.has_imu;
  if (imu_calibrated) {
    imu::apply(device->profile.imu, capture);
    fmt::print("IMU calibration of device '{}' applied\n", device->profile.id);
  } else {
    diagnostics.warn(args.capture, 0,
                     "no IMU calibration applied (no --device, or its profile has no imu section): the gyroscope's "
                     "scale and misalignment errors are estimated with the photos within a phone's tolerances, and "
                     "what remains unknown of them widens the σ of R_device_camera (a few tenths of a degree) and of "
                     "the time offset; run 'antpose calibrate imu --device' first");
  }
  const fs::path root = args.capture;
  const auto board = camera::read_board(capture_file(root, "board.yaml"));
  const auto camera_info = joint_intrinsics(args, device);
  const auto& intrinsics = camera_info.intrinsics;
  const auto placements = calibration::shot_placements(capture);
  std::optional<calibration::BoardReference> reference;
  for (const char* name : {"board_reference.csv", "board_reference.csv.gz"})
    if (fs::exists(root / name)) {
      reference = calibration::read_board_reference(capture_file(root, name));
      calibration::check_board_reference(*reference, placements);
      break;
    }
  if (args.solver == "thesis" && !reference)
    throw InputError(root / "board_reference.csv", "missing: the thesis method needs the level/compass angles");

  // The stages take up to a minute: each is reported as it ends (progress.hpp).
  ProgressLine progress;
  const auto stage = [report = progress.callback()](const char* name, std::size_t done, std::size_t total) {
    if (report) report(name, static_cast<int>(done), static_cast<int>(total));
  };
  stage("board poses", 0, 1);
  const auto poses = camera::board_poses(capture, board, intrinsics, diagnostics);
  stage("board poses", 1, 1);
  const auto photos = calibration::photo_observations(capture, poses);
  fmt::print("{} of {} photos with a board pose\n", photos.size(), capture.shots.size());

  const auto data = orientation::imu_data_from_capture(capture, diagnostics);
  const auto params = orientation::parse_params(args.params);
  std::vector<orientation::OrientationTrack> tracks;
  stage("phone orientation", 0, methods.size());
  for (const auto& m : methods) {
    tracks.push_back(orientation::make_estimator(m, params)->estimate(data, diagnostics));
    stage("phone orientation", tracks.size(), methods.size());
  }

  nlohmann::json j;
  j["capture"] = args.capture;
  std::optional<double> offset_for_thesis;
  CalibrationOutcome outcome;
  std::optional<store::CameraImuCalibration> stored;
  if (args.solver != "thesis") {
    calibration::ReferenceFreeOptions options;
    options.time_offset_start_s = args.time_offset;
    options.estimate_time_offset = !args.fixed_time_offset;
    options.gyro_trapezoid = params.count("gyro_trapezoid") && params.at("gyro_trapezoid") != 0.0;
    if (!imu_calibrated) options.assume_uncalibrated_gyroscope();
    if (camera_info.principal_point_sigma_px)
      options.camera_rotation_sigma_rad =
          calibration::principal_point_rotation_sigma(intrinsics, *camera_info.principal_point_sigma_px);
    else
      fmt::print("(the intrinsics give no principal-point σ: the rotation σ below leaves out their error)\n");
    stage("camera–IMU rotation", 0, 1);
    const auto r = calibration::calibrate_reference_free(photos, data.gyroscope, tracks.front(), options, diagnostics,
                                                         reference ? &*reference : nullptr);
    stage("camera–IMU rotation", 1, 1);
    offset_for_thesis = r.time_offset_s;
    stored = r.to_profile();
    outcome.residuals = {{"method", "reference-free"},
                         {"orientation", tracks.front().method},
                         {"variance_factor", r.variance_factor},
                         {"outliers", r.outliers.size()},
                         {"photos", r.residuals.size()}};
    outcome.residuals["gyroscope_calibrated"] = imu_calibrated;
    const Vec3 s = r.rotation_sigma_deg();
    const Vec3 e = log_so3(camera::nominal_R_device_camera().transpose() * r.R_device_camera);
    fmt::print("reference-free (orientation '{}'):\n", tracks.front().method);
    for (int k = 0; k < 3; ++k)
      fmt::print("  R_device_camera [{:9.6f} {:9.6f} {:9.6f}]\n", r.R_device_camera(k, 0), r.R_device_camera(k, 1),
                 r.R_device_camera(k, 2));
    fmt::print("  = nominal · exp(({:.3f}, {:.3f}, {:.3f})°), 1σ ({:.3f}, {:.3f}, {:.3f})° (device frame)\n",
               rad2deg(e.x()), rad2deg(e.y()), rad2deg(e.z()), s.x(), s.y(), s.z());
    if (r.time_offset_estimated && r.gyro_correction_estimated)
      fmt::print(
          "  time offset {:.1f} ± {:.1f} ms (IMU instant = shot t + offset; ± {:.1f} ms without the uncalibrated "
          "gyroscope's errors)\n",
          1e3 * r.time_offset_s, 1e3 * r.time_offset_sigma_s, 1e3 * r.time_offset_sigma_fit_s);
    else if (r.time_offset_estimated)
      fmt::print("  time offset {:.1f} ± {:.1f} ms (IMU instant = shot t + offset)\n", 1e3 * r.time_offset_s,
                 1e3 * r.time_offset_sigma_s);
    else
      fmt::print("  time offset fixed at {:.1f} ms\n", 1e3 * r.time_offset_s);
    fmt::print("  {:<28} {:<16} {:>8} {:>8} {:>9}\n", "photo", "placement", "angle°", "tilt°", "heading°");
    for (const auto& p : r.residuals)
      fmt::print("  {:<28} {:<16} {:8.3f} {:8.3f} {:9.3f}{}\n", p.name, p.placement, p.angle_deg, p.tilt_deg,
                 p.heading_deg, p.outlier ? "  outlier" : "");
    if (r.reference_check) fmt::print("{}", calibration::format_angle_error_table(*r.reference_check));
    nlohmann::json rf{{"orientation", tracks.front().method},
                      {"R_device_camera", io::matrix_rows_json(r.R_device_camera)},
                      {"rotation_sigma_deg", {s.x(), s.y(), s.z()}},
                      {"time_offset_s", r.time_offset_s},
                      {"time_offset_estimated", r.time_offset_estimated},
                      {"variance_factor", r.variance_factor},
                      {"warnings", r.warnings}};
    if (r.time_offset_estimated) rf["time_offset_sigma_s"] = r.time_offset_sigma_s;
    if (r.gyro_correction_estimated) {
      if (r.time_offset_estimated) rf["time_offset_sigma_fit_s"] = r.time_offset_sigma_fit_s;
      rf["gyro_correction"] = io::matrix_rows_json(r.gyro_correction);
      rf["gyro_correction_sigma"] = io::matrix_rows_json(r.gyro_correction_sigma);
    }
    for (const auto& p : r.residuals)
      rf["photos"].push_back({{"name", p.name},
                              {"placement", p.placement},
                              {"angle_deg", p.angle_deg},
                              {"tilt_deg", p.tilt_deg},
                              {"heading_deg", p.heading_deg},
                              {"outlier", p.outlier}});
    for (const auto& b : r.boards)
      rf["boards"].push_back(
          {{"placement", b.placement},
           {"R_world_board", io::matrix_rows_json(b.R_world_board)},
           {"photos", b.photos},
           {"rms_deg", b.rms_deg},
           {"gyro_bias_deg_s",
            {rad2deg(b.gyro_bias_rad_s.x()), rad2deg(b.gyro_bias_rad_s.y()), rad2deg(b.gyro_bias_rad_s.z())}}});
    if (r.reference_check) rf["reference_check"] = table_json(*r.reference_check);
    j["reference_free"] = rf;
  }
  if (args.solver != "reference-free" && reference) {
    calibration::ThesisOptions options;
    options.time_offset_s = offset_for_thesis.value_or(args.time_offset);
    std::vector<calibration::ThesisCalibration> results;
    for (const auto& track : tracks)
      results.push_back(calibration::calibrate_thesis(photos, *reference, track, options, diagnostics));
    fmt::print("thesis method (time offset {:.1f} ms):\n{}", 1e3 * options.time_offset_s,
               calibration::format_thesis_tables(results));
    for (const auto& r : results)
      j["thesis"].push_back({{"orientation", r.method},
                             {"R_device_camera", io::matrix_rows_json(r.R_device_camera)},
                             {"rotation_sigma_deg",
                              {rad2deg(std::sqrt(r.covariance(0, 0))), rad2deg(std::sqrt(r.covariance(1, 1))),
                               rad2deg(std::sqrt(r.covariance(2, 2)))}},
                             {"optimised", table_json(r.optimised)},
                             {"nominal", table_json(r.nominal)}});
    if (!stored) {  // --solver thesis: the first orientation method's result is the device's
      const auto& r = results.front();
      stored = store::CameraImuCalibration{r.R_device_camera, r.covariance.diagonal().cwiseMax(0.0).cwiseSqrt(),
                                           options.time_offset_s, std::nullopt, "thesis"};
      outcome.residuals = {{"method", "thesis"},
                           {"orientation", r.method},
                           {"downtilt_error_deg", r.optimised.overall.downtilt_error_deg},
                           {"azimuth_error_deg", r.optimised.overall.azimuth_error_deg}};
    }
  }
  if (!args.json.empty()) {
    store::Provenance provenance = provenance_of(verb).input("capture", args.capture);
    if (!args.camera.empty()) provenance.input("camera", args.camera);
    if (device) add_device(provenance, *device);
    provenance.site = capture.site;
    write_json(args.json, j, provenance);
  }
  if (!stored) throw MeasurementError("camera–IMU calibration: no method produced a result");
  outcome.apply = [c = *stored](store::DeviceProfile& current) { current.camera_imu = c; };
  return outcome;
}

void run_joint(const JointArgs& args, const CLI::App& verb) {
  const auto methods = split_list(args.orientation_methods);
  const auto device = args.device.resolve();
  Diagnostics diagnostics;
  nlohmann::json settings = {{"capture", args.capture},
                             {"solver", args.solver},
                             {"orientation_method", args.orientation_methods},
                             {"params", args.params},
                             {"time_offset_start_s", args.time_offset},
                             {"fixed_time_offset", args.fixed_time_offset}};
  if (!args.camera.empty()) settings["camera"] = args.camera;
  std::vector<fs::path> inputs{args.capture};
  if (!args.camera.empty()) inputs.emplace_back(args.camera);
  run_calibration(device, "camera-imu", settings, inputs, diagnostics,
                  [&] { return joint_calibration(args, verb, device, methods, diagnostics); });
}

}  // namespace

void add_calibrate_joint_command(CLI::App& calibrate) {
  auto args = std::make_shared<JointArgs>();
  auto* cmd = calibrate.add_subcommand("joint",
                                       "camera–IMU rotation R_device_camera and time offset from photos of a "
                                       "board (joint-calibration capture with a placement column)");
  cmd->add_option("capture", args->capture,
                  "capture folder: sensors, shots.csv with placement, images/, board.yaml, "
                  "optional board_reference.csv")
      ->required();
  cmd->add_option("--camera", args->camera, "camera YAML with the intrinsics (default: the --device profile's)");
  args->device.add_to(*cmd);
  cmd->add_option("--solver", args->solver,
                  "calibration solver: reference-free, thesis (needs board_reference.csv) "
                  "or both")
      ->capture_default_str()
      ->check(CLI::IsMember({"reference-free", "thesis", "both"}));
  add_orientation_method_option(*cmd, args->orientation_methods,
                                "orientation methods; the first serves the reference-free solver, the thesis "
                                "tables list each",
                                {.several = true,
                                 .other_names = {"reference-free", "thesis", "both"},
                                 .other_hint = "the calibration solver is --solver"})
      ->capture_default_str();
  add_renamed_option(*cmd, "--orientation", "--method");
  cmd->add_option("--param", args->params, "orientation parameter name=value (repeatable)");
  const calibration::ReferenceFreeOptions defaults;
  cmd->add_option("--time-offset", args->time_offset,
                  "start (or fixed) camera–IMU time offset, s, within the estimate's search bracket")
      ->capture_default_str()
      ->check(finite_within(defaults.time_offset_min_s, defaults.time_offset_max_s, "s"));
  cmd->add_flag("--fixed-time-offset", args->fixed_time_offset, "do not estimate the time offset");
  add_json_option(cmd, args->json, "also write the result");
  cmd->callback([args, cmd] { run_joint(*args, *cmd); });
}

}  // namespace antpose::cli
