#include "antpose/orientation/static_orientation.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "antpose/geometry/attitude.hpp"

namespace antpose::orientation {
namespace {

using ::testing::HasSubstr;

constexpr double kG = 9.80665;
const Vec3 kFieldWorld(0.0, 20.0, -40.0);  // ENU magnetic: H = 20 µT north, 40 µT down

// A still phone at R_world_device: acc at 100 Hz, mag at 50 Hz (asynchronous), optional
// white noise (per axis) and AR(1)-correlated noise with coefficient rho.
Capture still_capture(const Mat3& R_world_device, double duration_s, double acc_noise = 0.0, double mag_noise = 0.0,
                      double rho = 0.0, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  const Vec3 f = R_world_device.transpose() * Vec3(0, 0, kG);
  const Vec3 m = R_world_device.transpose() * kFieldWorld;
  auto make = [&](const char* name, double rate, double offset, const Vec3& value, double sigma) {
    std::vector<double> t;
    std::vector<Vec3> v;
    Vec3 state = Vec3::Zero();
    const double innovation = sigma * std::sqrt(1.0 - rho * rho);
    state = sigma * Vec3(n01(rng), n01(rng), n01(rng));
    for (double ti = offset; ti < duration_s; ti += 1.0 / rate) {
      t.push_back(ti);
      v.push_back(value + state);
      state = rho * state + innovation * Vec3(n01(rng), n01(rng), n01(rng));
    }
    return Stream::vector3(name, t, v);
  };
  Capture c;
  c.streams["accelerometer"] = make("accelerometer", 100.0, 0.0, f, acc_noise);
  c.streams["magnetometer"] = make("magnetometer", 50.0, 0.0037, m, mag_noise);
  return c;
}

void expect_rotation_near(const Mat3& a, const Mat3& b, double tol) {
  EXPECT_LT(rotation_distance(a, b), tol) << "got\n" << a << "\nexpected\n" << b;
}

// Phone flat, screen up, top pointing at heading psi (clockwise from magnetic north):
// R_world_device = Rz(-psi). Every quadrant.
class FlatHeading : public ::testing::TestWithParam<double> {};

TEST_P(FlatHeading, RecoversRotationAndAndroidAngles) {
  const double psi = deg2rad(GetParam());
  const Mat3 R = rot_z(-psi);
  const auto so = estimate_static_orientation(still_capture(R, 3.0), 0.0, 3.0);
  expect_rotation_near(so.R_world_device, R, 1e-12);
  EXPECT_NEAR(rad2deg(wrap_pi(so.android.azimuth - psi)), 0.0, 1e-9);
  EXPECT_NEAR(so.android.pitch, 0.0, 1e-12);
  EXPECT_NEAR(so.android.roll, 0.0, 1e-12);
  EXPECT_NEAR(so.field_uT, kFieldWorld.norm(), 1e-9);
  EXPECT_NEAR(so.horizontal_field_uT, 20.0, 1e-9);
  EXPECT_NEAR(rad2deg(so.dip), rad2deg(std::atan2(40.0, 20.0)), 1e-9);
  EXPECT_NEAR(so.gravity_mps2, kG, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Quadrants, FlatHeading, ::testing::Values(0.0, 30.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0));

// Upright phone (the contact pose): screen towards the viewer, top up, the back (−z) facing
// heading psi. No singularity here; Android's azimuth is degenerate (pitch −90°).
class UprightHeading : public ::testing::TestWithParam<double> {};

TEST_P(UprightHeading, RecoversRotationWithoutSingularity) {
  const double psi = deg2rad(GetParam());
  const Mat3 R_world_antenna = rotation_from_attitude(psi, 0.0, 0.0);
  const Mat3 R = R_world_antenna * contact_rotation(ContactPlacement::kTopUp).transpose();
  const auto so = estimate_static_orientation(still_capture(R, 3.0), 0.0, 3.0);
  expect_rotation_near(so.R_world_device, R, 1e-12);
  EXPECT_NEAR(rad2deg(so.android.pitch), -90.0, 1e-6);
  // The device's −z (the back) points along the boresight, at heading psi.
  const Vec3 back = so.R_world_device * Vec3(0, 0, -1);
  EXPECT_NEAR(rad2deg(wrap_pi(std::atan2(back.x(), back.y()) - psi)), 0.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Quadrants, UprightHeading, ::testing::Values(10.0, 100.0, 190.0, 280.0));

TEST(StaticOrientation, UpsideDownScreenDown) {
  // Screen facing the ground: rotate the flat pose 180° about the device y axis.
  for (double deg : {0.0, 60.0, 200.0, 300.0}) {
    const Mat3 R = rot_z(-deg2rad(deg)) * rot_y(std::numbers::pi);
    const auto so = estimate_static_orientation(still_capture(R, 2.0), 0.0, 2.0);
    expect_rotation_near(so.R_world_device, R, 1e-12);
    EXPECT_NEAR(rad2deg(wrap_pi(so.android.azimuth - deg2rad(deg))), 0.0, 1e-9);
    EXPECT_NEAR(std::abs(rad2deg(so.android.roll)), 180.0, 1e-9);
    EXPECT_NEAR(so.android.pitch, 0.0, 1e-12);
  }
}

TEST(StaticOrientation, AndroidAnglesMatchGetOrientationFormulas) {
  // Phone tilted: top raised by 20° (pitch −20° in Android's convention), heading 40°.
  const Mat3 R = rot_z(-deg2rad(40.0)) * rot_x(deg2rad(20.0));
  const auto a = android_orientation(R);
  EXPECT_NEAR(rad2deg(a.azimuth), 40.0, 1e-9);
  EXPECT_NEAR(rad2deg(a.pitch), -20.0, 1e-9);
  EXPECT_NEAR(a.roll, 0.0, 1e-12);
}

TEST(StaticOrientation, WhiteNoiseUncertaintyMatchesTheory) {
  const double sa = 0.03, sm = 0.5;
  const Mat3 R = rot_z(-deg2rad(70.0)) * rot_x(deg2rad(80.0));
  StaticOrientationOptions no_floor;
  no_floor.acc_bias_floor_mps2 = 0.0;
  no_floor.mag_residual_uT = 0.0;
  const auto so = estimate_static_orientation(still_capture(R, 8.0, sa, sm, 0.0, 7), 0.0, 8.0, no_floor);
  const double expected_tilt = sa / kG / std::sqrt(800.0);
  EXPECT_NEAR(so.tilt_sigma_scatter / expected_tilt, 1.0, 0.35);
  const double expected_heading =
      std::sqrt(std::pow(sm / 20.0, 2) / 400.0 + std::pow(expected_tilt * 2.0, 2));  // tan(dip) = 2
  EXPECT_NEAR(so.heading_sigma_scatter / expected_heading, 1.0, 0.35);
  EXPECT_GT(so.acc_n_eff, 400.0);
  EXPECT_NEAR(rad2deg(so.acc_direction_std), rad2deg(sa / kG * std::sqrt(2.0)), 0.05);
}

TEST(StaticOrientation, CorrelatedNoiseLowersEffectiveSamplesAndStaysCalibrated) {
  // AR(1) with rho = 0.95: N_eff ≈ N (1 − ρ)/(1 + ρ) ≈ N/39. Over many windows the predicted
  // σ must match the actual scatter of the tilt error.
  const double rho = 0.95, sa = 0.05;
  const Mat3 R = rot_z(-deg2rad(20.0)) * rot_x(deg2rad(85.0));
  StaticOrientationOptions no_floor;
  no_floor.acc_bias_floor_mps2 = 0.0;
  no_floor.mag_residual_uT = 0.0;
  double err2 = 0.0, sigma2 = 0.0, n_eff = 0.0;
  const int trials = 150;
  for (int k = 0; k < trials; ++k) {
    const auto so = estimate_static_orientation(still_capture(R, 8.0, sa, 0.3, rho, 100 + k), 0.0, 8.0, no_floor);
    const Vec3 up_true = R.transpose().col(2);  // world up in device coordinates
    const double e = angle_between(so.R_world_device.row(2).transpose(), up_true);
    err2 += e * e / 2.0;  // per-axis variance (two tilt axes)
    sigma2 += so.tilt_sigma_scatter * so.tilt_sigma_scatter;
    n_eff += so.acc_n_eff;
  }
  const double ratio = std::sqrt(err2 / sigma2);
  EXPECT_GT(ratio, 0.7) << "predicted tilt σ too large";
  EXPECT_LT(ratio, 1.4) << "predicted tilt σ too small (correlation ignored?)";
  n_eff /= trials;
  EXPECT_GT(n_eff, 800.0 / 80.0);
  EXPECT_LT(n_eff, 800.0 / 15.0);
}

TEST(StaticOrientation, FloorsAddToScatter) {
  const Mat3 R = rot_x(deg2rad(90.0));
  const auto so = estimate_static_orientation(still_capture(R, 4.0), 0.0, 4.0);  // defaults, no noise
  EXPECT_NEAR(so.tilt_sigma, 0.02 / kG, 1e-9);
  const double heading_floor = std::hypot(1.0 / (std::sqrt(3.0) * 20.0), 0.02 / kG * 2.0);
  EXPECT_NEAR(so.heading_sigma, heading_floor, 1e-9);
}

TEST(StaticOrientation, Errors) {
  Capture only_acc = still_capture(Mat3::Identity(), 2.0);
  only_acc.streams.erase("magnetometer");
  try {
    estimate_static_orientation(only_acc, 0.0, 2.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no magnetometer stream"));
  }
  try {
    estimate_static_orientation(still_capture(Mat3::Identity(), 2.0), 5.0, 6.0);
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("at least 5 of each are needed"));
  }
  // Field parallel to gravity: no heading.
  EXPECT_THROW(triad_world_device(Vec3(0, 0, 9.8), Vec3(0, 0, -50)), MeasurementError);
  try {
    triad_world_device(Vec3(0, 0, 9.8), Vec3(0, 0, -50));
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("parallel to gravity"));
  }
}

}  // namespace
}  // namespace antpose::orientation
