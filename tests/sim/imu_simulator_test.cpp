#include "antpose/sim/imu_simulator.hpp"

#include <cmath>
#include <numeric>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "antpose/io/text_file.hpp"
#include "antpose/geomag/earth_model.hpp"
#include "support/test_support.hpp"

namespace antpose::sim {
namespace {

using ::testing::HasSubstr;

const Vec3 kField(0.0, 24.0, -41.569219381653056);

Mat3 some_rotation() { return exp_so3(Vec3(0.3, -0.7, 1.1)); }

ImuSimulation still(const Mat3& R, double duration_s) {
  ImuSimulation sim;
  sim.trajectory.hold(R, duration_s);
  sim.field_world_uT = kField;
  return sim;
}

double mean(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()); }
double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}
std::vector<double> column(const Stream& s, int c) {
  std::vector<double> out(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) out[i] = s.values(static_cast<Eigen::Index>(i), c);
  return out;
}

TEST(ImuSimulator, StaticAccelerometerMeanIsRotatedGravity) {
  const Mat3 R = some_rotation();
  ImuSimulation sim = still(R, 20.0);
  sim.phone.accelerometer.noise_density = 180e-6 * 9.80665;
  const Capture c = simulate_imu(sim);
  const Stream& acc = c.require(streams::kAccelerometer);
  ASSERT_GT(acc.size(), 1900u);
  const Vec3 expected = R.transpose() * Vec3(0, 0, 9.80665);
  const double sigma = sim.phone.accelerometer.noise_density * std::sqrt(sim.phone.accelerometer.rate_hz);
  for (int i = 0; i < 3; ++i) {
    const double m = mean(column(acc, i));
    EXPECT_NEAR(m, expected[i], 4.0 * sigma / std::sqrt(static_cast<double>(acc.size()))) << "axis " << i;
  }
  // And the gyroscope of an ideal phone at rest reads exactly zero.
  const Stream& gyr = c.require(streams::kGyroscope);
  EXPECT_LT(gyr.values.cwiseAbs().maxCoeff(), 1e-15);
  // At rest: f = R^T (0, 0, +g) points along the device's "up".
  EXPECT_GT(expected.dot(R.transpose() * Vec3::UnitZ()), 9.8);
}

// Integrates q̇ = ½ q ⊗ (0, ω) with RK4 over pairs of steps (k, k+1, k+2 as start, middle, end).
Quat integrate_rk4(const Stream& gyr, Quat q) {
  auto deriv = [](const Quat& q, const Vec3& w) {
    Quat d = q * Quat(0.0, w.x(), w.y(), w.z());
    d.coeffs() *= 0.5;
    return d;
  };
  auto add = [](const Quat& q, const Quat& d, double h) {
    Quat r;
    r.coeffs() = q.coeffs() + h * d.coeffs();
    return r;
  };
  std::size_t k = 0;
  for (; k + 2 < gyr.size(); k += 2) {
    const double h = gyr.t[k + 2] - gyr.t[k];
    const Vec3 w0 = gyr.xyz(k), w1 = gyr.xyz(k + 1), w2 = gyr.xyz(k + 2);
    const Quat k1 = deriv(q, w0), k2 = deriv(add(q, k1, h / 2), w1), k3 = deriv(add(q, k2, h / 2), w1),
               k4 = deriv(add(q, k3, h), w2);
    q.coeffs() += h / 6.0 * (k1.coeffs() + 2 * k2.coeffs() + 2 * k3.coeffs() + k4.coeffs());
    q.normalize();
  }
  return q;
}

TEST(ImuSimulator, GyroIntegrationReproducesRotateTo) {
  const Mat3 R0 = some_rotation();
  const Mat3 R1 = R0 * exp_so3(Vec3(1.2, -0.9, 1.5));  // ≈ 124°
  ImuSimulation sim;
  sim.trajectory.hold(R0, 0.5).rotate_to(R1, 2.0).hold(0.5);
  sim.phone.gyroscope.rate_hz = 200;
  const Capture c = simulate_imu(sim);
  const Stream& gyr = c.require(streams::kGyroscope);
  // Use an odd number of samples so the pairs cover from the first sample to the last.
  Stream used = gyr;
  if (used.size() % 2 == 0) {
    used.t.pop_back();
    used.values.conservativeResize(used.values.rows() - 1, 3);
  }
  const Quat q_end = integrate_rk4(used, Quat(sim.trajectory.R_world_device(used.t.front())));
  const Mat3 R_expected = sim.trajectory.R_world_device(used.t.back());
  EXPECT_LT(rad2deg(rotation_distance(q_end.toRotationMatrix(), R_expected)), 0.05);
  EXPECT_LT(rotation_distance(R_expected, R1), 1e-9);
}

