#include "antpose/measure/contact.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/geomag/wmm.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "support/test_support.hpp"

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

Site paris() {
  Site s;
  s.lat_deg = 48.85;
  s.lon_deg = 2.35;
  s.alt_m = 60.0;
  s.date = "2026-03-01";
  return s;
}

// A contact capture of a plate at (azimuth, downtilt, roll) true, with the WMM field of the site.
Capture contact_capture(double az_deg, double dt_deg, double roll_deg, ContactPlacement placement,
                        const sim::PhoneModel& phone, std::optional<Site> site = paris(), double hold_s = 8.0,
                        double tremor = 0.0, std::uint64_t seed = 1) {
  sim::ImuSimulation s;
  s.phone = phone;
  s.field_world_uT = geomag::site_field(geomag::MagneticModel::wmm2025(), paris()).field_enu_uT;
  s.site = site;
  s.seed = seed;
  sim::ContactMotion motion;
  motion.hold_s = hold_s;
  motion.tremor_rotation_rms_rad = tremor;
  motion.tremor_translation_rms_m = 0.0;
  return sim::simulate_contact(s, rotation_from_attitude(deg2rad(az_deg), deg2rad(dt_deg), deg2rad(roll_deg)),
                               placement, motion);
}

double declination_paris() { return geomag::site_field(geomag::MagneticModel::wmm2025(), paris()).declination; }

struct Pose {
  double az, dt, roll;
  ContactPlacement placement;
};

// A neutral calibration that states both sensors were calibrated (the ideal phone needs no
// correction), so that the calibrated uncertainty floors apply.
imu::ImuCalibration neutral_calibration() {
  return imu::parse_imu_calibration(
      "format: antpose-device\nversion: 1\nimu:\n  magnetometer: {hard_iron_uT: [0, 0, 0]}\n"
      "  accelerometer: {bias_m_s2: [0, 0, 0], scale: [1, 1, 1]}\n",
      "neutral.yaml");
}

class ContactPerfect : public ::testing::TestWithParam<Pose> {};

TEST_P(ContactPerfect, RecoversTheAttitudeWithoutWarnings) {
  const Pose p = GetParam();
  ContactOptions options;
  options.placement = p.placement;
  options.calibration = neutral_calibration();
  const auto r = measure_contact(contact_capture(p.az, p.dt, p.roll, p.placement, sim::PhoneModel::ideal()), options);
  ASSERT_TRUE(r.azimuth_true && r.azimuth_magnetic && r.roll && r.declination);
  EXPECT_NEAR(rad2deg(wrap_pi(*r.azimuth_true - deg2rad(p.az))), 0.0, 0.01);
  EXPECT_NEAR(rad2deg(wrap_pi(*r.azimuth_magnetic - deg2rad(p.az) + declination_paris())), 0.0, 0.01);
  EXPECT_NEAR(rad2deg(r.downtilt), p.dt, 0.01);
  EXPECT_NEAR(rad2deg(*r.roll), p.roll, 0.01);
  EXPECT_NEAR(*r.declination, declination_paris(), 1e-12);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  EXPECT_FALSE(r.magnetic_disturbance);
  // The hold is [3.5, 11.5] s (before 1 s + approach 2.5 s).
  EXPECT_NEAR(r.t0, 3.5, 0.5);
  EXPECT_NEAR(r.t1, 11.5, 0.5);
  EXPECT_NEAR(r.field_uT, *r.expected_field_uT, 1e-6);
  EXPECT_NEAR(r.dip, *r.expected_dip, 1e-6);
  // Uncertainties are the floors: 0.02 m/s² → 0.117°, azimuth ≥ 1 µT / (√3 H).
  EXPECT_NEAR(rad2deg(r.sigma.downtilt), rad2deg(0.02 / 9.80665), 0.01);
  EXPECT_GT(*r.sigma.azimuth_true, r.sigma.azimuth);
  EXPECT_NEAR(rad2deg(*r.sigma.declination), 0.37, 0.1);  // WMM error model at H ≈ 21 µT
}

