// Device database: create/list/show/history/import/export, failed runs, concurrent writers
// (two processes, two threads), bad database files, default location.
#include <sys/wait.h>
#include <unistd.h>

#include <sqlite3.h>

#include <cstdlib>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "antpose/store/device_db.hpp"
#include "antpose/store/device_ref.hpp"
#include "support/test_support.hpp"

namespace antpose::store {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

DeviceProfile sample(const std::string& id, double bias) {
  DeviceProfile p;
  p.id = id;
  p.model = "Pixel 7";
  p.has_imu = true;
  p.imu.acc_bias = Vec3(bias, 0, 0);
  return p;
}

CalibrationRun imu_run(const std::string& id, const std::string& status = "ok") {
  CalibrationRun r;
  r.device_id = id;
  r.kind = "imu";
  r.status = status;
  r.settings = {{"sensors", "acc"}};
  r.residuals = {{"acc_residual_rms_m_s2", 0.004}};
  return r;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(DeviceDb, CreatesSchemaAndIsEmpty) {
  test::TempDir dir;
  const fs::path file = dir / "sub" / "folder" / "d.sqlite";  // folders are created
  DeviceDb db(file);
  EXPECT_TRUE(fs::exists(file));
  EXPECT_EQ(db.schema_version(), DeviceDb::kSchemaVersion);
  EXPECT_TRUE(db.list_devices().empty());
  EXPECT_EQ(db.integrity_check(), "ok");
  EXPECT_THAT(error_of([&] { db.profile("px7"); }), HasSubstr("no device 'px7': the database holds no devices yet"));
  DeviceDb again(file);  // reopening an existing database
  EXPECT_EQ(again.schema_version(), 1);
}

TEST(DeviceDb, RecordsRunsAndKeepsProfileOnFailure) {
  test::TempDir dir;
  DeviceDb db(dir / "d.sqlite");
  const auto first = db.record_run(imu_run("px7"), sample("px7", 0.1));
  EXPECT_NEAR(db.profile("px7").imu.acc_bias.x(), 0.1, 1e-15);
  CalibrationRun failed = imu_run("px7", "failed");
  failed.message = "no static frames";
  const auto second = db.record_run(failed, sample("px7", 9.0));  // its profile must not be used
  EXPECT_GT(second, first);
  EXPECT_NEAR(db.profile("px7").imu.acc_bias.x(), 0.1, 1e-15);
  db.record_run(imu_run("px7"), sample("px7", 0.2));
  EXPECT_NEAR(db.profile("px7").imu.acc_bias.x(), 0.2, 1e-15);

  const auto h = db.history("px7");
  ASSERT_EQ(h.size(), 3u);
  EXPECT_EQ(h[0].status, "ok");
  EXPECT_EQ(h[1].status, "failed");
  EXPECT_EQ(h[1].message, "no static frames");
  // The failed run stores the (unchanged) profile in force after it.
  EXPECT_NEAR(parse_device_profile(h[1].profile_yaml, "h").imu.acc_bias.x(), 0.1, 1e-15);
  EXPECT_NEAR(parse_device_profile(h[2].profile_yaml, "h").imu.acc_bias.x(), 0.2, 1e-15);
  EXPECT_EQ(h[0].settings["sensors"], "acc");
  EXPECT_DOUBLE_EQ(h[0].residuals["acc_residual_rms_m_s2"].get<double>(), 0.004);
  EXPECT_FALSE(h[2].finished_utc.empty());
  EXPECT_LE(h[0].started_utc, h[2].finished_utc);

  const auto list = db.list_devices();
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].id, "px7");
  EXPECT_EQ(list[0].model, "Pixel 7");
  EXPECT_EQ(list[0].calibrated, std::vector<std::string>{"imu"});
  EXPECT_EQ(*list[0].last_calibration_utc, h[2].finished_utc);
}