TEST(ImuSimulator, GyroIntegrationFollowsTremor) {
  ImuSimulation sim;
  sim.trajectory = random_rotations(3, 1.0, 1.5, 4).with_tremor(0.003, 1e-5, 5);
  sim.phone.gyroscope.rate_hz = 400;
  const Capture c = simulate_imu(sim);
  Stream used = c.require(streams::kGyroscope);
  if (used.size() % 2 == 0) {
    used.t.pop_back();
    used.values.conservativeResize(used.values.rows() - 1, 3);
  }
  const Quat q_end = integrate_rk4(used, Quat(sim.trajectory.R_world_device(used.t.front())));
  EXPECT_LT(rad2deg(rotation_distance(q_end.toRotationMatrix(), sim.trajectory.R_world_device(used.t.back()))), 0.05);
}

TEST(ImuSimulator, AnalyticDerivativesMatchFiniteDifferencesWithTremor) {
  Trajectory tr(some_rotation(), Vec3(1, 2, 3));
  tr.hold(0.5).move_to(exp_so3(Vec3(-0.4, 0.2, 2.0)), Vec3(1.3, 1.8, 3.4), 1.5).hold(0.5).with_tremor(0.01, 0.001, 7);
  const double h = 1e-5;
  for (double t : {0.2, 0.7, 1.1, 1.6, 2.2}) {
    const Vec3 w_fd = log_so3(tr.R_world_device(t - h).transpose() * tr.R_world_device(t + h)) / (2 * h);
    EXPECT_LT((tr.angular_velocity_device(t) - w_fd).norm(), 1e-6) << "t = " << t;
    const double h2 = 1e-3;
    const Vec3 a_fd = (tr.position_world(t + h2) - 2 * tr.position_world(t) + tr.position_world(t - h2)) / (h2 * h2);
    EXPECT_LT((tr.acceleration_world(t) - a_fd).norm(), 1e-3 * std::max(1.0, a_fd.norm())) << "t = " << t;
  }
  EXPECT_TRUE(tr.moving(1.0));
  EXPECT_FALSE(tr.moving(0.2));
  ASSERT_EQ(tr.holds().size(), 2u);
  EXPECT_DOUBLE_EQ(tr.holds()[1].first, 2.0);
}

TEST(ImuSimulator, TremorHasTheRequestedRms) {
  Trajectory tr;
  tr.hold(Mat3::Identity(), 200.0).with_tremor(0.002, 0.0001, 3);
  double sr = 0, sp = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double t = 200.0 * i / n;
    sr += std::pow(rotation_angle(tr.R_world_device(t)), 2);
    sp += tr.position_world(t).squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(sr / n), 0.002, 0.0004);
  EXPECT_NEAR(std::sqrt(sp / n), 0.0001, 0.00002);
}

TEST(ImuSimulator, WhiteNoiseStdIsDensityTimesSqrtRate) {
  ImuSimulation sim = still(Mat3::Identity(), 60.0);
  sim.phone.accelerometer.noise_density = 1e-3;
  sim.phone.accelerometer.rate_hz = 200;
  sim.phone.gyroscope.noise_density = 2e-4;
  sim.phone.gyroscope.rate_hz = 400;
  sim.phone.magnetometer.noise_uT = 0.4;
  const Capture c = simulate_imu(sim);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(stddev(column(c.require(streams::kAccelerometer), i)) / (1e-3 * std::sqrt(200.0)), 1.0, 0.03);
    EXPECT_NEAR(stddev(column(c.require(streams::kGyroscope), i)) / (2e-4 * std::sqrt(400.0)), 1.0, 0.03);
    EXPECT_NEAR(stddev(column(c.require(streams::kMagnetometer), i)) / 0.4, 1.0, 0.04);
  }
}

