// What the calibration verbs share for --device ID|FILE (docs/devices.md): resolving it, and
// storing each run with its inputs' hashes, settings and residuals, a failure included.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "antpose/core/error.hpp"
#include "antpose/store/device_ref.hpp"

namespace antpose::cli {

struct DeviceOption {
  std::optional<std::string> device, db;

  /// Adds --device and --db to a calibration verb.
  void add_to(CLI::App& cmd);
  /// The device (created when new), or nullopt without --device.
  std::optional<store::DeviceRef> resolve() const;
};

/// What a calibration changes in a profile, and its figures for the run record.
struct CalibrationOutcome {
  nlohmann::json residuals = nlohmann::json::object();
  std::function<void(store::DeviceProfile&)> apply;
};

/// Runs `calibrate`, then prints the warnings it left in `diagnostics` (also when it throws).
/// With a device, stores the run (store::store_calibration) of `kind` with `settings` and the
/// SHA-256 of every file of `inputs`, and prints where it went. An exception from `calibrate` is
/// stored as a failed run (database devices; the profile is kept) and rethrown.
void run_calibration(const std::optional<store::DeviceRef>& device, const std::string& kind,
                     const nlohmann::json& settings, const std::vector<std::filesystem::path>& inputs,
                     Diagnostics& diagnostics, const std::function<CalibrationOutcome()>& calibrate);

}  // namespace antpose::cli
