#include "antpose/orientation/gyro_integration.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace antpose::orientation {
namespace {

SensorSeries series(double rate_hz, double duration, const std::function<Vec3(double)>& w) {
  SensorSeries s;
  for (double t = 0.0; t <= duration + 1e-12; t += 1.0 / rate_hz) {
    s.t.push_back(t);
    s.v.push_back(w(t));
  }
  return s;
}

TEST(GyroIntegration, ConstantRateIsExact) {
  const Vec3 w(0.3, -0.2, 0.5);
  const auto g = series(100, 5, [&](double) { return w; });
  const GyroIntegration I(g, 1.0, 4.0);
  for (double t : {1.0, 1.003, 2.5, 3.9999, 4.0})
    EXPECT_LT(rotation_distance(I.at(t).R, exp_so3(w * (t - 1.0))), 1e-12) << t;
  EXPECT_LT((I.rate(2.0) - w).norm(), 1e-15);
  EXPECT_NEAR(I.longest_step_s(), 0.01, 1e-9);
}

// The bias Jacobian predicts the change of ΔR when the bias changes, to first order.
TEST(GyroIntegration, BiasJacobianMatchesReintegration) {
  auto w = [](double t) { return Vec3(0.8 * std::sin(1.3 * t), 0.5 * std::cos(0.7 * t), 0.6 * std::sin(2.1 * t + 1)); };
  const auto g = series(200, 20, w);
  const Vec3 b0(0.01, -0.02, 0.005);
  const GyroIntegration I(g, 2.0, 18.0, b0);
  const Vec3 db(2e-4, -1e-4, 3e-4);
  const GyroIntegration I2(g, 2.0, 18.0, b0 + db);
  for (double t : {2.0, 5.1234, 10.0, 17.99}) {
    const auto s = I.at(t);
    const Mat3 predicted = s.R * exp_so3(s.J * db);
    const double change = rotation_distance(s.R, I2.at(t).R);
    // First-order prediction: the error is second order in δb·t.
    EXPECT_LT(rotation_distance(predicted, I2.at(t).R), 1e-3 * change + 1e-9) << t << " change " << change;
  }
}

// Sample convention: sample k's rate acts over (t_{k-1}, t_k]; with trapezoid the mean acts.
TEST(GyroIntegration, SampleConventionOfTheEstimators) {
  SensorSeries g;
  g.t = {0.0, 0.1, 0.2};
  g.v = {Vec3(0, 0, 1), Vec3(0, 0, 2), Vec3(0, 0, 4)};
  const GyroIntegration held(g, 0.0, 0.2);
  EXPECT_NEAR(log_so3(held.at(0.2).R).z(), 0.1 * 2 + 0.1 * 4, 1e-12);
  EXPECT_NEAR(log_so3(held.at(0.15).R).z(), 0.1 * 2 + 0.05 * 4, 1e-12);
  const GyroIntegration trapezoid(g, 0.0, 0.2, Vec3::Zero(), true);
  EXPECT_NEAR(log_so3(trapezoid.at(0.2).R).z(), 0.1 * 1.5 + 0.1 * 3, 1e-12);
  EXPECT_NEAR(trapezoid.rate(0.15).z(), 3.0, 1e-12);
}

TEST(GyroIntegration, GapIsReportedAndDegenerateInputRefused) {
  auto g = series(100, 3, [](double) { return Vec3(0, 0, 0.1); });
  g.t.erase(g.t.begin() + 100, g.t.begin() + 150);
  g.v.erase(g.v.begin() + 100, g.v.begin() + 150);
  const GyroIntegration I(g, 0.5, 2.5);
  EXPECT_NEAR(I.longest_step_s(), 0.51, 1e-9);
  EXPECT_NEAR(I.longest_step_at(), 0.99, 1e-9);
  SensorSeries one;
  one.t = {0.0};
  one.v = {Vec3::Zero()};
  EXPECT_THROW(GyroIntegration(one, 0, 1), std::invalid_argument);
  EXPECT_THROW(GyroIntegration(g, 2, 1), std::invalid_argument);
  const GyroIntegration point(g, 1.0, 1.0);
  EXPECT_LT(rotation_angle(point.at(1.0).R), 1e-15);
  EXPECT_EQ(point.rate(1.0), Vec3::Zero());
}

}  // namespace
}  // namespace antpose::orientation