TEST(ImuSimulator, BiasRandomWalkVarianceGrowsLinearly) {
  const double K = 0.01;  // rad/s/s/√Hz
  std::vector<double> at5, at10;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    ImuSimulation sim = still(Mat3::Identity(), 10.0);
    sim.phone.gyroscope.bias_random_walk = K;
    sim.phone.gyroscope.rate_hz = 10;
    sim.phone.magnetometer.rate_hz = 1;
    sim.truth_rate_hz = 1;
    sim.seed = seed;
    const Stream g = simulate_imu(sim).require(streams::kGyroscope);
    // Sample k sits at phase + k/10 ≤ 0.1 + k/10.
    for (int i = 0; i < 3; ++i) {
      at5.push_back(g.values(49, i));
      at10.push_back(g.values(98, i));
    }
  }
  auto var0 = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x * x;
    return s / static_cast<double>(v.size());
  };
  // Var(b_w(t)) = K² t (IEEE Std 952 rate random walk); t ≈ 4.95 and 9.85 s.
  EXPECT_NEAR(var0(at5) / (K * K * 4.95), 1.0, 0.2);
  EXPECT_NEAR(var0(at10) / (K * K * 9.85), 1.0, 0.2);
  EXPECT_NEAR(var0(at10) / var0(at5), 9.85 / 4.95, 0.4);
}

TEST(ImuSimulator, InertialErrorsAreAppliedAsTKxPlusB) {
  const Mat3 R = some_rotation();
  ImuSimulation sim = still(R, 2.0);
  auto& a = sim.phone.accelerometer;
  a.misalignment << 1, 0.01, -0.02, 0.005, 1, 0.015, -0.01, 0.02, 1;
  a.scale = Vec3(1.01, 0.98, 1.03);
  a.bias = Vec3(0.1, -0.2, 0.3);
  const Capture c = simulate_imu(sim);
  const Vec3 f = R.transpose() * Vec3(0, 0, 9.80665);
  const Vec3 expected = a.misalignment * Vec3(1.01 * f.x(), 0.98 * f.y(), 1.03 * f.z()) + a.bias;
  EXPECT_LT((c.require(streams::kAccelerometer).xyz(10) - expected).norm(), 1e-12);
}

TEST(ImuSimulator, HardAndSoftIronAreAppliedAsSpecified) {
  ImuSimulation sim;
  sim.trajectory = random_rotations(4, 1.0, 1.0, 11);
  sim.field_world_uT = kField;
  sim.phone.magnetometer.hard_iron_uT = Vec3(12, -30, 7);
  sim.phone.magnetometer.soft_iron << 1.05, 0.02, 0.0, 0.02, 0.95, -0.03, 0.0, -0.03, 1.1;
  const Capture c = simulate_imu(sim);
  const Stream& mag = c.require(streams::kMagnetometer);
  for (std::size_t k = 0; k < mag.size(); k += 17) {
    const Vec3 expected = sim.phone.magnetometer.soft_iron * (sim.trajectory.R_world_device(mag.t[k]).transpose() * kField) +
                          sim.phone.magnetometer.hard_iron_uT;
    EXPECT_LT((mag.xyz(k) - expected).norm(), 1e-12);
  }
}

TEST(ImuSimulator, JitterKeepsTimesIncreasingWithTheRequestedStd) {
  ImuSimulation sim = still(Mat3::Identity(), 100.0);
  sim.phone.accelerometer.rate_hz = 100;
  sim.phone.accelerometer.rate_jitter_s = 1e-3;
  const Stream acc = simulate_imu(sim).require(streams::kAccelerometer);
  std::vector<double> resid(acc.size());
  for (std::size_t k = 0; k < acc.size(); ++k) {
    if (k > 0) {
      ASSERT_GT(acc.t[k], acc.t[k - 1]);
    }
    resid[k] = acc.t[k] - static_cast<double>(k) / 100.0;  // phase + jitter
  }
  EXPECT_NEAR(stddev(resid) / 1e-3, 1.0, 0.05);
  // No jitter: exactly periodic.
  const Stream gyr = simulate_imu(sim).require(streams::kGyroscope);
  EXPECT_NEAR(gyr.t[100] - gyr.t[0], 1.0, 1e-12);
}

