// Acceptance test of the contact measurement on simulated phones (sim/imu_simulator).
//
// 60 random plate attitudes (azimuth uniform 0–360°, downtilt −5..+15°, roll −3..+3°) at four
// sites, each measured with a different random phone (PhoneModel::random: noise, biases, scale,
// soft and hard iron), held 8 s on the plate with hand tremor (0.001 rad rms). The phone is
// calibrated: the simulated hard and soft iron and accelerometer bias and scale are given as
// the ImuCalibration. The calibration file has no accelerometer cross-axis term, so the
// accelerometer misalignment is set to identity for the asserted figures and its effect is
// measured (printed) separately.
#include "antpose/measure/contact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "antpose/geomag/wmm.hpp"
#include "antpose/sim/imu_simulator.hpp"

namespace antpose::measure {
namespace {

struct Errors {
  double az2 = 0, dt2 = 0, roll2 = 0, true_az2 = 0;
  int n = 0, disturbance = 0, within_2sigma_tilt = 0;
  void add(const ContactResult& r, double az_true, double decl, double dt, double roll) {
    const double e_az = rad2deg(wrap_pi(*r.azimuth_magnetic - (az_true - decl)));
    const double e_true = rad2deg(wrap_pi(*r.azimuth_true - az_true));
    const double e_dt = rad2deg(r.downtilt - dt);
    const double e_roll = rad2deg(wrap_pi(*r.roll - roll));
    az2 += e_az * e_az;
    true_az2 += e_true * e_true;
    dt2 += e_dt * e_dt;
    roll2 += e_roll * e_roll;
    within_2sigma_tilt += std::abs(e_dt) <= 2 * rad2deg(r.sigma.downtilt);
    disturbance += r.magnetic_disturbance;
    ++n;
  }
  double rms(double s) const { return std::sqrt(s / n); }
};

std::vector<Site> sites() {
  std::vector<Site> s(4);
  s[0] = {48.85, 2.35, 60.0, "2026-03-01"};      // Paris
  s[1] = {30.26, 120.12, 20.0, "2026-06-15"};    // Hangzhou (the thesis)
  s[2] = {-33.87, 151.21, 50.0, "2025-11-20"};   // Sydney
  s[3] = {61.22, -149.90, 100.0, "2027-01-10"};  // Anchorage (H ≈ 14 µT)
  return s;
}

enum class Scenario { kCalibrated, kWithAccMisalignment, kResidualHardIron1uT, kUncalibrated50uT, kUncalibrated50uTNoSite };

Errors run(Scenario scenario, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> az(0.0, 2 * std::numbers::pi), dt(deg2rad(-5.0), deg2rad(15.0)),
      roll(deg2rad(-3.0), deg2rad(3.0));
  std::normal_distribution<double> n01;
  const auto all_sites = sites();
  const auto model = geomag::MagneticModel::wmm2025();
  Errors e;
  for (int k = 0; k < count; ++k) {
    const Site site = all_sites[static_cast<std::size_t>(k) % all_sites.size()];
    const auto field = geomag::site_field(model, site);
    const double a = az(rng), d = dt(rng), r = roll(rng);
    sim::ImuSimulation s;
    s.phone = sim::PhoneModel::random(rng);
    if (scenario != Scenario::kWithAccMisalignment) s.phone.accelerometer.misalignment = Mat3::Identity();
    s.field_world_uT = field.field_enu_uT;
    if (scenario != Scenario::kUncalibrated50uTNoSite) s.site = site;
    s.seed = seed * 1000 + static_cast<std::uint64_t>(k);
    ContactOptions options;
    if (scenario == Scenario::kUncalibrated50uT || scenario == Scenario::kUncalibrated50uTNoSite) {
      s.phone.magnetometer.hard_iron_uT = 50.0 * Vec3(n01(rng), n01(rng), n01(rng)).normalized();
    } else {
      imu::ImuCalibration cal;
      cal.mag_hard_iron_uT = s.phone.magnetometer.hard_iron_uT;
      cal.mag_soft_iron = s.phone.magnetometer.soft_iron.inverse();
      cal.acc_bias = s.phone.accelerometer.bias;
      cal.acc_scale = s.phone.accelerometer.scale.cwiseInverse();
      if (scenario == Scenario::kResidualHardIron1uT)
        cal.mag_hard_iron_uT += 1.0 * Vec3(n01(rng), n01(rng), n01(rng)).normalized();
      options.calibration = cal;
    }
    const Capture c = sim::simulate_contact(s, rotation_from_attitude(a, d, r), ContactPlacement::kTopUp);
    const ContactResult res = measure_contact(c, options);
    if (scenario == Scenario::kUncalibrated50uTNoSite) {
      e.disturbance += res.magnetic_disturbance;
      ++e.n;
      continue;
    }
    EXPECT_TRUE(res.azimuth_magnetic && res.roll && res.azimuth_true);
    if (!res.azimuth_magnetic || !res.roll || !res.azimuth_true) continue;
    e.add(res, a, field.declination, d, r);
    if (scenario == Scenario::kUncalibrated50uT) {
      bool warned = false;
      for (const auto& w : res.warnings) warned = warned || w.find("magnetic disturbance") != std::string::npos;
      EXPECT_TRUE(warned) << "attitude " << k << " at site " << k % 4 << ": 50 µT hard iron not flagged, field "
                          << res.field_uT << " µT (WMM " << *res.expected_field_uT << "), dip " << rad2deg(res.dip)
                          << "° (WMM " << rad2deg(*res.expected_dip) << "°)";
    }
  }
  return e;
}

void report(const char* name, const Errors& e) {
  std::cout << name << " over " << e.n << " attitudes: RMS downtilt " << e.rms(e.dt2) << "°, roll " << e.rms(e.roll2)
            << "°, magnetic azimuth " << e.rms(e.az2) << "°, true azimuth " << e.rms(e.true_az2)
            << "°; |downtilt error| ≤ 2σ in " << e.within_2sigma_tilt << "; disturbance warnings " << e.disturbance
            << "\n";
}

TEST(ContactAccuracy, CalibratedPhoneMeetsTheTargets) {
  const Errors e = run(Scenario::kCalibrated, 60, 2024);
  report("calibrated", e);
  ::testing::Test::RecordProperty("rms_downtilt_deg", std::to_string(e.rms(e.dt2)));
  ::testing::Test::RecordProperty("rms_roll_deg", std::to_string(e.rms(e.roll2)));
  ::testing::Test::RecordProperty("rms_azimuth_magnetic_deg", std::to_string(e.rms(e.az2)));
  ASSERT_EQ(e.n, 60);
  EXPECT_LE(e.rms(e.dt2), 0.2);
  EXPECT_LE(e.rms(e.roll2), 0.2);
  EXPECT_LE(e.rms(e.az2), 1.0);
  EXPECT_EQ(e.disturbance, 0);
  EXPECT_GE(e.within_2sigma_tilt, 54);  // the reported σ is not optimistic (≥ 90 % within 2σ)
}

TEST(ContactAccuracy, RealisticResidualsAreReported) {
  // Not asserted against the targets: what the uncorrected accelerometer cross-axis error and a
  // 1 µT residual hard iron cost.
  const Errors mis = run(Scenario::kWithAccMisalignment, 40, 7);
  report("with accelerometer misalignment (0.3 % cross-axis, uncorrected)", mis);
  const Errors res = run(Scenario::kResidualHardIron1uT, 40, 8);
  report("with a 1 µT residual hard iron", res);
  EXPECT_LE(mis.rms(mis.dt2), 0.5);
  EXPECT_LE(res.rms(res.az2), 5.0);
}

TEST(ContactAccuracy, UncalibratedHardIronOf50uTIsFlagged) {
  const Errors e = run(Scenario::kUncalibrated50uT, 60, 99);
  report("uncalibrated 50 µT hard iron", e);
  EXPECT_EQ(e.disturbance, e.n);
  // Without a site only the 25–65 µT band is checked: a 50 µT hard iron often stays inside it.
  const Errors no_site = run(Scenario::kUncalibrated50uTNoSite, 60, 99);
  std::cout << "uncalibrated 50 µT hard iron, no site: " << no_site.disturbance << " of " << no_site.n
            << " flagged by the 25–65 µT band\n";
  EXPECT_GT(no_site.disturbance, 0);
}

}  // namespace
}  // namespace antpose::measure
