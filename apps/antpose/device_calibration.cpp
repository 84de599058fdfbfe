#include "device_calibration.hpp"

#include <fmt/format.h>

#include "commands.hpp"

namespace antpose::cli {

void DeviceOption::add_to(CLI::App& cmd) {
  cmd.add_option("--device", device,
                 "device: an id in the device database (created when new) or a profile YAML file; the result is "
                 "stored there with the run's history (docs/devices.md)");
  cmd.add_option("--db", db,
                 "device database (default: $ANTPOSE_DB, else $XDG_DATA_HOME/antpose/devices.sqlite, else "
                 "~/.local/share/antpose/devices.sqlite)");
}

std::optional<store::DeviceRef> DeviceOption::resolve() const {
  if (!device) return std::nullopt;
  return store::resolve_device_ref(*device, db ? std::optional<std::filesystem::path>(*db) : std::nullopt, true);
}

void run_calibration(const std::optional<store::DeviceRef>& device, const std::string& kind,
                     const nlohmann::json& settings, const std::vector<std::filesystem::path>& inputs,
                     Diagnostics& diagnostics, const std::function<CalibrationOutcome()>& calibrate) {
  store::CalibrationRun run;
  run.kind = kind;
  run.started_utc = store::utc_now();
  run.settings = settings;
  CalibrationOutcome outcome;
  try {
    if (device) {
      std::vector<store::InputFile> files;
      for (const auto& input : inputs)
        for (auto& f : store::hash_inputs(input)) files.push_back(std::move(f));
      run.inputs = store::to_json(files);
    }
    outcome = calibrate();
  } catch (const std::exception& e) {
    print_warnings(diagnostics);
    if (!device) throw;
    run.status = "failed";
    run.message = e.what();
    run.finished_utc = store::utc_now();
    if (device->database) {
      const auto id = store::store_calibration(*device, run, [](store::DeviceProfile&) {});
      fmt::print(stderr, "recorded failed run {} of device '{}' in {}; its profile was not changed\n", id,
                 device->profile.id, device->database->string());
    } else {
      fmt::print(stderr, "{} was not changed\n", device->file->string());
    }
    throw;
  }
  print_warnings(diagnostics);
  if (!device) return;
  run.residuals = outcome.residuals;
  run.finished_utc = store::utc_now();
  const auto id = store::store_calibration(*device, run, outcome.apply);
  if (device->database)
    fmt::print("recorded as run {} of device '{}' in {}\n", id, device->profile.id, device->database->string());
  else
    fmt::print("updated the {} section of {}\n", kind, device->file->string());
}

}  // namespace antpose::cli