TEST(ImuSimulator, HeavyJitterStillIncreases) {
  ImuSimulation sim = still(Mat3::Identity(), 20.0);
  sim.phone.magnetometer.rate_jitter_s = 0.05;  // larger than the period (0.02 s)
  const Stream mag = simulate_imu(sim).require(streams::kMagnetometer);
  for (std::size_t k = 1; k < mag.size(); ++k) ASSERT_GT(mag.t[k], mag.t[k - 1]);
}

TEST(ImuSimulator, DisturbanceOnlyInsideItsWindow) {
  const Mat3 R = some_rotation();
  ImuSimulation sim = still(R, 6.0);
  sim.disturbances.push_back({2.0, 4.0, Vec3(10, 0, -5)});
  const Stream mag = simulate_imu(sim).require(streams::kMagnetometer);
  int inside = 0, outside = 0;
  for (std::size_t k = 0; k < mag.size(); ++k) {
    const bool in = mag.t[k] >= 2.0 && mag.t[k] < 4.0;
    const Vec3 B = in ? Vec3(kField + Vec3(10, 0, -5)) : kField;
    EXPECT_LT((mag.xyz(k) - R.transpose() * B).norm(), 1e-12) << "t = " << mag.t[k];
    (in ? inside : outside)++;
  }
  EXPECT_GT(inside, 90);
  EXPECT_GT(outside, 190);
}

TEST(ImuSimulator, TruthQuaternionsMatchTrajectory) {
  ImuSimulation sim;
  sim.trajectory = random_rotations(3, 0.5, 1.0, 5).with_tremor(0.003, 0.0, 9);
  const Capture c = simulate_imu(sim);
  ASSERT_TRUE(c.truth_orientation);
  const Stream& q = *c.truth_orientation;
  ASSERT_EQ(q.columns, (std::vector<std::string>{"qw", "qx", "qy", "qz", "valid", "moving"}));
  EXPECT_EQ(q.size(), static_cast<std::size_t>(std::floor(sim.trajectory.duration() * 200)) + 1);
  for (std::size_t j = 0; j < q.size(); j += 7) {
    const auto r = q.values.row(static_cast<Eigen::Index>(j));
    const Quat qwd(r(0), r(1), r(2), r(3));
    EXPECT_NEAR(qwd.norm(), 1.0, 1e-12);
    EXPECT_GE(r(0), 0.0);
    EXPECT_LT(rotation_distance(qwd.toRotationMatrix(), sim.trajectory.R_world_device(q.t[j])), 1e-12);
    EXPECT_EQ(r(4), 1.0);
    EXPECT_EQ(r(5), sim.trajectory.moving(q.t[j]) ? 1.0 : 0.0);
  }
}

TEST(ImuSimulator, DeterministicForASeed) {
  ImuSimulation sim = still(some_rotation(), 3.0);
  sim.phone = PhoneModel::typical();
  const Capture a = simulate_imu(sim), b = simulate_imu(sim);
  sim.seed = 2;
  const Capture d = simulate_imu(sim);
  for (const auto* name : {"accelerometer", "gyroscope", "magnetometer"}) {
    EXPECT_EQ(a.require(name).t, b.require(name).t);
    EXPECT_TRUE(a.require(name).values == b.require(name).values);
    EXPECT_FALSE(a.require(name).values.rows() == d.require(name).values.rows() &&
                 a.require(name).values == d.require(name).values);
  }
  std::mt19937_64 r1(4), r2(4);
  EXPECT_TRUE(PhoneModel::random(r1).accelerometer.bias == PhoneModel::random(r2).accelerometer.bias);
}

TEST(ImuSimulator, PhoneModelsHaveDatasheetFigures) {
  const PhoneModel t = PhoneModel::typical();
  EXPECT_NEAR(t.accelerometer.noise_density, 180e-6 * 9.80665, 1e-9);
  EXPECT_NEAR(rad2deg(t.gyroscope.noise_density), 0.007, 1e-12);
  EXPECT_GE(t.magnetometer.noise_uT, 0.3);
  EXPECT_LE(t.magnetometer.noise_uT, 0.6);
  const PhoneModel i = PhoneModel::ideal();
  EXPECT_EQ(i.accelerometer.noise_density, 0.0);
  EXPECT_TRUE(i.magnetometer.soft_iron.isIdentity());
  std::mt19937_64 rng(1);
  const PhoneModel r = PhoneModel::random(rng);
  EXPECT_TRUE(r.magnetometer.soft_iron.isApprox(r.magnetometer.soft_iron.transpose()));
  EXPECT_LT((r.accelerometer.misalignment.diagonal() - Vec3::Ones()).norm(), 1e-15);
  EXPECT_LT(r.accelerometer.bias.norm(), 1.0);
}

