// Resolves a command's `--device ID|FILE` argument to a device profile.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "antpose/store/device_db.hpp"
#include "antpose/store/device_profile.hpp"

namespace antpose::store {

/// A command's device: its profile and where that lives.
struct DeviceRef {
  DeviceProfile profile;
  std::optional<std::filesystem::path> file;      // a YAML profile file, or
  std::optional<std::filesystem::path> database;  // a database record (key profile.id)
};

/// An existing file, or a name ending in .yaml/.yml, is read as a device YAML
/// (read_device_profile); anything else is a device id looked up in the database
/// (DeviceDb::resolve_path(db)). When `arg` is both an existing file and a database id the
/// choice is ambiguous and an InputError asks for "./NAME" or a rename. Missing file or id →
/// InputError saying what was tried (the known ids listed).
/// With `create` (calibration commands), a bare name that is neither a file nor a known id is a
/// new database device, and a missing .yaml file a new file device, each with an empty profile
/// (the database file is created when missing).
DeviceRef resolve_device_ref(const std::string& arg, const std::optional<std::filesystem::path>& db,
                             bool create = false);
DeviceProfile resolve_device(const std::string& arg, const std::optional<std::filesystem::path>& db);

/// Stores the outcome of a calibration run for a device (docs/devices.md):
///  - database: the run (settings, inputs, residuals, status) is recorded in one transaction with
///    the profile update, `apply` being made to the profile current at commit time (so sections
///    another process stored meanwhile are kept); a failed run leaves the profile unchanged;
///  - file: an ok run rewrites the file atomically with `apply` made to its current content; a
///    failed run leaves it untouched.
/// Returns the run id (database) or 0 (file).
std::int64_t store_calibration(const DeviceRef& device, CalibrationRun run,
                               const std::function<void(DeviceProfile&)>& apply);

}  // namespace antpose::store
