#include "antpose/measure/mount_side.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "antpose/model/antenna_model.hpp"
#include "antpose/model/sampling.hpp"

namespace antpose::measure {
namespace {

constexpr double kReach = 0.03;  // the fine ICP's correspondence distance
const Vec3 kTowardCameras(0.0, 20.0, 2.0);  // the site's camera, before the panel

struct Site {
  model::AntennaModel panel = model::builtin_panel("panel-2000x300x150");
  registration::KdTree model_tree{model::sample_surface(panel.mesh_antenna, 0.01, 1).points};
  PointCloud cloud;  // antenna frame: the radome seen from the front, the mount behind, a wall far behind
};

// Points on a vertical cylinder's half facing +y (radius r, centre (0, y0)), z within ±h/2.
void add_mast(PointCloud& c, double y0, double r, double h, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 3000; ++i) {
    const double a = M_PI * u(rng);
    c.points.emplace_back(r * std::cos(a), y0 + r * std::sin(a), h * (u(rng) - 0.5));
  }
}

Site site(bool with_mount) {
  Site s;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> depth_noise(0.0, 0.008);
  for (Vec3 p : model::visible_surface(s.panel.mesh_antenna, kTowardCameras, 0.01, 2).points) {
    p.y() += depth_noise(rng);
    s.cloud.points.push_back(p);
  }
  if (with_mount) {
    // Mast 0.25 m in radius whose face stands 0.3 m behind the back plate; two clamp arms.
    add_mast(s.cloud, -0.075 - 0.3 - 0.25, 0.25, 1.8, rng);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const double z : {-0.5, 0.5})
      for (int i = 0; i < 300; ++i) s.cloud.points.emplace_back(0.04 * (u(rng) - 0.5), -0.15 - 0.22 * u(rng), z);
  }
  for (int i = 0; i < 500; ++i) s.cloud.points.emplace_back(0.0, -3.0, -1.0 + 0.004 * i);  // a wall far behind
  return s;
}

TEST(MountSide, TheMastAndClampsLieBehindARightlyRegisteredPanel) {
  const auto s = site(true);
  const auto side = count_mount_side(s.cloud, Iso3::Identity(), s.model_tree, s.panel.size_m, kReach, kTowardCameras, {});
  EXPECT_GT(side.behind, 500u);
  EXPECT_EQ(side.before, 0u);  // the radome's own points, 8 mm deep noise, are the model's
  EXPECT_EQ(mount_verdict(side, {}), MountVerdict::kAsRegistered);
}

TEST(MountSide, APanelRegisteredFrontToBackIsTurned) {
  const auto s = site(true);
  Iso3 turned = Iso3::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();  // about the long axis
  const auto side = count_mount_side(s.cloud, turned, s.model_tree, s.panel.size_m, kReach, kTowardCameras, {});
  EXPECT_GT(side.before, 500u);
  EXPECT_EQ(mount_verdict(side, {}), MountVerdict::kTurned);
}

TEST(MountSide, WithoutAMountInReachNothingIsDecided) {
  const auto s = site(false);
  const auto side = count_mount_side(s.cloud, Iso3::Identity(), s.model_tree, s.panel.size_m, kReach, kTowardCameras, {});
  EXPECT_EQ(side.behind, 0u);  // the wall lies 3 m behind, beyond the mount's depth
  EXPECT_EQ(side.before, 0u);
  EXPECT_EQ(mount_verdict(side, {}), MountVerdict::kUndecided);
}

// A thin panel seen face-on from the ground: its radome's points scatter σ = 2.4 cm in depth
// (5606-1, 21 m), its mast and clamps hide behind it. Registered turned round, the scatter towards
// the cameras lies where its mount would be.
struct FaceOn {
  model::AntennaModel panel = model::builtin_panel("thesis-1310x159x80");
  registration::KdTree model_tree{model::sample_surface(panel.mesh_antenna, 0.01, 1).points};
  PointCloud cloud;
};
FaceOn face_on(double noise_m) {
  FaceOn s;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> depth_noise(0.0, noise_m);
  const Vec3 front = s.panel.size_m.y() / 2 * Vec3::UnitY();
  for (const Vec3& p : model::visible_surface(s.panel.mesh_antenna, kTowardCameras, 0.005, 3).points)
    if (p.y() > front.y() - 1e-6) s.cloud.points.push_back(p + depth_noise(rng) * Vec3::UnitY());
  return s;
}

TEST(MountSide, TheSeenFacesDepthNoiseIsMeasuredBehindIt) {
  const auto s = face_on(0.024);
  std::vector<Vec3> points = s.cloud.points;
  const auto noise = seen_face_depth_noise(points, s.panel.size_m, kTowardCameras, {});
  ASSERT_TRUE(noise.has_value());
  EXPECT_NEAR(*noise, 0.024, 0.003);
  // Seen from its side the points' depth is the panel's, not noise: not measured.
  EXPECT_FALSE(seen_face_depth_noise(points, s.panel.size_m, Vec3(20.0, 3.0, 2.0), {}).has_value());
  // Too few points.
  points.resize(10);
  EXPECT_FALSE(seen_face_depth_noise(points, s.panel.size_m, kTowardCameras, {}).has_value());
}

