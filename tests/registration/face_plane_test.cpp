#include "antpose/registration/face_plane.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace antpose::registration {
namespace {

const Vec3 kFacePanel(0.30, 0.15, 1.50);  // width, depth, length
constexpr double kFaceEdgeRadius = 0.01;

// A panel registered at T, its front face (+y_a) seen from 8 m in front.
struct FaceScene {
  Iso3 T = Iso3::Identity();
  std::vector<Vec3> viewpoints;
};

FaceScene seen_from_front() {
  FaceScene s;
  s.T.linear() = exp_so3(Vec3(0.3, 0.2, 1.0));
  s.T.translation() = Vec3(1.0, 2.0, 5.0);
  for (const double x : {-2.0, 0.0, 2.0}) s.viewpoints.push_back(s.T * Vec3(x, 8.0, 0.0));
  return s;
}

// Points 1 cm apart on the flat part of the face whose outward normal is `normal` (antenna frame)
// of the panel at T_true, `noise_m` deep (Gaussian), `count` of them at most.
PointCloud points_on_face(const Iso3& T_true, const Vec3& normal, double noise_m, std::size_t count = 1u << 20) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_m);
  const int axis = std::abs(normal.x()) > 0.5 ? 0 : 1;
  const double half_across = kFacePanel[1 - axis] / 2 - kFaceEdgeRadius - 0.01;
  PointCloud out;
  for (double z = -0.6; z <= 0.6; z += 0.01)
    for (double a = -half_across; a <= half_across; a += 0.01) {
      if (out.size() >= count) return out;
      Vec3 q = normal * (kFacePanel[axis] / 2 + noise(rng));
      q[1 - axis] = a, q.z() = z;
      out.points.push_back(T_true * q);
    }
  return out;
}

Mat3 outline_sigma_deg(double sigma_deg) { return Mat3::Identity() * std::pow(deg2rad(sigma_deg), 2); }

std::vector<FacePlane> planes_of(const PointCloud& points, const FaceScene& s, double outline_deg,
                                 const FacePlaneOptions& o = {}) {
  return fit_face_planes(points, s.T, kFacePanel, kFaceEdgeRadius, s.viewpoints, outline_sigma_deg(outline_deg), o);
}

// The face turned 1.5° about the long axis (a yaw the outline might miss) is measured by its
// points to within a few hundredths of a degree, and disagrees with an outline sure to 0.2°.
TEST(FacePlane, MeasuresTheTurnOfTheFaceItsPointsShow) {
  const FaceScene s = seen_from_front();
  const Vec3 turn_antenna(0.0, 0.0, deg2rad(1.5));
  Iso3 T_true = s.T;
  T_true.linear() = s.T.linear() * exp_so3(turn_antenna);
  const auto points = points_on_face(T_true, Vec3::UnitY(), 0.002);
  const auto planes = planes_of(points, s, 0.2);
  ASSERT_EQ(planes.size(), 1u);
  const auto& plane = planes.front();
  EXPECT_EQ(face_name(plane.normal_antenna), "+y");
  EXPECT_LT(rad2deg((plane.turn_board - s.T.linear() * turn_antenna).norm()), 0.05);
  EXPECT_NEAR(plane.rms_m, 0.002, 0.0003);
  EXPECT_TRUE(plane.disagrees) << plane.chi2;
  // Nothing about the face's own normal: the turn's covariance is flat along it.
  const Vec3 normal_board = s.T.linear() * Vec3::UnitY();
  EXPECT_LT(normal_board.dot(plane.covariance_board * normal_board), 1e-12);
  // An outline unsure by 3° does not disagree with it.
  const auto loose = planes_of(points, s, 3.0);
  ASSERT_EQ(loose.size(), 1u);
  EXPECT_FALSE(loose[0].disagrees) << loose[0].chi2;
}

// Points on the registered face agree with it: no disagreement from their noise, and the face's
// flatness keeps its σ from shrinking below what an extruded radome's tolerance allows.
TEST(FacePlane, PointsOnTheRegisteredFaceAgreeWithIt) {
  const FaceScene s = seen_from_front();
  const auto points = points_on_face(s.T, Vec3::UnitY(), 0.003);
  const auto planes = planes_of(points, s, 0.2);
  ASSERT_EQ(planes.size(), 1u);
  EXPECT_FALSE(planes[0].disagrees) << planes[0].chi2;
  EXPECT_LT(rad2deg(planes[0].turn_board.norm()), 0.05);
  FacePlaneOptions flat;
  flat.flatness_m = 0.0;
  const auto ideal = planes_of(points, s, 0.2, flat);
  ASSERT_EQ(ideal.size(), 1u);
  EXPECT_GT(planes[0].covariance_board.trace(), ideal[0].covariance_board.trace());
}

// A face with few points, or scattered beyond a plane's, or one the photos do not see, gives no
// plane.
TEST(FacePlane, NoPlaneFromFewOrScatteredPointsOrAnUnseenFace) {
  const FaceScene s = seen_from_front();
  EXPECT_TRUE(planes_of(points_on_face(s.T, Vec3::UnitY(), 0.002, 60), s, 0.2).empty());
  EXPECT_TRUE(planes_of(points_on_face(s.T, Vec3::UnitY(), 0.008), s, 0.2).empty());
  EXPECT_TRUE(planes_of(points_on_face(s.T, -Vec3::UnitY(), 0.002), s, 0.2).empty());
  FacePlaneOptions off;
  off.enabled = false;
  EXPECT_TRUE(planes_of(points_on_face(s.T, Vec3::UnitY(), 0.002), s, 0.2, off).empty());
}

// Seen obliquely, the side the photos see is checked beside the front; each measures the turn
// in its own plane.
TEST(FacePlane, ChecksEverySeenFace) {
  FaceScene s = seen_from_front();
  s.viewpoints = {s.T * Vec3(6.0, 6.0, 0.0), s.T * Vec3(5.0, 7.0, 0.0)};
  PointCloud points = points_on_face(s.T, Vec3::UnitY(), 0.002);
  const auto side = points_on_face(s.T, Vec3::UnitX(), 0.002);
  points.points.insert(points.points.end(), side.points.begin(), side.points.end());
  const auto planes = planes_of(points, s, 0.2);
  ASSERT_EQ(planes.size(), 2u);
  EXPECT_EQ(face_name(planes[0].normal_antenna), "+x");
  EXPECT_EQ(face_name(planes[1].normal_antenna), "+y");
}

TEST(FacePlane, OptionsCheckThemselves) {
  FacePlaneOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.min_gate_m = 0.05;  // wider than gate_m
  EXPECT_FALSE(o.Check().ok());
  EXPECT_NE(o.Check().message().find("min_gate_m"), std::string::npos);
}

}  // namespace
}  // namespace antpose::registration