INSTANTIATE_TEST_SUITE_P(
    Poses, ContactPerfect,
    ::testing::Values(Pose{0.0, 0.0, 0.0, ContactPlacement::kTopUp}, Pose{45.0, 6.0, -2.0, ContactPlacement::kTopUp},
                      Pose{135.0, -4.0, 1.5, ContactPlacement::kTopUp}, Pose{225.0, 12.0, 0.5, ContactPlacement::kTopUp},
                      Pose{315.0, 3.0, -1.0, ContactPlacement::kTopUp}, Pose{100.0, 8.0, 2.0, ContactPlacement::kTopDown},
                      Pose{200.0, 5.0, -3.0, ContactPlacement::kTopRight},
                      Pose{300.0, 2.0, 3.0, ContactPlacement::kTopLeft}));

TEST(Contact, WithoutCalibrationTheUncertaintyIsHonestAndFlagged) {
  // The same perfect data, but nothing says the sensors were calibrated: the floors of an
  // uncalibrated phone (8 mg accelerometer offset, 4 µT residual hard iron) apply.
  const auto r = measure_contact(contact_capture(45.0, 6.0, -2.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal()));
  EXPECT_NEAR(rad2deg(r.sigma.downtilt), rad2deg(0.08 / 9.80665), 0.02);
  EXPECT_GT(rad2deg(r.sigma.azimuth), 3.0);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_THAT(r.warnings.back(), HasSubstr("uncertain: 1σ azimuth"));
  EXPECT_THAT(r.warnings.back(), HasSubstr("not calibrated: accelerometer, magnetometer"));
}

TEST(Contact, PlacementMismatchChangesTheAnswer) {
  // A top-down recording read as top-up is off by 180° in roll.
  const auto r = measure_contact(contact_capture(80.0, 5.0, 0.0, ContactPlacement::kTopDown, sim::PhoneModel::ideal()));
  ASSERT_TRUE(r.roll);
  EXPECT_NEAR(std::abs(rad2deg(*r.roll)), 180.0, 0.01);
}

TEST(Contact, NoSiteGivesMagneticAzimuthOnlyAndSaysSo) {
  ContactOptions options;
  options.calibration = neutral_calibration();
  const auto r = measure_contact(
      contact_capture(30.0, 4.0, 0.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal(), std::nullopt), options);
  EXPECT_FALSE(r.azimuth_true);
  EXPECT_FALSE(r.declination);
  ASSERT_TRUE(r.azimuth_magnetic);
  EXPECT_NEAR(rad2deg(wrap_pi(*r.azimuth_magnetic - deg2rad(30.0) + declination_paris())), 0.0, 0.01);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_THAT(r.warnings[0], HasSubstr("no site in the capture"));
  const auto j = to_json(r);
  EXPECT_TRUE(j["azimuth_true_deg"].is_null());
  EXPECT_TRUE(j["declination_deg"].is_null());
}

TEST(Contact, HardIronWithoutCalibrationWarnsAndCalibrationFixesIt) {
  sim::PhoneModel phone = sim::PhoneModel::ideal();
  phone.magnetometer.hard_iron_uT = Vec3(35.0, -20.0, 30.0);  // 50 µT
  const Capture c = contact_capture(150.0, 6.0, 1.0, ContactPlacement::kTopUp, phone);
  const auto r = measure_contact(c);
  EXPECT_TRUE(r.magnetic_disturbance);
  bool found = false;
  for (const auto& w : r.warnings) found = found || w.find("magnetic disturbance") != std::string::npos;
  EXPECT_TRUE(found);

  ContactOptions options;
  options.calibration.emplace();
  options.calibration->mag_hard_iron_uT = phone.magnetometer.hard_iron_uT;
  const auto fixed = measure_contact(c, options);
  EXPECT_FALSE(fixed.magnetic_disturbance);
  EXPECT_TRUE(fixed.warnings.empty());
  EXPECT_NEAR(rad2deg(wrap_pi(*fixed.azimuth_true - deg2rad(150.0))), 0.0, 0.01);
}

TEST(Contact, ShortWindowHorizontalPlateAndVerticalBoresightWarn) {
  auto has = [](const ContactResult& r, const std::string& text) {
    for (const auto& w : r.warnings)
      if (w.find(text) != std::string::npos) return true;
    return false;
  };
  const auto short_hold = measure_contact(
      contact_capture(10.0, 3.0, 0.0, ContactPlacement::kTopUp, sim::PhoneModel::typical(), paris(), 1.2, 0.0));
  EXPECT_TRUE(has(short_hold, "static window short")) << ::testing::PrintToString(short_hold.warnings);

  const auto flat = measure_contact(contact_capture(10.0, 80.0, 0.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal()));
  EXPECT_TRUE(has(flat, "plate nearly horizontal"));

  const auto vertical = measure_contact(contact_capture(10.0, 90.0, 0.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal()));
  EXPECT_TRUE(has(vertical, "azimuth and roll are undefined"));
  EXPECT_FALSE(vertical.azimuth_magnetic);
  EXPECT_FALSE(vertical.roll);
  EXPECT_TRUE(to_json(vertical)["roll_deg"].is_null());
}