TEST(ImuSimulator, CaptureRoundTripsWithTruth) {
  test::TempDir dir;
  ImuSimulation sim;
  sim.trajectory = random_rotations(2, 1.0, 1.0, 3);
  sim.phone = PhoneModel::typical();
  sim.site = Site{48.1, 11.6, 520, "2025-06-01"};
  sim.time_origin = "2025-06-01T10:00:00Z";
  sim.disturbances.push_back({0.5, 1.0, Vec3(1, 2, 3)});
  const Capture c = simulate_imu(sim);
  write_capture(c, dir / "cap");
  Diagnostics diag;
  const Capture r = read_capture(dir / "cap", diag);
  EXPECT_TRUE(diag.empty()) << diag.warnings().front().to_string();
  EXPECT_EQ(r.kind, "imu-log");
  EXPECT_EQ(r.truth_world, "enu-true");
  EXPECT_EQ(r.device_model, "simulated typical");
  ASSERT_TRUE(r.site);
  EXPECT_EQ(r.site->date, "2025-06-01");
  for (const auto* name : {"accelerometer", "gyroscope", "magnetometer"}) {
    EXPECT_EQ(r.require(name).t, c.require(name).t);
    EXPECT_TRUE(r.require(name).values == c.require(name).values) << name;
  }
  ASSERT_TRUE(r.truth_orientation);
  EXPECT_TRUE(r.truth_orientation->values == c.truth_orientation->values);
  ASSERT_THAT(r.other_files, ::testing::Contains(std::filesystem::path("truth/device.yaml")));
  EXPECT_EQ(r.metadata["truth"]["device"].as<std::string>(), "truth/device.yaml");
  const YAML::Node dev = YAML::Load(io::read_text(dir / "cap" / "truth/device.yaml"));
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(dev["accelerometer"]["bias"][i].as<double>(), sim.phone.accelerometer.bias[i]);
    EXPECT_EQ(dev["magnetometer"]["soft_iron"][1][i].as<double>(), sim.phone.magnetometer.soft_iron(1, i));
  }
  EXPECT_EQ(dev["gyroscope"]["noise_density"].as<double>(), sim.phone.gyroscope.noise_density);
  EXPECT_EQ(dev["disturbances"][0]["t1"].as<double>(), 1.0);
  // Rewriting the read capture keeps the truth file (now an ordinary other file).
  write_capture(r, dir / "cap2");
  EXPECT_EQ(io::read_text(dir / "cap2" / "truth/device.yaml"), io::read_text(dir / "cap" / "truth/device.yaml"));
}