TEST(MountSide, DepthNoiseTowardsTheCamerasIsNoMount) {
  const auto s = face_on(0.024);
  Iso3 turned = Iso3::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  const auto side = count_mount_side(s.cloud, turned, s.model_tree, s.panel.size_m, kReach, kTowardCameras, {});
  EXPECT_NEAR(side.depth_noise_m, 0.024, 0.003);
  EXPECT_EQ(mount_verdict(side, {}), MountVerdict::kUndecided);
  EXPECT_LT(side.behind, 30u);
  // At the fixed gap alone the scatter reads as a mount behind the panel turned round.
  MountSideOptions gap_only;
  gap_only.noise_sigmas = 0.0;
  const auto fooled = count_mount_side(s.cloud, turned, s.model_tree, s.panel.size_m, kReach, kTowardCameras, gap_only);
  EXPECT_GT(fooled.behind, 50u);
  EXPECT_EQ(mount_verdict(fooled, gap_only), MountVerdict::kAsRegistered);
}

TEST(MountSide, TheVerdictNeedsEnoughPointsAndAClearRatio) {
  const MountSideOptions o;
  EXPECT_EQ(mount_verdict({o.min_points - 1, 0}, o), MountVerdict::kUndecided);
  EXPECT_EQ(mount_verdict({o.min_points, 0}, o), MountVerdict::kAsRegistered);
  EXPECT_EQ(mount_verdict({300, 200}, o), MountVerdict::kUndecided);
  EXPECT_EQ(mount_verdict({400, 200}, o), MountVerdict::kAsRegistered);
  EXPECT_EQ(mount_verdict({200, 400}, o), MountVerdict::kTurned);
  // Turning a pose round takes more points than keeping it (1004-1: 114 turned a right pose).
  EXPECT_EQ(mount_verdict({0, o.min_points_to_turn - 1}, o), MountVerdict::kUndecided);
  EXPECT_EQ(mount_verdict({0, o.min_points_to_turn}, o), MountVerdict::kTurned);
  EXPECT_EQ(mount_verdict({o.min_points_to_turn - 1, 0}, o), MountVerdict::kAsRegistered);
}

// A panel with downtilt t and azimuth a in a frame whose up is (0.3, −0.2, 0.93) (a board frame),
// and its turn by 180° about its own long axis.
struct Tilted {
  Mat3 R, R_turned;
  Vec3 up;
};
Tilted tilted(double downtilt_deg, double azimuth_deg) {
  Tilted t;
  t.up = Vec3(0.3, -0.2, 0.93).normalized();
  const Mat3 R_b_world = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), t.up).toRotationMatrix();
  const Mat3 R_world_antenna = (Eigen::AngleAxisd(-deg2rad(azimuth_deg), Vec3::UnitZ()) *
                                Eigen::AngleAxisd(-deg2rad(downtilt_deg), Vec3::UnitX()))
                                   .toRotationMatrix();
  t.R = R_b_world * R_world_antenna;
  t.R_turned = t.R * Eigen::AngleAxisd(M_PI, Vec3::UnitZ()).toRotationMatrix();
  return t;
}

// Scores measured on simulated sites (score, score with the attachments' outline).
TEST(MountSide, OnlyTheAttachmentsOutlineTurnsAPanelRound) {
  const double margin = 0.02;
  // 502-1: the brackets fit far better turned round, and most of the gain is theirs.
  EXPECT_TRUE(attachments_turn_round({0.0857, 0.1651}, {0.0067, 0.0320}, margin));
  // 4706-1: no bracket sample in any photo; the turned pose's polish fitted the box better.
  EXPECT_FALSE(attachments_turn_round({0.2505, 0.2505}, {0.1458, 0.1458}, margin));
  // 4706-2: the attachments' part better by 0.021, but the whole by less than the margin.
  EXPECT_FALSE(attachments_turn_round({0.2695, 0.2824}, {0.2724, 0.2643}, margin));
  // The same pose either way round: nothing to tell.
  EXPECT_FALSE(attachments_turn_round({0.05, 0.08}, {0.05, 0.08}, margin));
}

TEST(MountSide, DowntiltOfTheBoresight) {
  const auto t = tilted(7.0, 123.0);
  EXPECT_NEAR(rad2deg(boresight_downtilt(t.R, t.up)), 7.0, 1e-9);
  EXPECT_NEAR(rad2deg(boresight_downtilt(t.R_turned, t.up)), -7.0, 1e-9);  // turned round: the sign flips
}