TEST(Contact, MovingPhoneWarns) {
  // The phone creeps by 1.5° over 8 s on the plate: too slow for the static detector
  // (≤ 0.35°/s), but the tilt wanders by more than 0.5° inside the window.
  const Mat3 R = sim::contact_device_rotation(rotation_from_attitude(0.3, 0.05, 0.0), ContactPlacement::kTopUp);
  sim::ImuSimulation s;
  s.trajectory = sim::Trajectory(R).hold(1.0).rotate_to(R * rot_x(deg2rad(1.5)), 8.0).hold(1.0);
  s.field_world_uT = geomag::site_field(geomag::MagneticModel::wmm2025(), paris()).field_enu_uT;
  s.site = paris();
  const auto r = measure_contact(sim::simulate_imu(s));
  EXPECT_GT(r.t1 - r.t0, 8.0);
  bool found = false;
  for (const auto& w : r.warnings) found = found || w.find("phone not flat on the plate / moved") != std::string::npos;
  EXPECT_TRUE(found) << ::testing::PrintToString(r.warnings);
}

TEST(Contact, BadInputs) {
  const Capture good = contact_capture(10.0, 3.0, 0.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal());
  Capture no_acc = good;
  no_acc.streams.erase("accelerometer");
  try {
    measure_contact(no_acc);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no accelerometer stream"));
  }
  Capture no_mag = good;
  no_mag.streams.erase("magnetometer");
  try {
    measure_contact(no_mag);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no magnetometer stream"));
  }
  sim::ImuSimulation s;
  s.trajectory = sim::Trajectory(Mat3::Identity()).rotate_to(rot_x(1.0), 3.0).rotate_to(rot_y(1.5), 3.0).rotate_to(rot_z(2.0), 3.0);
  try {
    measure_contact(sim::simulate_imu(s));
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no static window"));
    EXPECT_THAT(e.what(), HasSubstr("hold it still"));
  }
  Capture bad_site = good;
  bad_site.site->date = "2026-13-01";
  EXPECT_THROW(measure_contact(bad_site), InputError);
}

