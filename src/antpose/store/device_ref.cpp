#include "antpose/store/device_ref.hpp"

#include <fmt/format.h>

#include "antpose/store/device_db.hpp"

namespace antpose::store {
namespace fs = std::filesystem;

namespace {

bool yaml_name(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".yaml" || ext == ".yml";
}

// A path written with a folder part ("./x", "dir/x") can only mean a file.
bool explicit_path(const std::string& arg) { return arg.find('/') != std::string::npos; }

}  // namespace

DeviceRef resolve_device_ref(const std::string& arg, const std::optional<fs::path>& db, bool create) {
  if (arg.empty()) throw InputError("--device", "empty; expected a device id from the database or a device YAML file");
  const fs::path path(arg);
  const bool is_file = fs::is_regular_file(path);
  if (yaml_name(path) || explicit_path(arg)) {
    if (!is_file && create && !fs::exists(path)) {
      DeviceProfile fresh;  // a new profile file, named after the file
      fresh.id = path.stem().string();
      return {fresh, path, std::nullopt};
    }
    if (!is_file)
      throw InputError(path, "--device: no such device file (a name ending in .yaml/.yml or containing '/' is read as a "
                             "file, not a database id)");
    return {read_device_profile(path), path, std::nullopt};
  }
  // A bare name: a database id, unless it only exists as a file.
  const fs::path db_file = DeviceDb::resolve_path(db);
  const bool db_exists = fs::exists(db_file);
  if (is_file) {
    if (db_exists && DeviceDb(db_file, DeviceDb::Access::kReadOnly).has_device(arg))
      throw InputError(path, fmt::format("--device '{}' is ambiguous: both a file in the current folder and a device id "
                                         "in {}; write ./{} for the file or use the id from another folder",
                                         arg, db_file.string(), arg));
    return {read_device_profile(path), path, std::nullopt};
  }
  if (create) {
    const DeviceDb database(db_file);
    if (database.has_device(arg)) return {database.profile(arg), std::nullopt, db_file};
    DeviceProfile fresh;
    fresh.id = arg;
    return {fresh, std::nullopt, db_file};
  }
  if (!db_exists)
    throw InputError(db_file, fmt::format("--device '{}' is neither a file nor a device id: the device database does not "
                                          "exist yet (import a profile with 'antpose device import FILE.yaml')",
                                          arg));
  return {DeviceDb(db_file, DeviceDb::Access::kReadOnly).profile(arg), std::nullopt, db_file};
}

DeviceProfile resolve_device(const std::string& arg, const std::optional<fs::path>& db) {
  return resolve_device_ref(arg, db).profile;
}

std::int64_t store_calibration(const DeviceRef& device, CalibrationRun run,
                               const std::function<void(DeviceProfile&)>& apply) {
  if (device.database) {
    if (run.device_id.empty()) run.device_id = device.profile.id;
    DeviceDb db(*device.database);
    return db.record_run(std::move(run), [&](DeviceProfile current) {
      apply(current);
      return current;
    });
  }
  if (device.file && run.status == "ok") {
    // Re-read: the file may have changed since the command started.
    DeviceProfile current = fs::exists(*device.file) ? read_device_profile(*device.file) : device.profile;
    apply(current);
    write_device_profile(current, *device.file);
  }
  return 0;
}

}  // namespace antpose::store
