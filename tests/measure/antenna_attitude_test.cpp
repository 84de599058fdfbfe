#include "antpose/measure/antenna_attitude.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

// A board tilted and turned in the world, its covariance small against the rivals' turns.
BoardWorldAttitude board() {
  BoardWorldAttitude b;
  b.R_world_board = (Eigen::AngleAxisd(0.7, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitX())).toRotationMatrix();
  b.covariance = Mat3::Identity() * std::pow(deg2rad(0.1), 2);
  return b;
}

struct Measured {
  BoardWorldAttitude board;
  Mat3 R_board_antenna;
  AntennaAttitudeResult result;
};

Measured measured(double azimuth_deg, double downtilt_deg, double roll_deg) {
  Measured m{board(), Mat3::Identity(), {}};
  const Mat3 R_world_antenna = rotation_from_attitude(deg2rad(azimuth_deg), deg2rad(downtilt_deg), deg2rad(roll_deg));
  m.R_board_antenna = m.board.R_world_board.transpose() * R_world_antenna;
  m.result = antenna_attitude(m.board, m.R_board_antenna,
                              {{"registration", Mat3::Identity() * std::pow(deg2rad(0.05), 2)}}, std::nullopt);
  return m;
}

TEST(AntennaAttitude, ARivalWidensEachAngleToHalfItsDifference) {
  auto m = measured(123.0, 0.0, 0.0);
  const auto before = m.result.sigma;
  // A level panel: turning about the vertical or about its own long axis is the same turn.
  const Mat3 R_rival = m.board.R_world_board.transpose() * rotation_from_attitude(deg2rad(143.0), 0.0, 0.0);
  const double turn = widen_for_rivals(m.result, m.R_board_antenna, {R_rival}, m.board);
  EXPECT_NEAR(rad2deg(turn), 20.0, 1e-6);
  EXPECT_NEAR(*m.result.sigma.azimuth, std::hypot(*before.azimuth, deg2rad(10.0)), 1e-9);
  EXPECT_NEAR(m.result.sigma.downtilt, before.downtilt, 1e-9);
  EXPECT_NEAR(*m.result.sigma.roll, *before.roll, 1e-9);
}

// A panel 3.9° down whose rival lies 30° round about the vertical, with the same roll:
// the truth may lie as far round the panel's own long axis, which turns its roll by about
// 30° · sin(3.9°) = 2.0°; the roll's σ covers half that.
TEST(AntennaAttitude, ARivalYawAlsoWidensTheRollAboutTheTiltedAxis) {
  auto m = measured(142.7, 3.9, 0.0);
  const auto before = m.result.sigma;
  const Mat3 R_rival = m.board.R_world_board.transpose() * rotation_from_attitude(deg2rad(172.7), deg2rad(3.9), 0.0);
  widen_for_rivals(m.result, m.R_board_antenna, {R_rival}, m.board);
  // The turn about the panel's own axis as the truth: its roll differs by about yaw · sin(downtilt).
  const Mat3 R_about_axis = m.R_board_antenna * Eigen::AngleAxisd(deg2rad(-30.0), Vec3::UnitZ()).toRotationMatrix();
  const auto turned = attitude_from_rotation(m.board.R_world_board * R_about_axis);
  const double roll_difference = std::abs(wrap_pi(*turned.roll - *m.result.magnetic.roll));
  EXPECT_NEAR(rad2deg(roll_difference), 30.0 * std::sin(deg2rad(3.9)), 0.1);
  // The rival's boresight lies 30° round about the vertical, a little less about the tilted axis.
  EXPECT_NEAR(*m.result.sigma.roll, std::hypot(*before.roll, roll_difference / 2), deg2rad(0.01));
  EXPECT_GT(rad2deg(*m.result.sigma.roll), 0.9);
  EXPECT_NEAR(rad2deg(*m.result.sigma.azimuth), 15.0, 0.1);
}