TEST(DeviceDb, UpdateFunctionSeesTheProfileCurrentAtCommit) {
  test::TempDir dir;
  DeviceDb db(dir / "d.sqlite");
  DeviceProfile cam = sample("px7", 0.1);
  cam.camera = CameraCalibrationInfo{};
  cam.camera->intrinsics = {640, 480, 500, 500, 320, 240, {}};
  CalibrationRun camera_run = imu_run("px7");
  camera_run.kind = "camera";
  db.record_run(camera_run, cam);  // e.g. stored by another process during an IMU calibration
  const Vec3 new_bias(0.4, 0.5, 0.6);
  db.record_run(imu_run("px7"), [&](DeviceProfile current) {
    current.imu.acc_bias = new_bias;
    return current;
  });
  const DeviceProfile p = db.profile("px7");
  EXPECT_EQ(p.imu.acc_bias, new_bias);
  ASSERT_TRUE(p.camera);
  EXPECT_EQ(p.camera->intrinsics.fx, 500);
  bool called = false;
  db.record_run(imu_run("px7", "failed"), [&](DeviceProfile current) {
    called = true;
    return current;
  });
  EXPECT_FALSE(called);
  EXPECT_EQ(db.history("px7").size(), 3u);
}

TEST(DeviceDb, FailedFirstRunRegistersDeviceWithEmptyProfile) {
  test::TempDir dir;
  DeviceDb db(dir / "d.sqlite");
  db.record_run(imu_run("new", "failed"), sample("new", 3.0));
  const DeviceProfile p = db.profile("new");
  EXPECT_FALSE(p.has_imu);
  EXPECT_TRUE(p.imu.acc_bias.isZero());
  EXPECT_FALSE(db.list_devices()[0].last_calibration_utc);
}

TEST(DeviceDb, ImportExportAndMissingIds) {
  test::TempDir dir;
  DeviceDb db(dir / "d.sqlite");
  DeviceProfile p = sample("", 0.3);
  p.camera = CameraCalibrationInfo{};
  p.camera->intrinsics = {640, 480, 500, 500, 320, 240, {0.1, 0, 0, 0, 0}};
  write_device_profile(p, dir / "p.yaml");
  EXPECT_THAT(error_of([&] { db.import_profile(dir / "p.yaml", std::nullopt, std::nullopt); }), HasSubstr("--id"));
  db.import_profile(dir / "p.yaml", std::string("cam1"), std::string("Fairphone 5"));
  const auto h = db.history("cam1");
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h[0].kind, "import");
  ASSERT_EQ(h[0].inputs.size(), 1u);
  EXPECT_EQ(h[0].inputs[0]["sha256"], sha256_file(dir / "p.yaml"));
  EXPECT_EQ(h[0].inputs[0]["size_bytes"].get<std::uintmax_t>(), fs::file_size(dir / "p.yaml"));
  EXPECT_EQ(db.profile("cam1").model, "Fairphone 5");
  EXPECT_FALSE(db.list_devices()[0].last_calibration_utc);  // an import is not a calibration
  EXPECT_EQ(db.list_devices()[0].calibrated, (std::vector<std::string>{"imu", "camera"}));

  db.export_profile("cam1", dir / "out.yaml", false);
  const DeviceProfile q = read_device_profile(dir / "out.yaml");
  EXPECT_EQ(q.id, "cam1");
  EXPECT_EQ(q.camera->intrinsics.distortion[0], 0.1);
  EXPECT_NEAR(q.imu.acc_bias.x(), 0.3, 1e-15);
  EXPECT_THAT(error_of([&] { db.export_profile("cam1", dir / "out.yaml", false); }), HasSubstr("--force"));
  db.export_profile("cam1", dir / "out.yaml", true);

  db.record_run(imu_run("b2"), sample("b2", 0));
  EXPECT_THAT(error_of([&] { db.profile("zz"); }), HasSubstr("no device 'zz'; known devices: b2, cam1"));
  EXPECT_THAT(error_of([&] { db.history("zz"); }), HasSubstr("known devices: b2, cam1"));
  db.remove_device("b2");
  EXPECT_THAT(error_of([&] { db.remove_device("b2"); }), HasSubstr("known devices: cam1"));
  EXPECT_EQ(db.list_devices().size(), 1u);
}

