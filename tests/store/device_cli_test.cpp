// antpose device ... and calibrate imu|camera --device: end to end through the CLI.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>

#include "antpose/sim/imu_simulator.hpp"
#include "antpose/store/device_db.hpp"
#include "support/test_support.hpp"

namespace antpose::store {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

const char* kProfile = R"(format: antpose-device
version: 1
device: {model: Pixel 7, id: px7}
imu:
  gyroscope: {bias_rad_s: [0.01, 0, 0]}
camera: {width_px: 640, height_px: 480, fx_px: 500, fy_px: 500, cx_px: 320, cy_px: 240, note: kept}
)";

TEST(DeviceCli, AFolderWithoutWritePermissionIsReadButNotWritten) {
  test::TempDir dir;
  const fs::path db = dir / "shared" / "d.sqlite";
  test::write_file(dir / "p.yaml", kProfile);
  ASSERT_EQ(test::run_cli(fmt::format("device import {} --db {}", (dir / "p.yaml").string(), db.string())).status, 0);
  // Root may write anywhere: the commands then run as nobody, for whom the folder is read-only.
  fs::permissions(dir.path(), fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                  fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(db.parent_path(), fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                        fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const auto run = [](const std::string& args) { return test::run_cli_unprivileged(args); };
  auto r = run("device list --db " + db.string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("px7"));
  r = run("device show px7 --db " + db.string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("fx_px: 500"));
  r = run(fmt::format("device import {} --id other --db {}", (dir / "p.yaml").string(), db.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("d.sqlite: "));
  fs::permissions(db.parent_path(), fs::perms::owner_all);
}

TEST(DeviceCli, ADamagedDatabaseTakesNoWrites) {
  test::TempDir dir;
  const fs::path db = dir / "d.sqlite";
  test::write_file(dir / "p.yaml", kProfile);
  for (int i = 0; i < 40; ++i)
    ASSERT_EQ(
        test::run_cli(fmt::format("device import {} --id dev{:02d} --db {}", (dir / "p.yaml").string(), i, db.string()))
            .status,
        0);
  {
    std::fstream f(db, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4096 + 100);
    const std::string garbage(8192, '\x5a');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  const auto before = fs::file_size(db);
  const auto r =
      test::run_cli(fmt::format("device import {} --id late --db {}", (dir / "p.yaml").string(), db.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("the device database is corrupt"));
  EXPECT_THAT(r.err, HasSubstr("nothing was written into it"));
  EXPECT_EQ(fs::file_size(db), before);
}

TEST(DeviceCli, ImportListShowExportRemove) {
  test::TempDir dir;
  const std::string db = "--db " + (dir / "d.sqlite").string();
  test::write_file(dir / "p.yaml", kProfile);
  auto r = test::run_cli("device list " + db);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("no devices"));
  r = test::run_cli(fmt::format("device import {} {}", (dir / "p.yaml").string(), db));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("as device 'px7' (run 1)"));
  r = test::run_cli(fmt::format("device import {} --id second --model 'Other phone' {}", (dir / "p.yaml").string(), db));
  ASSERT_EQ(r.status, 0) << r.err;
  r = test::run_cli("device list " + db);
  EXPECT_THAT(r.out, HasSubstr("px7"));
  EXPECT_THAT(r.out, HasSubstr("Other phone"));
  EXPECT_THAT(r.out, HasSubstr("imu, camera"));
  r = test::run_cli("device show px7 --history " + db);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("note: kept"));
  EXPECT_THAT(r.out, HasSubstr("import      ok"));
  r = test::run_cli("device show px7 --history --json - " + db);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["id"], "px7");
  ASSERT_EQ(j["history"].size(), 1u);
  EXPECT_EQ(j["history"][0]["kind"], "import");
  EXPECT_EQ(j["history"][0]["inputs"][0]["sha256"].get<std::string>().size(), 64u);

  const auto out = dir / "exported.yaml";
  r = test::run_cli(fmt::format("device export px7 -o {} {}", out.string(), db));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_device_profile(out).camera->intrinsics.fx, 500);
  r = test::run_cli(fmt::format("device export px7 -o {} {}", out.string(), db));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--force"));
  r = test::run_cli(fmt::format("device export px7 -o {} --force {}", out.string(), db));
  EXPECT_EQ(r.status, 0) << r.err;

  r = test::run_cli("device show nope " + db);
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("no device 'nope'; known devices: px7, second"));
  r = test::run_cli("device remove second " + db);
  EXPECT_EQ(r.status, 0) << r.err;
  r = test::run_cli("device show second " + db);
  EXPECT_THAT(r.err, HasSubstr("known devices: px7"));
}