TEST(Contact, JsonHasTheDocumentedKeys) {
  const auto j = to_json(measure_contact(contact_capture(45.0, 6.0, -2.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal())));
  for (const char* key : {"azimuth_magnetic_deg", "azimuth_true_deg", "declination_deg", "downtilt_deg", "roll_deg",
                          "sigma", "warnings", "window_s", "field", "placement", "phone_attitude"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_NEAR(j["azimuth_true_deg"].get<double>(), 45.0, 0.01);
  EXPECT_NEAR(j["downtilt_deg"].get<double>(), 6.0, 0.01);
  EXPECT_NEAR(j["roll_deg"].get<double>(), -2.0, 0.01);
  for (const char* key : {"azimuth_magnetic_deg", "downtilt_deg", "roll_deg"})
    EXPECT_GT(j["sigma"][key].get<double>(), 0.0);
  for (const char* key : {"measured_uT", "expected_uT", "dip_deg", "expected_dip_deg"}) EXPECT_TRUE(j["field"][key].is_number());
  EXPECT_EQ(j["placement"], "top-up");
  EXPECT_EQ(j["window_s"].size(), 2u);
  // Top up: pitch = −asin(up component of device y = z_a) = −(90° − acos(cos 6° cos 2°)).
  EXPECT_NEAR(j["phone_attitude"]["pitch_deg"].get<double>(),
              -(90.0 - rad2deg(std::acos(std::cos(deg2rad(6.0)) * std::cos(deg2rad(2.0))))), 1e-3);
}

// --- CLI ----------------------------------------------------------------------------------

TEST(ContactCli, WritesJsonAndPrintsTable) {
  test::TempDir dir;
  write_capture(contact_capture(45.0, 6.0, -2.0, ContactPlacement::kTopUp, sim::PhoneModel::typical(), paris(), 8.0, 0.001),
                dir / "cap");
  const auto res = test::run_cli(fmt::format("contact {} --json {}", (dir / "cap").string(), (dir / "out.json").string()));
  // The phone is uncalibrated: the azimuth's σ of 7° is written, and said to be unusable (exit 4).
  ASSERT_EQ(res.status, 4) << res.err;
  EXPECT_THAT(res.err, HasSubstr("warning: the result is not usable: azimuth sigma 7."));
  EXPECT_THAT(res.out, HasSubstr("azimuth true"));
  EXPECT_THAT(res.out, HasSubstr("downtilt"));
  EXPECT_THAT(res.out, HasSubstr("field check"));
  const auto j = nlohmann::json::parse(io::read_text(dir / "out.json"));
  for (const char* key : {"azimuth_magnetic_deg", "azimuth_true_deg", "declination_deg", "downtilt_deg", "roll_deg",
                          "sigma", "warnings", "window_s", "field", "placement", "phone_attitude"})
    EXPECT_TRUE(j.contains(key)) << key;
  // The typical phone has a 10 mg accelerometer bias (≈ 0.6°) uncalibrated.
  EXPECT_NEAR(j["downtilt_deg"].get<double>(), 6.0, 1.0);
  EXPECT_NEAR(j["azimuth_true_deg"].get<double>(), 45.0, 5.0);
}

TEST(ContactCli, CalibrationFolderAndFile) {
  test::TempDir dir;
  sim::PhoneModel phone = sim::PhoneModel::ideal();
  phone.magnetometer.hard_iron_uT = Vec3(-30.0, 25.0, 30.0);
  write_capture(contact_capture(200.0, 4.0, 1.0, ContactPlacement::kTopUp, phone), dir / "cap");
  sim::ImuSimulation calib;
  calib.trajectory = sim::tumble(40.0, 1.5, 9);
  calib.phone = phone;
  calib.field_world_uT = geomag::site_field(geomag::MagneticModel::wmm2025(), paris()).field_enu_uT;
  calib.kind = "imu-calibration";
  write_capture(sim::simulate_imu(calib), dir / "calib");

  const auto raw = test::run_cli(fmt::format("contact {}", (dir / "cap").string()));
  ASSERT_EQ(raw.status, 0) << raw.err;
  EXPECT_THAT(raw.err, HasSubstr("magnetic disturbance"));

  const auto folder = test::run_cli(fmt::format("contact {} --imu-calibration {} --json {}", (dir / "cap").string(),
                                                (dir / "calib").string(), (dir / "a.json").string()));
  ASSERT_EQ(folder.status, 0) << folder.err;
  EXPECT_THAT(folder.out, HasSubstr("hard iron from"));
  EXPECT_THAT(folder.err, ::testing::Not(HasSubstr("magnetic disturbance")));
  const auto j = nlohmann::json::parse(io::read_text(dir / "a.json"));
  EXPECT_NEAR(j["azimuth_true_deg"].get<double>(), 200.0, 2.0);

  test::write_file(dir / "phone.yaml",
                   "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_uT: [-30, 25, 30]\n");
  const auto file = test::run_cli(fmt::format("contact {} --imu-calibration {} --json {}", (dir / "cap").string(),
                                              (dir / "phone.yaml").string(), (dir / "b.json").string()));
  ASSERT_EQ(file.status, 0) << file.err;
  const auto jb = nlohmann::json::parse(io::read_text(dir / "b.json"));
  EXPECT_NEAR(jb["azimuth_true_deg"].get<double>(), 200.0, 0.05);
  EXPECT_TRUE(jb["warnings"].empty());
}

TEST(ContactCli, Errors) {
  test::TempDir dir;
  write_capture(contact_capture(45.0, 6.0, -2.0, ContactPlacement::kTopUp, sim::PhoneModel::ideal()), dir / "cap");
  test::write_file(dir / "bad.yaml", "format: antpose-device\nversion: 1\nimu:\n  magnetometer:\n    hard_iron_uT: [1, x, 3]\n");
  const auto bad = test::run_cli(fmt::format("contact {} --imu-calibration {}", (dir / "cap").string(), (dir / "bad.yaml").string()));
  EXPECT_EQ(bad.status, 2);
  EXPECT_THAT(bad.err, HasSubstr("bad.yaml:5: imu.magnetometer.hard_iron_uT[1]: 'x' is not a number"));

  const auto missing = test::run_cli(fmt::format("contact {} --imu-calibration {}", (dir / "cap").string(), (dir / "nope").string()));
  EXPECT_EQ(missing.status, 2);
  EXPECT_THAT(missing.err, HasSubstr("no such file or folder"));

  const auto placement = test::run_cli(fmt::format("contact {} --placement sideways", (dir / "cap").string()));
  EXPECT_EQ(placement.status, 2);
  EXPECT_THAT(placement.err, HasSubstr("--placement: unknown contact placement 'sideways'"));

  // A calibration folder where the phone was not turned: exit 3 with the coverage message.
  sim::ImuSimulation still;
  still.trajectory = sim::Trajectory(Mat3::Identity()).hold(5.0);
  write_capture(sim::simulate_imu(still), dir / "still");
  const auto cover = test::run_cli(fmt::format("contact {} --imu-calibration {}", (dir / "cap").string(), (dir / "still").string()));
  EXPECT_EQ(cover.status, 3);
  EXPECT_THAT(cover.err, HasSubstr("not turned enough"));

  // No static window: exit 3.
  sim::ImuSimulation moving;
  moving.trajectory =
      sim::Trajectory(Mat3::Identity()).rotate_to(rot_x(1.0), 3.0).rotate_to(rot_y(1.5), 3.0).rotate_to(rot_z(2.0), 3.0);
  write_capture(sim::simulate_imu(moving), dir / "moving");
  const auto none = test::run_cli(fmt::format("contact {}", (dir / "moving").string()));
  EXPECT_EQ(none.status, 3);
  EXPECT_THAT(none.err, HasSubstr("no static window"));
}

}  // namespace
}  // namespace antpose::measure