TEST(DeviceDb, Sha256MatchesKnownDigestsAndHashesCaptureFolders) {
  test::TempDir dir;
  test::write_file(dir / "abc.txt", "abc");
  // FIPS 180-4 test vector.
  EXPECT_EQ(sha256_file(dir / "abc.txt"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  test::write_file(dir / "cap" / "b.csv", "");
  test::write_file(dir / "cap" / "a" / "c.csv", "abc");
  const auto files = hash_inputs(dir / "cap");
  ASSERT_EQ(files.size(), 2u);
  EXPECT_THAT(files[0].path, HasSubstr("cap/a/c.csv"));
  EXPECT_EQ(files[0].size, 3u);
  EXPECT_EQ(files[1].sha256, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_THROW(hash_inputs(dir / "nothing"), InputError);
}

TEST(DeviceDb, BadDatabaseFilesGiveClearMessages) {
  test::TempDir dir;
  test::write_file(dir / "text.sqlite", "this is not a database, just some text that is long enough to have a header\n");
  std::string m = error_of([&] { DeviceDb db(dir / "text.sqlite"); });
  EXPECT_THAT(m, HasSubstr("text.sqlite"));
  EXPECT_THAT(m, HasSubstr("not an SQLite file"));

  // A valid database whose pages were overwritten: corrupt.
  {
    DeviceDb db(dir / "c.sqlite");
    for (int i = 0; i < 50; ++i) db.record_run(imu_run(fmt::format("dev{:03d}", i)), sample(fmt::format("dev{:03d}", i), 0.01 * i));
  }
  {
    std::fstream f(dir / "c.sqlite", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4096 + 100);
    const std::string garbage(8192, '\x5a');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  m = error_of([&] {
    DeviceDb db(dir / "c.sqlite");
    db.list_devices();
    for (const auto& d : db.list_devices()) db.history(d.id);
  });
  EXPECT_THAT(m, HasSubstr("c.sqlite"));
  EXPECT_THAT(m, HasSubstr("the device database is corrupt"));

  // Newer schema.
  {
    DeviceDb db(dir / "new.sqlite");
  }
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "new.sqlite").c_str(), &raw), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(raw, "PRAGMA user_version=7", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(raw);
  }
  m = error_of([&] { DeviceDb db(dir / "new.sqlite"); });
  EXPECT_THAT(m, HasSubstr("schema version 7 is newer"));
  EXPECT_THAT(m, HasSubstr("new.sqlite"));

  // Another application's SQLite database.
  {
    sqlite3* raw = nullptr;
    ASSERT_EQ(sqlite3_open((dir / "other.sqlite").c_str(), &raw), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(raw, "CREATE TABLE t(x)", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(raw);
  }
  EXPECT_THAT(error_of([&] { DeviceDb db(dir / "other.sqlite"); }), HasSubstr("not an antpose device database"));

  EXPECT_THAT(error_of([&] { DeviceDb db(dir.path()); }), HasSubstr("is a folder"));
}

TEST(DeviceDb, DefaultLocationFollowsEnvironment) {
  struct Saved {
    const char* name;
    std::optional<std::string> value;
  };
  std::vector<Saved> saved;
  for (const char* n : {"ANTPOSE_DB", "XDG_DATA_HOME", "HOME"}) {
    const char* v = std::getenv(n);
    saved.push_back({n, v ? std::optional<std::string>(v) : std::nullopt});
  }
  setenv("ANTPOSE_DB", "/tmp/x/env.sqlite", 1);
  setenv("XDG_DATA_HOME", "/data/home", 1);
  setenv("HOME", "/home/u", 1);
  EXPECT_EQ(DeviceDb::resolve_path(fs::path("given.sqlite")), fs::path("given.sqlite"));
  EXPECT_EQ(DeviceDb::resolve_path(std::nullopt), fs::path("/tmp/x/env.sqlite"));
  unsetenv("ANTPOSE_DB");
  EXPECT_EQ(DeviceDb::resolve_path(std::nullopt), fs::path("/data/home/antpose/devices.sqlite"));
  setenv("XDG_DATA_HOME", "relative/ignored", 1);  // the XDG spec: relative paths are invalid
  EXPECT_EQ(DeviceDb::resolve_path(std::nullopt), fs::path("/home/u/.local/share/antpose/devices.sqlite"));
  unsetenv("XDG_DATA_HOME");
  EXPECT_EQ(DeviceDb::resolve_path(std::nullopt), fs::path("/home/u/.local/share/antpose/devices.sqlite"));
  unsetenv("HOME");
  EXPECT_THAT(error_of([] { DeviceDb::resolve_path(std::nullopt); }), HasSubstr("--db"));
  for (const auto& s : saved) {
    if (s.value) setenv(s.name, s.value->c_str(), 1);
    else unsetenv(s.name);
  }
}

TEST(DeviceDb, ResolveDeviceFromFileOrId) {
  test::TempDir dir;
  const fs::path db_file = dir / "d.sqlite";
  EXPECT_THAT(error_of([&] { resolve_device("px7", db_file); }), HasSubstr("does not exist yet"));
  {
    DeviceDb db(db_file);
    db.record_run(imu_run("px7"), sample("px7", 0.5));
  }
  EXPECT_NEAR(resolve_device("px7", db_file).imu.acc_bias.x(), 0.5, 1e-15);
  EXPECT_THAT(error_of([&] { resolve_device("px8", db_file); }), HasSubstr("known devices: px7"));
  write_device_profile(sample("file-dev", 0.7), dir / "f.yaml");
  EXPECT_NEAR(resolve_device((dir / "f.yaml").string(), db_file).imu.acc_bias.x(), 0.7, 1e-15);
  EXPECT_THAT(error_of([&] { resolve_device("missing.yaml", db_file); }), HasSubstr("no such device file"));
  // A bare name that is both a file here and an id in the database is ambiguous.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir.path());
  write_device_profile(sample("x", 0.9), "px7");
  const std::string m = error_of([&] { resolve_device("px7", db_file); });
  fs::current_path(cwd);
  EXPECT_THAT(m, HasSubstr("ambiguous"));
  EXPECT_THAT(m, HasSubstr("./px7"));
}

// Two connections in two processes (and two threads) write runs at the same time: none lost,
// the database intact.
constexpr int kRunsPerWriter = 40;

void write_runs(const fs::path& file, const std::string& device) {
  DeviceDb db(file);
  for (int i = 0; i < kRunsPerWriter; ++i) {
    CalibrationRun r = imu_run(device, i % 5 == 4 ? "failed" : "ok");
    r.message = fmt::format("{} #{}", device, i);
    db.record_run(r, sample(device, 0.001 * i));
  }
}

void expect_all_runs(const fs::path& file, const std::vector<std::string>& devices) {
  DeviceDb db(file);
  EXPECT_EQ(db.integrity_check(), "ok");
  for (const auto& d : devices) {
    const auto h = db.history(d);
    ASSERT_EQ(h.size(), static_cast<std::size_t>(kRunsPerWriter)) << d;
    for (int i = 0; i < kRunsPerWriter; ++i) EXPECT_EQ(h[i].message, fmt::format("{} #{}", d, i));
    // Last ok run is #38 (#39 failed): its profile is current.
    EXPECT_NEAR(db.profile(d).imu.acc_bias.x(), 0.001 * (kRunsPerWriter - 2), 1e-15) << d;
  }
}

TEST(DeviceDb, TwoProcessesWritingAtOnceLoseNothing) {
  test::TempDir dir;
  const fs::path file = dir / "d.sqlite";  // created by the racing children themselves
  std::vector<pid_t> children;
  for (const char* device : {"proc-a", "proc-b"}) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int status = 0;
      try {
        write_runs(file, device);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "child %s: %s\n", device, e.what());
        status = 1;
      }
      std::_Exit(status);
    }
    children.push_back(pid);
  }
  for (pid_t pid : children) {
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "writer process failed";
  }
  expect_all_runs(file, {"proc-a", "proc-b"});
}

TEST(DeviceDb, TwoThreadsWithSeparateConnections) {
  test::TempDir dir;
  const fs::path file = dir / "d.sqlite";
  std::string error_a, error_b;
  auto run = [&](const char* device, std::string& error) {
    try {
      write_runs(file, device);
    } catch (const std::exception& e) {
      error = e.what();
    }
  };
  std::thread a(run, "thread-a", std::ref(error_a));
  std::thread b(run, "thread-b", std::ref(error_b));
  a.join();
  b.join();
  EXPECT_EQ(error_a, "");
  EXPECT_EQ(error_b, "");
  expect_all_runs(file, {"thread-a", "thread-b"});
}

}  // namespace
}  // namespace antpose::store
