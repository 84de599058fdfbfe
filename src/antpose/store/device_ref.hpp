// Resolves a command's `--device ID|FILE` argument to a device profile.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "antpose/store/device_profile.hpp"

namespace antpose::store {

/// An existing file, or a name ending in .yaml/.yml, is read as a device YAML
/// (read_device_profile); anything else is a device id looked up in the database
/// (DeviceDb::resolve_path(db)). When `arg` is both an existing file and a database id the
/// choice is ambiguous and an InputError asks for "./NAME" or a rename. Missing file or id →
/// InputError saying what was tried (the known ids listed).
DeviceProfile resolve_device(const std::string& arg, const std::optional<std::filesystem::path>& db);

}  // namespace antpose::store