TEST(DeviceCli, DatabaseFromEnvironmentAndBadFile) {
  test::TempDir dir;
  test::write_file(dir / "p.yaml", kProfile);
  // $ANTPOSE_DB names the database when --db is not given (the child inherits the variable).
  const char* old = std::getenv("ANTPOSE_DB");
  const std::optional<std::string> saved = old ? std::optional<std::string>(old) : std::nullopt;
  const fs::path env_db = dir / "env" / "x.sqlite";
  setenv("ANTPOSE_DB", env_db.c_str(), 1);
  const auto imported = test::run_cli(fmt::format("device import {}", (dir / "p.yaml").string()));
  const auto listed = test::run_cli("device list");
  if (saved) setenv("ANTPOSE_DB", saved->c_str(), 1);
  else unsetenv("ANTPOSE_DB");
  EXPECT_EQ(imported.status, 0) << imported.err;
  EXPECT_THAT(imported.out, HasSubstr(env_db.string()));
  EXPECT_TRUE(fs::exists(env_db));
  EXPECT_THAT(listed.out, HasSubstr("px7"));

  test::write_file(dir / "junk.sqlite", "definitely not SQLite, but long enough to be read as a header......");
  const auto r = test::run_cli("device list --db " + (dir / "junk.sqlite").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("junk.sqlite: is not an antpose device database"));
}

fs::path write_sim(const test::TempDir& dir, const std::string& name) {
  std::mt19937_64 rng(21);
  sim::ImuSimulation sim;
  sim.phone = sim::PhoneModel::random(rng);
  sim.kind = "imu-calibration";
  sim.trajectory = sim::static_poses(sim::calibration_poses(), 3.0, 2.0);
  write_capture(sim::simulate_imu(sim), dir / name);
  return dir / name;
}

