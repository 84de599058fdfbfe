// antpose measure: the non-contact measurement (docs/non-contact.md).
//   antpose measure CAPTURE --device ID|FILE [--model MESH|BUILTIN [--model-box BOX] [--model-units m|mm]]
//       --roi IMAGE:x,y,w,h [--roi ...] [--json OUT] [--report DIR [--force]]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "antpose/camera/board.hpp"
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/measure/device_setup.hpp"
#include "antpose/measure/non_contact.hpp"
#include "antpose/measure/report.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/orientation/estimator.hpp"
#include "antpose/store/device_ref.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "option_checks.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "usable.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct MeasureArgs {
  std::string capture, device, model_units = "m", json, report, orientation = "antpose-smoother";
  double max_sigma_deg = kDefaultMaxSigmaDeg;
  std::optional<std::string> db;
  std::vector<std::string> rois, models, model_boxes;
  bool model_canonical = false, force = false;
};

// A built-in panel name, or a mesh file with (optionally) its box file.
model::AntennaModel load_model(const std::string& name, const std::string& box, const MeasureArgs& a) {
  if (!fs::exists(name) && model::is_builtin_panel(name)) {
    if (!box.empty()) throw InputError(box, "--model-box: '" + name + "' is a built-in panel, which has its box");
    return model::builtin_panel(name);
  }
  if (!fs::exists(name)) {
    std::string list;
    for (const auto& n : model::builtin_panel_names()) list += (list.empty() ? "" : ", ") + n;
    throw InputError(name, "--model: no such file, and not a built-in panel (" + list +
                               ", or any datasheet box panel-<h>x<w>x<d> in mm)");
  }
  model::Units units = model::Units::kMetres;
  if (a.model_units == "mm")
    units = model::Units::kMillimetres;
  else if (a.model_units != "m")
    throw InputError("--model-units", fmt::format("'{}' is not m or mm", a.model_units));
  return model::load_antenna_model(name, box.empty() ? std::nullopt : std::optional<fs::path>(box), units,
                                   a.model_canonical);
}

// --model once for every antenna or once per --roi; --model-box, when given, pairs with them.
std::vector<model::AntennaModel> load_models(const MeasureArgs& a) {
  if (!a.model_boxes.empty() && a.model_boxes.size() != a.models.size())
    throw InputError("--model-box", fmt::format("{} box files for {} models: give one per --model, in the same order",
                                                a.model_boxes.size(), a.models.size()));
  std::vector<model::AntennaModel> models;
  for (std::size_t i = 0; i < a.models.size(); ++i)
    models.push_back(load_model(a.models[i], a.model_boxes.empty() ? std::string() : a.model_boxes[i], a));
  return models;
}

measure::NonContactSetup setup_from(const MeasureArgs& a, const store::DeviceProfile& device, const fs::path& where) {
  measure::NonContactSetup s = measure::device_setup(device, where);
  s.board = camera::read_board(capture_file(a.capture, "board.yaml"));
  s.models = load_models(a);
  for (const auto& r : a.rois) s.rois.push_back(measure::parse_roi(r));
  return s;
}

std::string cell(const std::optional<double>& v, const std::optional<double>& sigma, int digits) {
  if (!v) return "undefined";
  return fmt::format("{:.{}f} ± {:.{}f}", rad2deg(*v), digits, rad2deg(sigma.value_or(0.0)), digits);
}

void print_table(const measure::NonContactResult& r) {
  fmt::print(
      "{} photos, board found in {}, board attitude from {}; camera poses {:.2f} px (board) / {:.2f} px "
      "(scene, {} tracks)\n",
      r.photos.size(), r.posed.size(), r.board.used, r.poses.board_rms_px, r.poses.scene_rms_px, r.poses.tracks);
  if (r.site) fmt::print("declination {:.2f}° (WMM2025, east positive)\n", rad2deg(r.site->declination));
  fmt::print("{:>3}  {:<22} {:>16} {:>16} {:>14} {:>14} {:>8} {:>7}\n", "#", "photo", "azimuth mag °", "azimuth true °",
             "downtilt °", "roll °", "fit mm", "points");
  for (std::size_t k = 0; k < r.antennas.size(); ++k) {
    const auto& m = r.antennas[k];
    const auto photo = fs::path(m.roi.image).filename().string();
    if (m.error) {
      fmt::print("{:>3}  {:<22} FAILED: {}\n", k + 1, photo, *m.error);
      continue;
    }
    const auto& a = m.attitude;
    fmt::print("{:>3}  {:<22} {:>16} {:>16} {:>14} {:>14} {:>8.1f} {:>7}\n", k + 1, photo,
               cell(a.magnetic.azimuth, a.sigma.azimuth, 2),
               r.site ? cell(a.azimuth_true, a.azimuth_true_sigma, 2) : std::string("no site"),
               cell(a.magnetic.downtilt, a.sigma.downtilt, 2), cell(a.magnetic.roll, a.sigma.roll, 2),
               1e3 * m.fit_rmse_m, m.region.cloud_board.size());
  }
}