TEST(MountSide, WithoutTheMountTheDowntiltsSignDecidesBeyondTheUptiltLimit) {
  const double limit = deg2rad(3.0);
  const auto call = [&](const Tilted& t, bool turned) {
    const double a = boresight_downtilt(t.R, t.up), b = boresight_downtilt(t.R_turned, t.up);
    return turned ? decide_front_back(MountVerdict::kUndecided, b, a, limit)
                  : decide_front_back(MountVerdict::kUndecided, a, b, limit);
  };
  const auto down = tilted(8.0, 40.0);
  EXPECT_EQ(call(down, false).verdict, MountVerdict::kAsRegistered);
  EXPECT_EQ(call(down, true).verdict, MountVerdict::kTurned);
  EXPECT_TRUE(call(down, true).by_downtilt);
  // Within the limit either way (a panel 2° down could be one 2° up): no decision.
  const auto flat = tilted(2.0, 40.0);
  for (const bool turned : {false, true}) {
    EXPECT_EQ(call(flat, turned).verdict, MountVerdict::kUndecided);
    EXPECT_FALSE(call(flat, turned).by_downtilt || call(flat, turned).in_doubt);
  }
}

TEST(MountSide, TheMountDecidesUnlessItWouldTiltThePanelUp) {
  const double limit = deg2rad(3.0), down = deg2rad(8.0), flat = deg2rad(1.0);
  // The mount agrees with the downtilt, or the downtilt cannot tell: the mount's verdict.
  for (const double tilt : {down, flat, -flat}) {
    const auto kept = decide_front_back(MountVerdict::kAsRegistered, tilt, -tilt, limit);
    EXPECT_EQ(kept.verdict, MountVerdict::kAsRegistered);
    EXPECT_FALSE(kept.in_doubt || kept.by_downtilt);
    const auto turned = decide_front_back(MountVerdict::kTurned, -tilt, tilt, limit);
    EXPECT_EQ(turned.verdict, MountVerdict::kTurned);
    EXPECT_FALSE(turned.in_doubt || turned.by_downtilt);
  }
  // The mount's choice tilts the panel up by 8° (site 1004-1: 114 points before the panel turned
  // a right pose): the cues disagree, nothing is decided, and the caller keeps both.
  const auto against_registered = decide_front_back(MountVerdict::kAsRegistered, -down, down, limit);
  EXPECT_EQ(against_registered.verdict, MountVerdict::kUndecided);
  EXPECT_TRUE(against_registered.in_doubt);
  const auto against_turned = decide_front_back(MountVerdict::kTurned, down, -down, limit);
  EXPECT_EQ(against_turned.verdict, MountVerdict::kUndecided);
  EXPECT_TRUE(against_turned.in_doubt);
}

// A vertical mast of 0.25 m radius at the origin (frame c: z up), a panel 0.5 m from its axis.
Iso3 panel_at(double bearing_deg, double boresight_deg) {
  const double b = deg2rad(bearing_deg), y = deg2rad(boresight_deg);
  Iso3 T = Iso3::Identity();
  T.translation() = Vec3(0.5 * std::cos(b), 0.5 * std::sin(b), 3.0);
  const Vec3 boresight(std::cos(y), std::sin(y), 0.0);
  T.linear().col(1) = boresight;
  T.linear().col(2) = Vec3::UnitZ();
  T.linear().col(0) = boresight.cross(Vec3::UnitZ());
  return T;
}

TEST(MountSide, APanelsBackFacesItsMast) {
  const Vec3 axis_point(0.0, 0.0, 1.0), up = Vec3::UnitZ();
  const double r = 0.25, limit = deg2rad(60.0);
  // Facing away from the mast (and up to the limit off it): as registered; towards it: turned.
  EXPECT_EQ(mast_side_verdict(axis_point, up, r, panel_at(30.0, 30.0), limit), MountVerdict::kAsRegistered);
  EXPECT_EQ(mast_side_verdict(axis_point, up, r, panel_at(30.0, 80.0), limit), MountVerdict::kAsRegistered);
  EXPECT_EQ(mast_side_verdict(axis_point, up, r, panel_at(30.0, 210.0), limit), MountVerdict::kTurned);
  EXPECT_EQ(mast_side_verdict(axis_point, up, r, panel_at(30.0, -160.0), limit), MountVerdict::kTurned);
  // Side-on to the mast, or its centre within the mast's radius: no verdict.
  EXPECT_EQ(mast_side_verdict(axis_point, up, r, panel_at(30.0, 120.0), limit), MountVerdict::kUndecided);
  EXPECT_EQ(mast_side_verdict(axis_point, up, 0.6, panel_at(30.0, 30.0), limit), MountVerdict::kUndecided);
  // Only the directions across the axis count: a tilted mast, the panel tilted with it.
  const Mat3 tilt = Eigen::AngleAxisd(deg2rad(10.0), Vec3::UnitX()).toRotationMatrix();
  Iso3 T = panel_at(30.0, 30.0);
  T.linear() = tilt * T.linear();
  T.translation() = tilt * T.translation();
  EXPECT_EQ(mast_side_verdict(tilt * axis_point, tilt * up, r, T, limit), MountVerdict::kAsRegistered);
}

}  // namespace
}  // namespace antpose::measure