TEST(DeviceCli, CalibrateImuRecordsRunsAndFailureKeepsProfile) {
  test::TempDir dir;
  const fs::path db_file = dir / "d.sqlite";
  const std::string db = "--db " + db_file.string();
  test::write_file(dir / "p.yaml", kProfile);
  ASSERT_EQ(test::run_cli(fmt::format("device import {} {}", (dir / "p.yaml").string(), db)).status, 0);

  // A calibration that throws (the capture has no data): a failed run, the profile unchanged.
  fs::create_directories(dir / "empty");
  auto r = test::run_cli(fmt::format("calibrate imu {} --device px7 {}", (dir / "empty").string(), db));
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_THAT(r.err, HasSubstr("failed run 2"));
  {
    DeviceDb d(db_file);
    const auto h = d.history("px7");
    ASSERT_EQ(h.size(), 2u);
    EXPECT_EQ(h[1].status, "failed");
    EXPECT_EQ(h[1].kind, "imu");
    EXPECT_FALSE(h[1].message.empty());
    const DeviceProfile p = d.profile("px7");
    EXPECT_EQ(p.imu.gyro_bias, Vec3(0.01, 0, 0));
    EXPECT_FALSE(d.list_devices()[0].last_calibration_utc);
  }

  // A successful one: the gyroscope section is kept, the accelerometer updated, the inputs hashed.
  const fs::path cap = write_sim(dir, "cal");
  r = test::run_cli(fmt::format("calibrate imu {} --sensors acc --device px7 {} -o {}", cap.string(), db,
                                (dir / "out.yaml").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("recorded as run 3 of device 'px7'"));
  DeviceDb d(db_file);
  const auto h = d.history("px7");
  ASSERT_EQ(h.size(), 3u);
  EXPECT_EQ(h[2].status, "ok");
  EXPECT_EQ(h[2].settings["sensors"], "acc");
  EXPECT_TRUE(h[2].residuals.contains("acc_residual_rms_m_s2"));
  const auto inputs = hash_inputs(cap);
  ASSERT_EQ(h[2].inputs.size(), inputs.size());
  ASSERT_GE(inputs.size(), 2u);
  for (std::size_t i = 0; i < inputs.size(); ++i) EXPECT_EQ(h[2].inputs[i]["sha256"], inputs[i].sha256);
  const DeviceProfile p = d.profile("px7");
  EXPECT_EQ(p.imu.gyro_bias, Vec3(0.01, 0, 0));
  EXPECT_FALSE(p.imu.acc_bias.isZero());
  ASSERT_TRUE(p.camera);
  EXPECT_EQ(read_device_profile(dir / "out.yaml").imu.acc_bias, p.imu.acc_bias);
  EXPECT_THAT(format_device_profile(p), HasSubstr("note: kept"));  // unknown keys of other sections survive
  EXPECT_TRUE(d.list_devices()[0].last_calibration_utc);

  // An existing -o is replaced only with --force (and the refusal records no run).
  r = test::run_cli(fmt::format("calibrate imu {} --sensors acc --device px7 {} -o {}", cap.string(), db,
                                (dir / "out.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--force"));
  EXPECT_EQ(d.history("px7").size(), 3u);

  // Without --device, -o stays required.
  r = test::run_cli(fmt::format("calibrate imu {}", cap.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--device"));
}

// calibrate camera --device: the intrinsics (with the principal point's σ) become the camera
// section; a calibration that fails is a failed run and the profile keeps its camera.
TEST(DeviceCli, CalibrateCameraStoresIntrinsicsAndFailureKeepsThem) {
  test::TempDir dir;
  const fs::path db_file = dir / "d.sqlite";
  const std::string db = "--db " + db_file.string();
  const auto chess = test::shared_path("data/camera/opencv-chessboard-9x6");
  auto r = test::run_cli(fmt::format("calibrate camera '{}' --device cam1 {}", chess.string(), db));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("recorded as run 1 of device 'cam1'"));
  DeviceDb d(db_file);
  auto p = d.profile("cam1");
  ASSERT_TRUE(p.camera);
  EXPECT_NEAR(p.camera->intrinsics.fx, 536.07, 0.1);
  ASSERT_TRUE(p.camera->principal_point_sigma_px);
  EXPECT_GT(p.camera->principal_point_sigma_px->x(), 0.0);
  EXPECT_FALSE(p.has_imu);
  const auto h = d.history("cam1");
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h[0].kind, "camera");
  EXPECT_NEAR(h[0].residuals["rms_px"].get<double>(), 0.4087, 1e-3);
  EXPECT_EQ(h[0].residuals["photos_used"], 13);

  // A config naming another board: no photo shows it, the run fails, the camera stays.
  test::write_file(dir / "wrong.yaml", "board: {type: chessboard, cols: 7, rows: 5, square_m: 0.03}\n");
  r = test::run_cli(fmt::format("calibrate camera '{}' --config '{}' --device cam1 {}", chess.string(),
                                (dir / "wrong.yaml").string(), db));
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_THAT(r.err, HasSubstr("no board found"));
  EXPECT_THAT(r.err, HasSubstr("recorded failed run 2 of device 'cam1'"));
  EXPECT_EQ(d.history("cam1").back().status, "failed");
  p = d.profile("cam1");
  ASSERT_TRUE(p.camera);
  EXPECT_NEAR(p.camera->intrinsics.fx, 536.07, 0.1);

  // Neither -o nor --device: refused before any work.
  r = test::run_cli(fmt::format("calibrate camera '{}'", chess.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("no output given: pass -o camera.yaml and/or --device ID|FILE"));
}

}  // namespace
}  // namespace antpose::store
