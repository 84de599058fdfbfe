#include "antpose/geometry/attitude.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace antpose {
namespace {

constexpr double kTol = 1e-12;

Mat3 R_from_axes(const Vec3& x_a, const Vec3& y_a, const Vec3& z_a) {
  Mat3 R;
  R << x_a, y_a, z_a;  // columns: antenna axes in ENU
  return R;
}

TEST(Attitude, LevelNorthIsIdentity) {
  EXPECT_TRUE(rotation_from_attitude(0, 0, 0).isApprox(Mat3::Identity(), kTol));
  const auto a = attitude_from_rotation(Mat3::Identity());
  ASSERT_TRUE(a.azimuth && a.roll);
  EXPECT_NEAR(*a.azimuth, 0.0, kTol);
  EXPECT_NEAR(a.downtilt, 0.0, kTol);
  EXPECT_NEAR(*a.roll, 0.0, kTol);
}

// Closed-form cases: boresight along each compass quadrant, level, upright.
struct Quadrant {
  double azimuth_deg;
  Vec3 boresight_enu;
};

class AttitudeQuadrant : public ::testing::TestWithParam<Quadrant> {};

TEST_P(AttitudeQuadrant, AzimuthIsClockwiseFromNorth) {
  const auto q = GetParam();
  const Vec3 z_a = Vec3::UnitZ();
  const Vec3 y_a = q.boresight_enu.normalized();
  const Mat3 R = R_from_axes(y_a.cross(z_a), y_a, z_a);
  const auto a = attitude_from_rotation(R);
  ASSERT_TRUE(a.azimuth);
  EXPECT_NEAR(rad2deg(*a.azimuth), q.azimuth_deg, 1e-9);
  EXPECT_NEAR(a.downtilt, 0.0, kTol);
  EXPECT_NEAR(*a.roll, 0.0, kTol);
  EXPECT_TRUE(rotation_from_attitude(deg2rad(q.azimuth_deg), 0, 0).isApprox(R, 1e-12));
}

INSTANTIATE_TEST_SUITE_P(Compass, AttitudeQuadrant,
                         ::testing::Values(Quadrant{0, {0, 1, 0}}, Quadrant{45, {1, 1, 0}}, Quadrant{90, {1, 0, 0}},
                                           Quadrant{135, {1, -1, 0}}, Quadrant{180, {0, -1, 0}}, Quadrant{225, {-1, -1, 0}},
                                           Quadrant{270, {-1, 0, 0}}, Quadrant{315, {-1, 1, 0}}));

TEST(Attitude, DowntiltPositiveWhenBoresightBelowHorizon) {
  // Facing east, pointing 10° down: b = (cos10, 0, -sin10); the long axis leans back (towards west-up).
  const double d = deg2rad(10.0);
  const Vec3 b(std::cos(d), 0, -std::sin(d));
  const Vec3 u(std::sin(d), 0, std::cos(d));
  const Mat3 R = R_from_axes(b.cross(u), b, u);
  const auto a = attitude_from_rotation(R);
  EXPECT_NEAR(rad2deg(*a.azimuth), 90.0, 1e-9);
  EXPECT_NEAR(rad2deg(a.downtilt), 10.0, 1e-9);
  EXPECT_NEAR(*a.roll, 0.0, 1e-12);
  EXPECT_TRUE(rotation_from_attitude(deg2rad(90), d, 0).isApprox(R, 1e-12));
  // Uptilt is negative downtilt.
  EXPECT_NEAR(rad2deg(attitude_from_rotation(rotation_from_attitude(0, -d, 0)).downtilt), -10.0, 1e-9);
}

TEST(Attitude, RollPositiveWhenRightSideGoesDown) {
  // Facing north, level boresight, rolled 5° clockwise seen from behind: x_a (east) dips.
  const double r = deg2rad(5.0);
  const Mat3 R = rotation_from_attitude(0, 0, r);
  EXPECT_LT(R.col(0).z(), 0.0);  // right-hand side (x_a) goes down
  EXPECT_NEAR(R.col(0).z(), -std::sin(r), kTol);
  EXPECT_NEAR(R.col(2).x(), std::sin(r), kTol);  // the top leans right (east)
  const auto a = attitude_from_rotation(R);
  EXPECT_NEAR(rad2deg(*a.roll), 5.0, 1e-9);
}

TEST(Attitude, RoundTripRandom) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> az(0, 2 * std::numbers::pi), tilt(-1.5, 1.5), roll(-3.1, 3.1);
  for (int i = 0; i < 1000; ++i) {
    const double A = az(rng), D = tilt(rng), Rr = roll(rng);
    const auto a = attitude_from_rotation(rotation_from_attitude(A, D, Rr));
    ASSERT_TRUE(a.azimuth && a.roll);
    EXPECT_NEAR(wrap_pi(*a.azimuth - A), 0.0, 1e-9);
    EXPECT_NEAR(a.downtilt, D, 1e-9);
    EXPECT_NEAR(wrap_pi(*a.roll - Rr), 0.0, 1e-9);
  }
}

