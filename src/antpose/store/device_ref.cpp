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

DeviceProfile resolve_device(const std::string& arg, const std::optional<fs::path>& db) {
  if (arg.empty()) throw InputError("--device", "empty; expected a device id from the database or a device YAML file");
  const fs::path path(arg);
  const bool is_file = fs::is_regular_file(path);
  if (yaml_name(path) || explicit_path(arg)) {
    if (!is_file)
      throw InputError(path, "--device: no such device file (a name ending in .yaml/.yml or containing '/' is read as a "
                             "file, not a database id)");
    return read_device_profile(path);
  }
  // A bare name: a database id, unless it only exists as a file.
  const fs::path db_file = DeviceDb::resolve_path(db);
  const bool db_exists = fs::exists(db_file);
  if (is_file) {
    if (db_exists && DeviceDb(db_file).has_device(arg))
      throw InputError(path, fmt::format("--device '{}' is ambiguous: both a file in the current folder and a device id "
                                         "in {}; write ./{} for the file or use the id from another folder",
                                         arg, db_file.string(), arg));
    return read_device_profile(path);
  }
  if (!db_exists)
    throw InputError(db_file, fmt::format("--device '{}' is neither a file nor a device id: the device database does not "
                                          "exist yet (import a profile with 'antpose device import FILE.yaml')",
                                          arg));
  return DeviceDb(db_file).profile(arg);
}

}  // namespace antpose::store
