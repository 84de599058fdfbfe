#include "antpose/store/device_db.hpp"

#include <unistd.h>

#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <random>
#include <thread>

#include <fmt/format.h>

#include "antpose/io/text_file.hpp"

namespace antpose::store {
namespace fs = std::filesystem;

// ---- SQLite helpers -------------------------------------------------------------------------

namespace {

// Throws the error of the last call on `db`, naming the database file. Not-a-database and
// corruption are the user's input (exit status 2); anything else is an internal Error.
[[noreturn]] void throw_sqlite(sqlite3* db, int rc, const fs::path& file, const std::string& what) {
  const int primary = rc & 0xff;
  const std::string detail = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  if (primary == SQLITE_NOTADB)
    throw InputError(file, fmt::format("is not an antpose device database: not an SQLite file ({}). Use --db to name "
                                       "another file or move this one away",
                                       detail));
  if (primary == SQLITE_CORRUPT)
    throw InputError(file, fmt::format("the device database is corrupt ({}); restore it from a backup or re-import "
                                       "the device YAML files into a new database",
                                       detail));
  if (primary == SQLITE_CANTOPEN || primary == SQLITE_READONLY || primary == SQLITE_PERM)
    throw InputError(file, fmt::format("cannot open the device database for writing ({})", detail));
  throw Error(fmt::format("{}: SQLite error while {}: {}", file.string(), what, detail));
}

class Statement {
 public:
  Statement(sqlite3* db, const fs::path& file, const char* sql) : db_(db), file_(file) {
    const int rc = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr);
    if (rc != SQLITE_OK) throw_sqlite(db, rc, file, fmt::format("preparing '{}'", sql));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& text) {
    sqlite3_bind_text(stmt_, i, text.c_str(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& bind(int i, std::int64_t v) {
    sqlite3_bind_int64(stmt_, i, v);
    return *this;
  }
  /// True when a row is available; throws on errors (SQLITE_BUSY included: callers retry whole
  /// transactions, see with_write_transaction).
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw_sqlite(db_, rc, file_, "executing a statement");
  }
  std::string text(int col) const {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col)))
             : std::string();
  }
  bool is_null(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }

 private:
  sqlite3* db_;
  const fs::path& file_;
  sqlite3_stmt* stmt_ = nullptr;
};

bool is_busy(int rc) { return (rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED; }

// Runs `sql` (no results), returning the SQLite code so that callers can retry on BUSY.
int exec_rc(sqlite3* db, const char* sql) { return sqlite3_exec(db, sql, nullptr, nullptr, nullptr); }

void exec(sqlite3* db, const fs::path& file, const char* sql) {
  const int rc = exec_rc(db, sql);
  if (rc != SQLITE_OK) throw_sqlite(db, rc, file, fmt::format("executing '{}'", sql));
}

struct BusyError {};

// busy_timeout already waits inside SQLite; these retries cover the cases where SQLite returns
// BUSY at once (a WAL checkpoint or recovery in progress, a lock upgrade) — exponential backoff
// with jitter so that two waiting writers do not wake in lock step.
constexpr int kBusyTimeoutMs = 5000;
constexpr int kMaxAttempts = 12;

template <class F>
auto with_write_transaction(sqlite3* db, const fs::path& file, F&& body) {
  std::mt19937 jitter(std::random_device{}());
  int delay_ms = 5;
  for (int attempt = 1;; ++attempt) {
    const int rc = exec_rc(db, "BEGIN IMMEDIATE");
    if (rc == SQLITE_OK) {
      try {
        if constexpr (std::is_void_v<decltype(body())>) {
          body();
          const int c = exec_rc(db, "COMMIT");
          if (c != SQLITE_OK) throw_sqlite(db, c, file, "committing");
          return;
        } else {
          auto result = body();
          const int c = exec_rc(db, "COMMIT");
          if (c != SQLITE_OK) throw_sqlite(db, c, file, "committing");
          return result;
        }
      } catch (...) {
        exec_rc(db, "ROLLBACK");
        throw;
      }
    }
    if (!is_busy(rc) || attempt >= kMaxAttempts) throw_sqlite(db, rc, file, "starting a write transaction");
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms + static_cast<int>(jitter() % 10)));
    delay_ms = std::min(delay_ms * 2, 1000);
  }
}