namespace antpose::measure {
namespace {

// The bundled sample is made with `antpose simulate imu --preset contact`: contact must read it.
TEST(ContactCli, ReadsTheSimulatorContactPreset) {
  test::TempDir dir;
  const auto sim = test::run_cli(fmt::format("simulate imu --preset contact --lat 48.85 --lon 2.35 --date 2026-03-01 -o {}",
                                             (dir / "cap").string()));
  ASSERT_EQ(sim.status, 0) << sim.err;
  const auto res = test::run_cli(
      fmt::format("contact {} --json {} --max-sigma-deg 10", (dir / "cap").string(), (dir / "r.json").string()));
  ASSERT_EQ(res.status, 0) << res.err;  // the uncalibrated phone's azimuth σ of 7° is within this limit
  const auto j = nlohmann::json::parse(io::read_text(dir / "r.json"));
  // Truth: azimuth 0, downtilt 0, roll 0; the typical phone is uncalibrated (10 mg bias,
  // 3.5 µT residual hard iron), hence the loose bounds.
  EXPECT_NEAR(std::remainder(j["azimuth_true_deg"].get<double>(), 360.0), 0.0, 8.0);
  EXPECT_NEAR(j["downtilt_deg"].get<double>(), 0.0, 1.0);
  EXPECT_NEAR(j["roll_deg"].get<double>(), 0.0, 1.0);
}

}  // namespace
}  // namespace antpose::measure

namespace antpose::measure {
namespace {

TEST(ContactCalibration, RecordingGivesHardIronWithAnHonestResidual) {
  sim::ImuSimulation s;
  s.phone = sim::PhoneModel::ideal();
  s.phone.magnetometer.noise_uT = 0.4;
  s.phone.magnetometer.hard_iron_uT = Vec3(20.0, -10.0, 5.0);
  s.trajectory = sim::tumble(30.0, 1.0, 5);
  s.kind = "imu-calibration";
  const Capture recording = sim::simulate_imu(s);
  ContactOptions options;
  const auto hard = calibrate_from_recording(recording, options);
  ASSERT_TRUE(options.calibration);
  EXPECT_EQ(options.calibration->mag_hard_iron_uT, hard.hard_iron_uT);
  // The sphere fit uses every sample and lands on the truth; (max+min)/2 is off by about
  // what it reports as its residual.
  EXPECT_LT((hard.sphere_center_uT - s.phone.magnetometer.hard_iron_uT).norm(), 0.3);
  EXPECT_LT((hard.hard_iron_uT - s.phone.magnetometer.hard_iron_uT).norm(), hard.residual_uT + 0.3);
  EXPECT_GE(options.orientation.mag_residual_uT, hard.residual_uT);
  EXPECT_GE(options.orientation.mag_residual_uT, 1.0);
}

}  // namespace
}  // namespace antpose::measure