TEST(Attitude, VerticalBoresightLeavesAzimuthAndRollUndefined) {
  for (double tilt_deg : {90.0, -90.0, 89.5, -89.5}) {
    const auto a = attitude_from_rotation(rotation_from_attitude(deg2rad(30), deg2rad(tilt_deg), deg2rad(10)));
    EXPECT_FALSE(a.azimuth) << tilt_deg;
    EXPECT_FALSE(a.roll) << tilt_deg;
    EXPECT_NEAR(rad2deg(a.downtilt), tilt_deg, 1e-9);
  }
  // Just outside the limit both are defined again.
  const auto a = attitude_from_rotation(rotation_from_attitude(deg2rad(30), deg2rad(88.5), deg2rad(10)));
  ASSERT_TRUE(a.azimuth && a.roll);
  EXPECT_NEAR(rad2deg(*a.azimuth), 30.0, 1e-6);
  EXPECT_NEAR(rad2deg(*a.roll), 10.0, 1e-6);
}

TEST(Attitude, ThesisGraAndNor) {
  EXPECT_NEAR(rad2deg(angle_from_down({0, 0, -1})), 0.0, kTol);
  EXPECT_NEAR(rad2deg(angle_from_down({0, 0, 1})), 180.0, 1e-12);
  EXPECT_NEAR(rad2deg(angle_from_down({1, 0, 0})), 90.0, 1e-12);
  EXPECT_NEAR(rad2deg(*heading_from_north({0, 1, -5})), 0.0, kTol);
  EXPECT_NEAR(rad2deg(*heading_from_north({1, 0, 3})), 90.0, 1e-12);
  EXPECT_NEAR(rad2deg(*heading_from_north({-1, 0, 0})), 270.0, 1e-12);
  EXPECT_FALSE(heading_from_north({0, 0, -1}));
}

TEST(ContactPlacement, TopUpMatchesTheModelNote) {
  // x_device = x_a, y_device = z_a, z_device = -y_a.
  const Mat3 R_device_antenna = contact_rotation(ContactPlacement::kTopUp);
  EXPECT_TRUE((R_device_antenna * Vec3::UnitX()).isApprox(Vec3::UnitX()));
  EXPECT_TRUE((R_device_antenna * Vec3::UnitY()).isApprox(-Vec3::UnitZ()));
  EXPECT_TRUE((R_device_antenna * Vec3::UnitZ()).isApprox(Vec3::UnitY()));
}

TEST(ContactPlacement, AllPlacementsAreRotationsWithScreenFacingBack) {
  for (auto p : {ContactPlacement::kTopUp, ContactPlacement::kTopDown, ContactPlacement::kTopRight, ContactPlacement::kTopLeft}) {
    const Mat3 R = contact_rotation(p);
    EXPECT_NEAR(R.determinant(), 1.0, kTol) << to_string(p);
    EXPECT_TRUE((R * Vec3::UnitY()).isApprox(-Vec3::UnitZ())) << to_string(p);  // boresight = -z_device
    EXPECT_EQ(parse_contact_placement(to_string(p)), p);
  }
  EXPECT_THROW(parse_contact_placement("sideways"), std::invalid_argument);
}

}  // namespace
}  // namespace antpose

namespace antpose {
namespace {

// First-order propagation against a Monte Carlo of the same world-frame rotation error, and
// against the closed forms of contact mode for an isotropic tilt error σ_t and heading error σ_h.
TEST(AttitudeSigma, MatchesMonteCarloAndTheClosedForms) {
  const double st = deg2rad(0.3), sh = deg2rad(1.5);
  const Mat3 cov = Vec3(st * st, st * st, sh * sh).asDiagonal();
  for (double downtilt_deg : {0.0, 8.0, 25.0}) {
    const Mat3 R = rotation_from_attitude(deg2rad(40), deg2rad(downtilt_deg), deg2rad(2));
    const auto s = attitude_sigma(R, cov);
    ASSERT_TRUE(s.azimuth && s.roll);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> g(0.0, 1.0);
    double sa = 0, sd = 0, sr = 0;
    const auto a0 = attitude_from_rotation(R);
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const Vec3 d(st * g(rng), st * g(rng), sh * g(rng));
      const auto a = attitude_from_rotation(exp_so3(d) * R);
      sa += std::pow(wrap_pi(*a.azimuth - *a0.azimuth), 2) / n;
      sd += std::pow(a.downtilt - a0.downtilt, 2) / n;
      sr += std::pow(wrap_pi(*a.roll - *a0.roll), 2) / n;
    }
    EXPECT_NEAR(*s.azimuth, std::sqrt(sa), 0.03 * std::sqrt(sa)) << downtilt_deg;
    EXPECT_NEAR(s.downtilt, std::sqrt(sd), 0.03 * std::sqrt(sd)) << downtilt_deg;
    EXPECT_NEAR(*s.roll, std::sqrt(sr), 0.03 * std::sqrt(sr)) << downtilt_deg;
    const double dt = deg2rad(downtilt_deg);
    EXPECT_NEAR(s.downtilt, st, 1e-6);
    EXPECT_NEAR(*s.azimuth, std::hypot(sh, st * std::tan(dt)), 1e-6);
    std::printf("downtilt %4.1f°: roll σ %.4f°, contact mode's σ_t/cos(downtilt) %.4f°\n", downtilt_deg,
                rad2deg(*s.roll), rad2deg(st / std::cos(dt)));
  }
  // A vertical boresight: azimuth and roll undefined, so no σ for them either.
  const auto v = attitude_sigma(rotation_from_attitude(0, deg2rad(90), 0), cov);
  EXPECT_FALSE(v.azimuth);
  EXPECT_FALSE(v.roll);
}

}  // namespace
}  // namespace antpose