void calibrated_sections(const DeviceProfile& p, std::vector<std::string>& out) {
  if (p.has_imu) out.push_back("imu");
  if (p.camera) out.push_back("camera");
  if (p.camera_imu) out.push_back("camera-imu");
}

bool valid_kind(const std::string& k) { return k == "imu" || k == "camera" || k == "camera-imu" || k == "import"; }

// The default profile of a device that has none yet: id and model only.
std::string empty_profile_yaml(const std::string& id, const std::string& model) {
  DeviceProfile p;
  p.id = id;
  p.model = model;
  return format_device_profile(p);
}

fs::path source_name(const fs::path& db, const std::string& id) { return fs::path(db.string() + ":" + id); }

}  // namespace

// ---- DeviceDb -------------------------------------------------------------------------------

fs::path DeviceDb::resolve_path(const std::optional<fs::path>& db) {
  if (db && !db->empty()) return *db;
  auto env = [](const char* name) -> std::optional<std::string> {
    const char* v = std::getenv(name);
    if (v && *v) return std::string(v);
    return std::nullopt;
  };
  if (const auto v = env("ANTPOSE_DB")) return *v;
  // XDG Base Directory: a relative $XDG_DATA_HOME is invalid and must be ignored.
  if (const auto v = env("XDG_DATA_HOME"); v && fs::path(*v).is_absolute()) return fs::path(*v) / "antpose" / "devices.sqlite";
  if (const auto home = env("HOME")) return fs::path(*home) / ".local" / "share" / "antpose" / "devices.sqlite";
  throw InputError("--db", "no device database given and neither $ANTPOSE_DB, $XDG_DATA_HOME nor $HOME is set; pass "
                           "--db PATH");
}

namespace {

// An SQLite URI for `file` (RFC 3986 escapes for the characters a URI path reserves).
std::string read_only_uri(const fs::path& file, bool immutable) {
  std::string uri = "file:";
  for (const char c : fs::absolute(file).string())
    if (c == '%' || c == '?' || c == '#')
      uri += fmt::format("%{:02X}", static_cast<unsigned char>(c));
    else
      uri += c;
  return uri + (immutable ? "?mode=ro&immutable=1" : "?mode=ro");
}

bool folder_writable(const fs::path& file) {
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  return ::access(folder.c_str(), W_OK) == 0;
}

}  // namespace

DeviceDb::DeviceDb(const fs::path& file, Access access) : file_(file) {
  if (fs::is_directory(file)) throw InputError(file, "is a folder; expected the device database file (e.g. devices.sqlite)");
  if (access == Access::kReadOnly && !fs::exists(file))
    throw InputError(file,
                     "no device database here yet ('antpose device import' or a calibration with --device "
                     "creates it)");
  if (access == Access::kReadWrite && file.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) throw InputError(file, fmt::format("cannot create the folder of the device database: {}", ec.message()));
  }
  open(access);
}

