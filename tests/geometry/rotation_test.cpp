#include "antpose/geometry/rotation.hpp"

#include <gtest/gtest.h>

#include <random>

namespace antpose {
namespace {

TEST(Rotation, ElementaryRotationsAreRightHanded) {
  const double a = deg2rad(90);
  EXPECT_TRUE((rot_x(a) * Vec3::UnitY()).isApprox(Vec3::UnitZ()));
  EXPECT_TRUE((rot_y(a) * Vec3::UnitZ()).isApprox(Vec3::UnitX()));
  EXPECT_TRUE((rot_z(a) * Vec3::UnitX()).isApprox(Vec3::UnitY()));
}

TEST(Rotation, Wrapping) {
  EXPECT_DOUBLE_EQ(wrap_2pi(-deg2rad(90)), deg2rad(270));
  EXPECT_DOUBLE_EQ(wrap_2pi(2 * std::numbers::pi), 0.0);
  EXPECT_GE(wrap_2pi(-1e-18), 0.0);
  EXPECT_LT(wrap_2pi(-1e-18), 2 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(wrap_pi(deg2rad(270)), -deg2rad(90));
  EXPECT_DOUBLE_EQ(wrap_pi(std::numbers::pi), std::numbers::pi);
}

TEST(Rotation, ExpLogRoundTripIncludingNearPi) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  for (int i = 0; i < 500; ++i) {
    Vec3 axis(n(rng), n(rng), n(rng));
    axis.normalize();
    for (double angle : {1e-9, 1e-4, 0.3, 2.0, std::numbers::pi - 1e-7}) {
      const Vec3 w = angle * axis;
      const Vec3 back = log_so3(exp_so3(w));
      EXPECT_LT((back - w).norm(), 1e-9 * std::max(1.0, angle)) << angle;
    }
  }
}

TEST(Rotation, DistanceAndNearest) {
  const Mat3 A = rot_z(0.2) * rot_x(-0.4);
  const Mat3 B = A * rot_y(deg2rad(3));
  EXPECT_NEAR(rad2deg(rotation_distance(A, B)), 3.0, 1e-10);
  Mat3 noisy = A;
  noisy(0, 1) += 1e-3;
  const Mat3 R = nearest_rotation(noisy);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  EXPECT_TRUE((R.transpose() * R).isApprox(Mat3::Identity(), 1e-12));
  EXPECT_LT(rotation_distance(R, A), 1e-3);
}

TEST(Rotation, AngleBetweenIsAccurateForTinyAngles) {
  EXPECT_NEAR(angle_between(Vec3(1, 0, 0), Vec3(1, 1e-10, 0)), 1e-10, 1e-20);
  EXPECT_NEAR(angle_between(Vec3(1, 0, 0), Vec3(-1, 0, 0)), std::numbers::pi, 1e-15);
}

}  // namespace
}  // namespace antpose