// Each angle's σ² is the sum of its shares' squares: the sources are independent and the
// propagation linear. A source that turns only about the world's vertical moves the azimuth alone.
TEST(AntennaAttitude, TheBudgetAddsUpToEachAngleSigma) {
  const auto b = board();
  const Mat3 R_world_antenna = rotation_from_attitude(deg2rad(210.0), deg2rad(4.0), deg2rad(1.0));
  const Mat3 R_board_antenna = b.R_world_board.transpose() * R_world_antenna;
  const Vec3 up_board = b.R_world_board.transpose() * Vec3::UnitZ();
  const Mat3 about_vertical = up_board * up_board.transpose() * std::pow(deg2rad(0.8), 2);
  const Mat3 anisotropic = Vec3(0.3, 0.05, 0.2).cwiseAbs2().asDiagonal() * std::pow(deg2rad(1.0), 2);
  const auto r =
      antenna_attitude(b, R_board_antenna, {{"heading only", about_vertical}, {"outline", anisotropic}}, std::nullopt);
  ASSERT_EQ(r.budget.size(), 3u);
  EXPECT_EQ(r.budget[0].source, "board attitude in the world");
  EXPECT_EQ(r.budget[1].source, "heading only");
  EXPECT_EQ(r.budget[2].source, "outline");
  double az2 = 0, tilt2 = 0, roll2 = 0;
  for (const auto& share : r.budget)
    az2 += std::pow(*share.sigma.azimuth, 2), tilt2 += std::pow(share.sigma.downtilt, 2),
        roll2 += std::pow(*share.sigma.roll, 2);
  EXPECT_NEAR(std::sqrt(az2), *r.sigma.azimuth, 1e-9);
  EXPECT_NEAR(std::sqrt(tilt2), r.sigma.downtilt, 1e-9);
  EXPECT_NEAR(std::sqrt(roll2), *r.sigma.roll, 1e-9);
  EXPECT_NEAR(rad2deg(*r.budget[1].sigma.azimuth), 0.8, 1e-6);
  EXPECT_LT(rad2deg(r.budget[1].sigma.downtilt), 1e-6);
  EXPECT_LT(rad2deg(*r.budget[1].sigma.roll), 1e-6);
}

// A rival's widening joins the budget as its own share: what it added in quadrature.
TEST(AntennaAttitude, ARivalsWideningIsItsOwnShare) {
  auto m = measured(123.0, 0.0, 0.0);
  const auto before = m.result.sigma;
  const std::size_t sources = m.result.budget.size();
  const Mat3 R_rival = m.board.R_world_board.transpose() * rotation_from_attitude(deg2rad(143.0), 0.0, 0.0);
  widen_for_rivals(m.result, m.R_board_antenna, {R_rival}, m.board);
  ASSERT_EQ(m.result.budget.size(), sources + 1);
  const auto& rival = m.result.budget.back();
  EXPECT_EQ(rival.source, "rival poses");
  EXPECT_NEAR(*rival.sigma.azimuth, deg2rad(10.0), 1e-9);
  EXPECT_NEAR(std::hypot(*before.azimuth, *rival.sigma.azimuth), *m.result.sigma.azimuth, 1e-12);
  EXPECT_NEAR(rival.sigma.downtilt, 0.0, 1e-9);
  // A second widening, by another kind of rival, joins the budget under its own name.
  widen_for_rivals(m.result, m.R_board_antenna, {R_rival}, m.board, "face points against the outline");
  ASSERT_EQ(m.result.budget.size(), sources + 2);
  EXPECT_EQ(m.result.budget.back().source, "face points against the outline");
}

TEST(AntennaAttitude, NoRivalNoWidening) {
  auto m = measured(10.0, 5.0, 1.0);
  const auto before = m.result.sigma;
  EXPECT_EQ(widen_for_rivals(m.result, m.R_board_antenna, {}, m.board), 0.0);
  EXPECT_EQ(*m.result.sigma.azimuth, *before.azimuth);
  EXPECT_EQ(m.result.sigma.downtilt, before.downtilt);
  EXPECT_EQ(*m.result.sigma.roll, *before.roll);
  EXPECT_EQ(m.result.budget.back().source, "registration");
}

}  // namespace
}  // namespace antpose::measure
