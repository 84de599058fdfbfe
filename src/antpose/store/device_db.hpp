// The device database: one SQLite file holding every phone's current profile and the history of
// its calibration runs (docs/devices.md).
//
// Location: --db PATH > $ANTPOSE_DB > $XDG_DATA_HOME/antpose/devices.sqlite >
// ~/.local/share/antpose/devices.sqlite (XDG Base Directory spec); folders are created.
//
// Schema (PRAGMA user_version = kSchemaVersion, PRAGMA application_id = kApplicationId):
//   devices(id TEXT PRIMARY KEY, model TEXT, created_utc TEXT, updated_utc TEXT, profile_yaml TEXT)
//   calibration_runs(run_id INTEGER PRIMARY KEY, device_id TEXT → devices.id, kind TEXT
//     (imu | camera | camera-imu | import), started_utc TEXT, finished_utc TEXT, status TEXT
//     (ok | failed), settings_json TEXT, inputs_json TEXT ([{path, sha256, size}]),
//     residuals_json TEXT, profile_yaml TEXT (the device's profile after the run), message TEXT)
// Times are ISO 8601 UTC with milliseconds ("2026-11-24T02:10:01.123Z").
//
// Concurrency: WAL journal (readers never block the writer), busy_timeout, every write in
// BEGIN IMMEDIATE (the write lock is taken up front, so two writers cannot deadlock upgrading
// read locks) and retried with exponential backoff while SQLite answers SQLITE_BUSY. Use one
// DeviceDb per thread (a connection is not shared); any number of processes may write at once.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/store/content_hash.hpp"
#include "antpose/store/device_profile.hpp"

struct sqlite3;

namespace antpose::store {

struct CalibrationRun {
  std::int64_t run_id = 0;      // assigned by record_run
  std::string device_id;
  std::string kind;             // imu | camera | camera-imu | import
  std::string started_utc, finished_utc;
  std::string status = "ok";    // ok | failed
  nlohmann::json settings = nlohmann::json::object();
  nlohmann::json inputs = nlohmann::json::array();  // [{path, sha256, size}]
  nlohmann::json residuals = nlohmann::json::object();
  std::string profile_yaml;     // filled by record_run: the current profile after the run
  std::string message;
};

struct DeviceSummary {
  std::string id, model, created_utc, updated_utc;
  std::optional<std::string> last_calibration_utc;  // finished_utc of the latest ok run (not import)
  std::vector<std::string> calibrated;              // "imu", "camera", "camera-imu" present in the profile
};

class DeviceDb {
 public:
  static constexpr int kSchemaVersion = 1;
  static constexpr std::int32_t kApplicationId = 0x414e5450;  // "ANTP"

  /// The file to use: `db` when given, else the environment chain above.
  static std::filesystem::path resolve_path(const std::optional<std::filesystem::path>& db);

  /// kReadWrite creates or migrates the file and refuses a damaged one (nothing is written into
  /// it); kReadOnly neither creates nor changes anything, so that listing and reading work in a
  /// folder without write permission.
  enum class Access { kReadWrite, kReadOnly };

  /// Opens the database. InputError naming the file when it is not an SQLite file, corrupt
  /// (kReadWrite checks every page first), another application's database, of a newer schema,
  /// or missing (kReadOnly).
  explicit DeviceDb(const std::filesystem::path& file, Access access = Access::kReadWrite);
  ~DeviceDb();
  DeviceDb(const DeviceDb&) = delete;
  DeviceDb& operator=(const DeviceDb&) = delete;

  const std::filesystem::path& path() const { return file_; }

  std::vector<DeviceSummary> list_devices() const;
  bool has_device(const std::string& id) const;
  /// Current profile; InputError listing the known ids when `id` is missing.
  DeviceProfile profile(const std::string& id) const;
  /// Runs of a device, oldest first.
  std::vector<CalibrationRun> history(const std::string& id) const;

  /// One transaction: creates the device when new (with `profile_after`'s model), inserts the
  /// run and, when run.status is "ok", makes `profile_after` the current profile. A failed run
  /// keeps the previous profile untouched (and stores it as the run's profile_yaml). Returns the
  /// run id.
  std::int64_t record_run(CalibrationRun run, const DeviceProfile& profile_after);
  /// Same, with the new profile computed inside the transaction from the profile current at that
  /// moment (a fresh id/model-only profile for a new device): a calibration that changes one
  /// section then keeps sections another process stored meanwhile (no lost update). `update` is
  /// not called for a failed run.
  std::int64_t record_run(CalibrationRun run, const std::function<DeviceProfile(DeviceProfile current)>& update);
  /// Imports a YAML profile as a run of kind "import" (inputs = the file and its hash). `id` and
  /// `model` override the file's device.id / device.model; InputError when no id is known.
  std::int64_t import_profile(const std::filesystem::path& yaml, const std::optional<std::string>& id,
                              const std::optional<std::string>& model);
  /// Writes the current profile as YAML (atomically). InputError when `file` exists and !force.
  void export_profile(const std::string& id, const std::filesystem::path& file, bool force) const;
  /// Deletes a device and its runs; InputError when missing.
  void remove_device(const std::string& id);

  /// "ok" or SQLite's list of problems (PRAGMA integrity_check).
  std::string integrity_check() const;
  int schema_version() const;

 private:
  void open(Access access);
  void migrate();
  void require_intact() const;
  [[noreturn]] void fail_missing(const std::string& id) const;

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

}  // namespace antpose::store