void DeviceDb::open(Access access) {
  // Read-only in a folder nobody may write: no journal can appear beside the file, so nothing can
  // change it, and SQLite may skip the locks and shared memory it could not create there.
  const int rc = access == Access::kReadWrite
                     ? sqlite3_open_v2(file_.c_str(), &db_,
                                       SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr)
                     : sqlite3_open_v2(read_only_uri(file_, !folder_writable(file_)).c_str(), &db_,
                                       SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string detail = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw InputError(file_, fmt::format("cannot open the device database: {}", detail));
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, kBusyTimeoutMs);
    // The first read of the header: a non-SQLite file fails here with SQLITE_NOTADB.
    {
      Statement s(db_, file_, "PRAGMA application_id");
      s.step();
      const std::int64_t app = s.integer(0);
      if (app != 0 && app != kApplicationId)
        throw InputError(file_, fmt::format("is an SQLite database of another application (application_id {:#x}), not "
                                            "an antpose device database",
                                            app));
    }
    if (access == Access::kReadOnly) {
      if (const int version = schema_version(); version != kSchemaVersion)
        throw InputError(file_, fmt::format("device database schema version {} where this antpose reads {}{}", version,
                                            kSchemaVersion, version > kSchemaVersion ? "; update antpose" : ""));
      return;
    }
    // WAL: readers and one writer proceed concurrently, and a crash never leaves a torn write.
    // Switching the mode needs a moment without other connections, hence the retries.
    for (int attempt = 0;; ++attempt) {
      const int w = exec_rc(db_, "PRAGMA journal_mode=WAL");
      if (w == SQLITE_OK) break;
      if (!is_busy(w) || attempt > 50) throw_sqlite(db_, w, file_, "enabling the WAL journal");
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    exec(db_, file_, "PRAGMA foreign_keys=ON");
    // NORMAL is durable in WAL mode except for the last transactions on power loss, never corrupt.
    exec(db_, file_, "PRAGMA synchronous=NORMAL");
    migrate();
    require_intact();
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

// A damaged file takes no writes: a run recorded into it could be lost with the damage, and the
// user could not tell which profile is current. The database holds a few devices, so checking
// every page (PRAGMA quick_check, O(N)) costs milliseconds.
void DeviceDb::require_intact() const {
  Statement s(db_, file_, "PRAGMA quick_check(1)");
  s.step();
  const std::string verdict = s.text(0);
  if (verdict != "ok")
    throw InputError(file_, fmt::format("the device database is corrupt ({}); nothing was written into it: restore it "
                                        "from a backup, or move it aside and calibrate again",
                                        verdict));
}

DeviceDb::~DeviceDb() { sqlite3_close(db_); }

int DeviceDb::schema_version() const {
  Statement s(db_, file_, "PRAGMA user_version");
  s.step();
  return static_cast<int>(s.integer(0));
}

// Migrations run in one write transaction, from the file's user_version up to kSchemaVersion; a
// later version appends a step here (ALTER TABLE ..., user_version = 2). Two processes opening
// a new file at once serialise on BEGIN IMMEDIATE and the second sees version 1.
void DeviceDb::migrate() {
  const int found = schema_version();
  if (found > kSchemaVersion)
    throw InputError(file_, fmt::format("device database schema version {} is newer than this antpose supports ({}); "
                                        "update antpose",
                                        found, kSchemaVersion));
  if (found == kSchemaVersion) return;  // the common case: no write lock needed to read
  with_write_transaction(db_, file_, [&] {
    const int version = schema_version();
    if (version > kSchemaVersion)
      throw InputError(file_, fmt::format("device database schema version {} is newer than this antpose supports ({}); "
                                          "update antpose",
                                          version, kSchemaVersion));
    if (version < 1) {
      Statement tables(db_, file_, "SELECT count(*) FROM sqlite_master WHERE type='table'");
      tables.step();
      if (tables.integer(0) != 0)
        throw InputError(file_, "is an SQLite database with other tables and no antpose schema version; not an antpose "
                                "device database");
      exec(db_, file_, R"sql(
        CREATE TABLE devices (
          id TEXT PRIMARY KEY NOT NULL,
          model TEXT NOT NULL DEFAULT '',
          created_utc TEXT NOT NULL,
          updated_utc TEXT NOT NULL,
          profile_yaml TEXT NOT NULL
        );
        CREATE TABLE calibration_runs (
          run_id INTEGER PRIMARY KEY AUTOINCREMENT,
          device_id TEXT NOT NULL REFERENCES devices(id) ON DELETE CASCADE,
          kind TEXT NOT NULL CHECK (kind IN ('imu', 'camera', 'camera-imu', 'import')),
          started_utc TEXT NOT NULL,
          finished_utc TEXT NOT NULL,
          status TEXT NOT NULL CHECK (status IN ('ok', 'failed')),
          settings_json TEXT NOT NULL DEFAULT '{}',
          inputs_json TEXT NOT NULL DEFAULT '[]',
          residuals_json TEXT NOT NULL DEFAULT '{}',
          profile_yaml TEXT NOT NULL,
          message TEXT NOT NULL DEFAULT ''
        );
        CREATE INDEX calibration_runs_device ON calibration_runs(device_id, run_id);
      )sql");
      exec(db_, file_, fmt::format("PRAGMA application_id={}", kApplicationId).c_str());
      exec(db_, file_, fmt::format("PRAGMA user_version={}", kSchemaVersion).c_str());
    }
  });
}

bool DeviceDb::has_device(const std::string& id) const {
  Statement s(db_, file_, "SELECT 1 FROM devices WHERE id=?");
  s.bind(1, id);
  return s.step();
}

void DeviceDb::fail_missing(const std::string& id) const {
  std::vector<std::string> ids;
  Statement s(db_, file_, "SELECT id FROM devices ORDER BY id");
  while (s.step()) ids.push_back(s.text(0));
  if (ids.empty())
    throw InputError(file_, fmt::format("no device '{}': the database holds no devices yet (add one with 'antpose "
                                        "device import FILE.yaml' or 'antpose calibrate imu ... --device ID')",
                                        id));
  throw InputError(file_, fmt::format("no device '{}'; known devices: {}", id, fmt::join(ids, ", ")));
}

std::vector<DeviceSummary> DeviceDb::list_devices() const {
  std::vector<DeviceSummary> out;
  Statement s(db_, file_,
              "SELECT d.id, d.model, d.created_utc, d.updated_utc, d.profile_yaml, "
              "(SELECT max(finished_utc) FROM calibration_runs r WHERE r.device_id=d.id AND r.status='ok' AND "
              "r.kind<>'import') FROM devices d ORDER BY d.id");
  while (s.step()) {
    DeviceSummary d{s.text(0), s.text(1), s.text(2), s.text(3), std::nullopt, {}};
    if (!s.is_null(5)) d.last_calibration_utc = s.text(5);
    try {
      calibrated_sections(parse_device_profile(s.text(4), source_name(file_, d.id)), d.calibrated);
    } catch (const InputError&) {
      d.calibrated.push_back("(unreadable profile)");
    }
    out.push_back(std::move(d));
  }
  return out;
}

DeviceProfile DeviceDb::profile(const std::string& id) const {
  Statement s(db_, file_, "SELECT profile_yaml, model FROM devices WHERE id=?");
  s.bind(1, id);
  if (!s.step()) fail_missing(id);
  DeviceProfile p = parse_device_profile(s.text(0), source_name(file_, id));
  p.id = id;
  if (p.model.empty()) p.model = s.text(1);
  return p;
}

std::vector<CalibrationRun> DeviceDb::history(const std::string& id) const {
  if (!has_device(id)) fail_missing(id);
  std::vector<CalibrationRun> runs;
  Statement s(db_, file_,
              "SELECT run_id, device_id, kind, started_utc, finished_utc, status, settings_json, inputs_json, "
              "residuals_json, profile_yaml, message FROM calibration_runs WHERE device_id=? ORDER BY run_id");
  s.bind(1, id);
  auto json = [](const std::string& text) {
    return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  };
  while (s.step()) {
    CalibrationRun r;
    r.run_id = s.integer(0);
    r.device_id = s.text(1);
    r.kind = s.text(2);
    r.started_utc = s.text(3);
    r.finished_utc = s.text(4);
    r.status = s.text(5);
    r.settings = json(s.text(6));
    r.inputs = json(s.text(7));
    r.residuals = json(s.text(8));
    r.profile_yaml = s.text(9);
    r.message = s.text(10);
    runs.push_back(std::move(r));
  }
  return runs;
}

std::int64_t DeviceDb::record_run(CalibrationRun run, const DeviceProfile& profile_after) {
  if (run.device_id.empty()) run.device_id = profile_after.id;
  return record_run(std::move(run), [&](const DeviceProfile&) { return profile_after; });
}

std::int64_t DeviceDb::record_run(CalibrationRun run, const std::function<DeviceProfile(DeviceProfile current)>& update) {
  if (run.device_id.empty()) throw InputError(file_, "a calibration run needs a device id");
  if (!valid_kind(run.kind))
    throw Error(fmt::format("calibration run kind '{}' is not imu, camera, camera-imu or import", run.kind));
  if (run.status != "ok" && run.status != "failed")
    throw Error(fmt::format("calibration run status '{}' is not ok or failed", run.status));
  if (run.started_utc.empty()) run.started_utc = utc_now();
  if (run.finished_utc.empty()) run.finished_utc = utc_now();
  const bool ok = run.status == "ok";
  return with_write_transaction(db_, file_, [&]() -> std::int64_t {
    const std::string now = utc_now();
    std::string current;
    bool exists = false;
    {
      Statement s(db_, file_, "SELECT profile_yaml FROM devices WHERE id=?");
      s.bind(1, run.device_id);
      exists = s.step();
      if (exists) current = s.text(0);
    }
    DeviceProfile current_profile;
    current_profile.id = run.device_id;
    if (exists) current_profile = parse_device_profile(current, source_name(file_, run.device_id));
    current_profile.id = run.device_id;
    std::optional<DeviceProfile> after;
    if (ok) {
      after = update(current_profile);
      after->id = run.device_id;
    }
    if (!exists) {
      // A new device: a failed first run still registers it, with an empty profile.
      const std::string model = after ? after->model : std::string();
      current = empty_profile_yaml(run.device_id, model);
      Statement ins(db_, file_, "INSERT INTO devices(id, model, created_utc, updated_utc, profile_yaml) VALUES (?,?,?,?,?)");
      ins.bind(1, run.device_id).bind(2, model).bind(3, now).bind(4, now).bind(5, current);
      ins.step();
    }
    const std::string new_yaml = after ? format_device_profile(*after) : current;
    if (after) {
      Statement up(db_, file_,
                   "UPDATE devices SET profile_yaml=?, model=CASE WHEN ?<>'' THEN ? ELSE model END, updated_utc=? WHERE id=?");
      up.bind(1, new_yaml).bind(2, after->model).bind(3, after->model).bind(4, now).bind(5, run.device_id);
      up.step();
    }
    Statement ins(db_, file_,
                  "INSERT INTO calibration_runs(device_id, kind, started_utc, finished_utc, status, settings_json, "
                  "inputs_json, residuals_json, profile_yaml, message) VALUES (?,?,?,?,?,?,?,?,?,?)");
    ins.bind(1, run.device_id).bind(2, run.kind).bind(3, run.started_utc).bind(4, run.finished_utc).bind(5, run.status);
    ins.bind(6, run.settings.dump()).bind(7, run.inputs.dump()).bind(8, run.residuals.dump());
    ins.bind(9, new_yaml).bind(10, run.message);
    ins.step();
    return sqlite3_last_insert_rowid(db_);
  });
}

std::int64_t DeviceDb::import_profile(const fs::path& yaml, const std::optional<std::string>& id,
                                      const std::optional<std::string>& model) {
  CalibrationRun run;
  run.kind = "import";
  run.started_utc = utc_now();
  DeviceProfile p = read_device_profile(yaml);
  if (id) p.id = *id;
  if (model) p.model = *model;
  if (p.id.empty())
    throw InputError(yaml, "has no device.id; give the database id with --id ID (e.g. --id pixel7-a)");
  run.device_id = p.id;
  run.inputs = to_json(hash_inputs(yaml));
  run.settings = {{"source", yaml.string()}};
  run.finished_utc = utc_now();
  run.message = fmt::format("imported from {}", yaml.string());
  return record_run(std::move(run), p);
}

void DeviceDb::export_profile(const std::string& id, const fs::path& file, bool force) const {
  const DeviceProfile p = profile(id);
  if (fs::exists(file) && !force)
    throw InputError(file, "exists; it was not changed (use --force to replace it)");
  write_device_profile(p, file);
}

void DeviceDb::remove_device(const std::string& id) {
  with_write_transaction(db_, file_, [&] {
    if (!has_device(id)) fail_missing(id);
    Statement runs(db_, file_, "DELETE FROM calibration_runs WHERE device_id=?");
    runs.bind(1, id);
    runs.step();
    Statement dev(db_, file_, "DELETE FROM devices WHERE id=?");
    dev.bind(1, id);
    dev.step();
  });
}

std::string DeviceDb::integrity_check() const {
  Statement s(db_, file_, "PRAGMA integrity_check");
  std::vector<std::string> lines;
  while (s.step()) lines.push_back(s.text(0));
  return fmt::format("{}", fmt::join(lines, "\n"));
}

}  // namespace antpose::store