TEST(ImuSimulator, ContactCaptureHasSceneTruth) {
  const double az = deg2rad(123.0), tilt = deg2rad(6.0), roll = deg2rad(-1.5);
  const Mat3 R_wa = rotation_from_attitude(az, tilt, roll);
  ImuSimulation sim;
  sim.field_world_uT = Vec3(5.0, 20.0, -40.0);  // declination atan2(5, 20) ≈ 14.04° east
  ContactMotion motion;
  motion.tremor_rotation_rms_rad = 0;
  motion.tremor_translation_rms_m = 0;
  const Capture c = simulate_contact(sim, R_wa, ContactPlacement::kTopUp, motion);
  EXPECT_EQ(c.kind, "contact");
  ASSERT_TRUE(c.generated_files.contains("truth/scene.yaml"));
  const YAML::Node scene = YAML::Load(c.generated_files.at("truth/scene.yaml"));
  const double decl = rad2deg(std::atan2(5.0, 20.0));
  EXPECT_NEAR(scene["antennas"][0]["azimuth_deg"].as<double>(), 123.0, 1e-9);
  EXPECT_NEAR(scene["antennas"][0]["magnetic_azimuth_deg"].as<double>(), 123.0 - decl, 1e-9);
  EXPECT_NEAR(scene["antennas"][0]["downtilt_deg"].as<double>(), 6.0, 1e-9);
  EXPECT_NEAR(scene["antennas"][0]["roll_deg"].as<double>(), -1.5, 1e-9);
  EXPECT_NEAR(scene["antennas"][0]["declination_deg"].as<double>(), decl, 1e-9);
  EXPECT_EQ(scene["contact"]["placement"].as<std::string>(), "top-up");
  const double h0 = scene["contact"]["hold"][0].as<double>(), h1 = scene["contact"]["hold"][1].as<double>();
  EXPECT_DOUBLE_EQ(h0, 3.5);
  EXPECT_DOUBLE_EQ(h1, 11.5);
  Mat3 R_wa_back;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R_wa_back(i, j) = scene["antennas"][0]["R_world_antenna"][i][j].as<double>();
  EXPECT_TRUE(R_wa_back.isApprox(R_wa, 1e-15));

  // During the hold the device lies on the plate: R_world_device = R_world_antenna R_device_antenna^T,
  // so the accelerometer sees the boresight's tilt: f = R_device_antenna R_world_antenna^T (0,0,g).
  const Stream& acc = c.require(streams::kAccelerometer);
  const Vec3 f_expected = contact_rotation(ContactPlacement::kTopUp) * R_wa.transpose() * Vec3(0, 0, 9.80665);
  for (std::size_t k = 0; k < acc.size(); ++k)
    if (acc.t[k] > h0 && acc.t[k] < h1) {
      EXPECT_LT((acc.xyz(k) - f_expected).norm(), 1e-12);
    }
  // The screen (device z) faces backwards: minus the boresight.
  const Mat3 R_wd = contact_device_rotation(R_wa, ContactPlacement::kTopUp);
  EXPECT_LT((R_wd.col(2) + R_wa.col(1)).norm(), 1e-15);
  // Moving before and after the hold.
  const Stream& gyr = c.require(streams::kGyroscope);
  double max_rate = 0;
  for (std::size_t k = 0; k < gyr.size(); ++k)
    if (gyr.t[k] < h0) max_rate = std::max(max_rate, gyr.xyz(k).norm());
  EXPECT_GT(max_rate, 0.3);
}

TEST(ImuSimulator, PresetsAreWellFormed) {
  const auto poses = calibration_poses();
  ASSERT_EQ(poses.size(), 18u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_LT((poses[i] * poses[i].transpose() - Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(poses[i].determinant(), 1.0, 1e-12);
    for (std::size_t j = 0; j < i; ++j) EXPECT_GT(rotation_distance(poses[i], poses[j]), 0.1);
  }
  const Trajectory s = static_poses(poses, 2.0, 1.5);
  EXPECT_DOUBLE_EQ(s.duration(), 18 * 2.0 + 17 * 1.5);
  EXPECT_EQ(s.holds().size(), 18u);
  EXPECT_LT(rotation_distance(s.R_world_device(s.holds()[5].first + 1.0), poses[5]), 1e-12);
  const Trajectory t = tumble(20.0, 1.0, 4);
  EXPECT_NEAR(t.duration(), 20.0, 1.0);
  EXPECT_EQ(t.holds().size(), 2u);
}

TEST(ImuSimulator, BadArgumentsAreRejected) {
  Trajectory tr;
  tr.hold(Mat3::Identity(), 1.0);
  try {
    tr.hold(rot_z(0.1), 1.0);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("use rotate_to"));
  }
  EXPECT_THROW(tr.rotate_to(rot_z(1.0), 0.0), std::invalid_argument);
  EXPECT_THROW(simulate_imu(ImuSimulation{}), std::invalid_argument);
  ImuSimulation sim = still(Mat3::Identity(), 1.0);
  sim.phone.accelerometer.rate_hz = -5;
  try {
    simulate_imu(sim);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("-5 Hz must be positive"));
  }
}

TEST(ImuSimulator, EarthRotationNeedsASiteAndTurnsTheGyroscope) {
  ImuSimulation sim = still(Mat3::Identity(), 1.0);
  sim.earth_rotation = true;
  EXPECT_THROW(simulate_imu(sim), std::invalid_argument);
  sim.site = Site{45.0, 0.0, 0.0, ""};
  const Stream g = simulate_imu(sim).require(streams::kGyroscope);
  EXPECT_LT((g.xyz(0) - geomag::earth_rate_enu(45.0)).norm(), 1e-18);
}

}  // namespace
}  // namespace antpose::sim
