#include "antpose/registration/yaw_turns.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <gtest/gtest.h>

#include "antpose/geometry/rotation.hpp"
#include "antpose/model/box_file.hpp"
#include "antpose/registration/pose_selection.hpp"

namespace antpose::registration {
namespace {

const Vec3 kBox(0.43, 0.23, 2.24);                                    // width, depth, height
const double kDiagonalDeg = rad2deg(std::atan2(kBox.y(), kBox.x()));  // θ*, about 28°

// An upright box whose boresight is φ from +y (the direction to viewpoints_along_y), about z.
Iso3 box_facing(double phi) {
  Iso3 T = Iso3::Identity();
  T.linear() = rot_z(phi);
  T.translation() = Vec3(1.0, -2.0, 3.0);
  return T;
}

std::vector<Vec3> viewpoints_along_y(const Iso3& T, double spread_deg) {
  std::vector<Vec3> out;
  for (const double d : {-spread_deg, 0.0, spread_deg}) {
    const double a = deg2rad(d);
    out.push_back(T.translation() + 20.0 * Vec3(std::sin(a), std::cos(a), 0.0) + Vec3(0, 0, -6.0));
  }
  return out;
}

Iso3 turned(const Iso3& T, double turn) {
  Iso3 U = T;
  U.linear() = exp_so3(turn * T.linear().col(2)) * T.linear();
  return U;
}

// The width of the box's outline across a far viewer's line of sight along +y, from its corners
// (not from the formula the strategy uses).
double outline_width(const Iso3& T) {
  double lo = 1e9, hi = -1e9;
  for (const Vec3& c : model::box_corners(kBox)) {
    const double u = (T * c).x();
    lo = std::min(lo, u), hi = std::max(hi, u);
  }
  return hi - lo;
}

TEST(YawTurns, TheViewAngleIsTheDirectionToThePhotosFromTheBoresight) {
  for (const double phi_deg : {-70.0, -20.0, 0.0, 12.0, 50.0, 135.0}) {
    const Iso3 T = box_facing(deg2rad(phi_deg));
    EXPECT_NEAR(rad2deg(view_angle(T, viewpoints_along_y(T, 10.0))), phi_deg, 1e-6) << phi_deg;
  }
}

TEST(YawTurns, EveryMirrorTurnShowsTheSameOutlineWidth) {
  // Beyond 2θ* from face-on (about 56° here) no yaw on the other side of θ* is as wide.
  for (const auto& [phi_deg, count] :
       {std::pair{-40.0, 3u}, {-5.0, 3u}, {10.0, 3u}, {35.0, 3u}, {60.0, 1u}, {170.0, 3u}}) {
    const Iso3 T = box_facing(deg2rad(phi_deg));
    const auto views = viewpoints_along_y(T, 0.0);
    const auto turns = mirror_turns(T, kBox, views);
    ASSERT_EQ(turns.size(), count) << phi_deg;
    for (const double t : turns) {
      EXPECT_NEAR(outline_width(turned(T, t)), outline_width(T), 1e-9) << phi_deg << " turned by " << rad2deg(t);
      EXPECT_GT(std::abs(t), deg2rad(1.0)) << phi_deg;
    }
  }
  // With the box's diagonal across the line of sight the mirror about θ* is no turn at all.
  const Iso3 D = box_facing(deg2rad(kDiagonalDeg));
  const auto turns = mirror_turns(D, kBox, viewpoints_along_y(D, 0.0));
  EXPECT_EQ(std::count_if(turns.begin(), turns.end(), [](double t) { return std::abs(t) < 1e-9; }), 1);
}

TEST(YawTurns, AFaceOnBoxIsTurnedToItsDiagonalMirrorsAndTheGridTheyLeave) {
  const Iso3 T = box_facing(0.0);
  const auto views = viewpoints_along_y(T, 15.0);
  const auto poses = yaw_turns(T, kBox, views, {});
  // −φ is no turn; the grid's ±60° lie within 4° of the mirrors at ±2θ* (56°); 90° stays.
  std::vector<double> got;
  for (const Iso3& P : poses) {
    EXPECT_NEAR((P.translation() - T.translation()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(P.linear().col(2).dot(T.linear().col(2)), 1.0, 1e-12) << "turned about the long axis";
    got.push_back(rad2deg(view_angle(P, views)));
  }
  const std::vector<double> expected{-30.0, 30.0, 2 * kDiagonalDeg, -2 * kDiagonalDeg, 90.0};
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(std::abs(got[i]), std::abs(expected[i]), 1e-6) << i;
}

TEST(YawTurns, TurnsAHalfTurnApartAreOne) {
  YawTurnOptions o;
  o.turns_deg = {90.0, -90.0, 178.0};
  const Iso3 T = box_facing(deg2rad(-70.0));  // beyond 2θ*: its only mirror is −φ, a turn of 140°
  const auto poses = yaw_turns(T, kBox, viewpoints_along_y(T, 5.0), o);
  ASSERT_EQ(poses.size(), 2u) << "90° and −90° leave the same box, as 178° leaves it nearly; 140° stays";
}

// The turn to face a direction keeps the long axis and the centre, turns by at most a quarter
// turn, and leaves the boresight (or its reverse) in the plane of the long axis and the direction.
TEST(YawTurns, FacingTurnPutsAFaceTowardsTheDirection) {
  const Iso3 T = isometry(rot_z(deg2rad(35.0)) * rot_x(deg2rad(-8.0)), Vec3(1.0, -2.0, 3.0));
  const Vec3 z = T.linear().col(2);
  for (const Vec3& direction : {Vec3(1.0, 0.2, 0.0), Vec3(-0.3, -1.0, 0.4), Vec3(0.0, 1.0, -0.1)}) {
    const auto U = facing_turn(T, direction);
    ASSERT_TRUE(U);
    EXPECT_TRUE(U->translation().isApprox(T.translation()));
    EXPECT_LT(angle_between(U->linear().col(2), z), 1e-9);
    EXPECT_LE(rotation_distance(U->linear(), T.linear()), M_PI / 2 + 1e-9);
    const Vec3 across = (direction - direction.dot(z) * z).normalized();
    EXPECT_NEAR(std::abs(U->linear().col(1).dot(across)), 1.0, 1e-9) << direction.transpose();
  }
  EXPECT_FALSE(facing_turn(T, 2.0 * z));
}

// A box turned by θ* and centred on the middle of another's front face lays its diagonal along that
// face, its ends beyond the face's corners by only (√(w² + d²) − w) / 2: the outline the front face
// alone shows, where a side face is too faint to be seen. Its crease twin is the other box.
TEST(YawTurns, TheCreaseTwinOfABoxLyingOnAFrontFaceIsThatFacesBox) {
  const Iso3 T = box_facing(deg2rad(10.0));
  const auto viewpoints = viewpoints_along_y(T, 20.0);  // towards T's front face (+y_a)
  for (const double sign : {1.0, -1.0}) {
    Iso3 W = turned(T, sign * deg2rad(kDiagonalDeg));
    W.translation() = T * Vec3(0.0, 0.5 * kBox.y(), 0.0);
    std::size_t on_face = 0;
    for (const Vec3& c : model::box_corners(kBox)) {
      const Vec3 in_T = T.inverse() * (W * c);
      if (std::abs(in_T.y() - 0.5 * kBox.y()) > 1e-9) continue;
      ++on_face;
      EXPECT_NEAR(std::abs(in_T.x()), 0.5 * std::hypot(kBox.x(), kBox.y()), 1e-9);
    }
    EXPECT_EQ(on_face, 4u) << "a diagonal's two edges, top and bottom corners";
    const auto twins = crease_twins(W, kBox, viewpoints);
    ASSERT_EQ(twins.size(), 2u);
    const auto is_T = [&](const Iso3& U) {
      return box_angle(U.linear(), T.linear()) < 1e-9 && (U.translation() - T.translation()).norm() < 1e-9;
    };
    EXPECT_EQ(std::count_if(twins.begin(), twins.end(), is_T), 1) << sign;
    for (const Iso3& U : twins)
      EXPECT_NEAR(rad2deg(angle_between(U.linear().col(2), W.linear().col(2))), 0.0, 1e-9) << "about the long axis";
  }
}

TEST(YawTurns, OptionsAreChecked) {
  YawTurnOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.min_turn_deg = 0.0;
  EXPECT_FALSE(o.Check().ok());
  EXPECT_THROW(yaw_turns(Iso3::Identity(), kBox, {Vec3(0, 5, 0)}, o), std::invalid_argument);
  o = {};
  o.turns_deg = {200.0};
  EXPECT_FALSE(o.Check().ok());
}

}  // namespace
}  // namespace antpose::registration