// 3 when no antenna was measured; 4 when one failed or has an angle that is not usable (each said
// on stderr); 0 otherwise.
int exit_status(const measure::NonContactResult& r, double max_sigma_deg) {
  std::size_t failed = 0, unusable = 0;
  for (std::size_t k = 0; k < r.antennas.size(); ++k) {
    const auto& m = r.antennas[k];
    if (m.error) {
      ++failed;
      continue;
    }
    const auto& a = m.attitude;
    const bool truth = a.azimuth_true.has_value();
    const std::string why =
        unusable_reason({{truth ? "azimuth" : "magnetic azimuth", truth ? a.azimuth_true : a.magnetic.azimuth,
                          truth ? a.azimuth_true_sigma : a.sigma.azimuth},
                         {"downtilt", a.magnetic.downtilt, a.sigma.downtilt},
                         {"roll", a.magnetic.roll, a.sigma.roll}},
                        max_sigma_deg);
    if (!why.empty()) {
      ++unusable;
      fmt::print(stderr, "warning: antenna {} is not usable: {}\n", k + 1, why);
    }
  }
  if (failed == r.antennas.size()) return kExitUnsupported;
  return failed + unusable > 0 ? kExitPartial : kExitOk;
}

// The capture, the device, and the mesh and box files among the models (a built-in panel is in
// the options by name).
store::Provenance measure_provenance(const MeasureArgs& a, const CLI::App& verb, const store::DeviceRef& device,
                                     const Capture& capture) {
  store::Provenance p = provenance_of(verb).input("capture", a.capture);
  add_device(p, device);
  for (const auto& files : {a.models, a.model_boxes})
    for (const auto& file : files)
      if (fs::is_regular_file(file)) p.input("model", file);
  p.site = capture.site;
  return p;
}

int run_measure(const MeasureArgs& a, const CLI::App& verb) {
  if (a.rois.empty())
    throw InputError("--roi", "at least one --roi IMAGE:x,y,w,h is needed (the antenna in one photo)");
  const auto ref = store::resolve_device_ref(a.device, a.db ? std::optional<fs::path>(*a.db) : std::nullopt);
  const fs::path where = ref.file ? *ref.file : fs::path("--device " + ref.profile.id);
  const auto setup = setup_from(a, ref.profile, where);
  if (!a.report.empty() && fs::exists(a.report) && !fs::is_empty(a.report) && !a.force)
    throw InputError(a.report, "already exists and is not empty; choose a new report folder or add --force");

  Diagnostics diagnostics;
  Capture capture = read_capture(a.capture, diagnostics);
  if (ref.profile.has_imu) {
    imu::apply(ref.profile.imu, capture);
  } else {
    diagnostics.warn(where, 0, kNoImuCalibrationWarning);
  }

  measure::NonContactOptions options;
  options.world.orientation = a.orientation;
  ProgressLine progress;
  options.progress = progress.callback();
  const auto result = measure::measure_non_contact(capture, setup, options, diagnostics);
  print_warnings(diagnostics);
  print_table(result);
  Diagnostics result_warnings;
  for (const auto& w : result.warnings) result_warnings.warn(w);
  for (std::size_t k = 0; k < result.antennas.size(); ++k) {
    const auto& m = result.antennas[k];
    if (!m.error)  // the board's warnings are the capture's, printed once
      for (const auto& w : m.attitude.warnings)
        if (std::find(result.warnings.begin(), result.warnings.end(), w) == result.warnings.end())
          result_warnings.warn(fmt::format("antenna {}: {}", k + 1, w));
    for (const auto& w : m.warnings) result_warnings.warn(fmt::format("antenna {}: {}", k + 1, w));
  }
  print_warnings(result_warnings);
  if (!a.json.empty() || !a.report.empty()) {  // hashing the photos costs a moment: only when kept
    const store::Provenance provenance = measure_provenance(a, verb, ref, capture);
    write_json(a.json, measure::to_json(result), provenance);
    if (!a.report.empty()) {
      measure::write_report(a.report, capture, setup, result, provenance, a.force);
      fmt::print("report: {}\n", (fs::path(a.report) / "index.html").string());
    }
  }
  return exit_status(result, a.max_sigma_deg);
}

}  // namespace

void add_measure_command(CLI::App& app) {
  auto a = std::make_shared<MeasureArgs>();
  auto* cmd = app.add_subcommand("measure", "antenna azimuth, downtilt and roll from photos with the board in view");
  cmd->add_option("capture", a->capture, "native capture folder (photos, shots.csv, board.yaml, IMU streams)")
      ->required();
  cmd->add_option("--device", a->device,
                  "the phone: a device id in the database or a profile YAML file (intrinsics, "
                  "camera-IMU rotation, IMU calibration)")
      ->required();
  cmd->add_option("--db", a->db, "device database (default as 'antpose device')");
  cmd->add_option("--model", a->models,
                  "antenna model: an OBJ/PLY mesh or a built-in panel name, once for all antennas or once per --roi; "
                  "without it the model-free face fit");
  cmd->add_option("--model-box", a->model_boxes, "the mesh's A–H box file (fixes the antenna frame), one per --model");
  cmd->add_option("--model-units", a->model_units, "units of the mesh and box: m or mm")->capture_default_str();
  cmd->add_flag("--model-canonical", a->model_canonical, "the mesh is already in the antenna frame (no box file)");
  cmd->add_option(
         "--roi", a->rois,
         "IMAGE:x,y,w,h: the antenna's rectangle in one photo (px, on the photo shown upright); once per antenna")
      ->required();
  add_orientation_method_option(*cmd, a->orientation, "phone orientation method")->capture_default_str();
  add_renamed_option(*cmd, "--orientation", "--method");
  add_json_option(cmd, a->json, "write the result");
  cmd->add_option("--report", a->report, "write a report folder (HTML, overlays, PLY clouds)");
  cmd->add_flag("--force", a->force, "replace an existing report folder");
  add_max_sigma_option(cmd, a->max_sigma_deg);
  cmd->callback([a, cmd] {
    const int status = run_measure(*a, *cmd);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace antpose::cli
