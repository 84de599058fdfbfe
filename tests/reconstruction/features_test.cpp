#include "antpose/reconstruction/features.hpp"

#include <random>

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "reconstruction/scene_fixture.hpp"

namespace antpose::reconstruction::detail {
namespace {

/// Three cameras 0.5 m apart looking at points 3–5 m away; features are the exact projections
/// plus 0.3 px noise.
struct Synthetic {
  camera::CameraIntrinsics K = test::scene_intrinsics();
  std::vector<Mat3> R;
  std::vector<Vec3> t;
  std::vector<Vec3> points;
  std::vector<ViewFeatures> features;
};

Synthetic synthetic(int n_points) {
  Synthetic s;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, 0.3);
  for (int v = 0; v < 3; ++v) {
    s.R.push_back(rot_y(deg2rad(-5.0 * (v - 1))));
    s.t.push_back(-s.R.back() * Vec3(0.5 * (v - 1), 0.0, 0.0));
  }
  for (int i = 0; i < n_points; ++i) s.points.emplace_back(u(rng), 0.7 * u(rng), 4.0 + u(rng));
  s.features.resize(3);
  for (int v = 0; v < 3; ++v)
    for (const auto& p : s.points) {
      const Vec2 px = *s.K.project(s.R[v] * p + s.t[v]) + Vec2(noise(rng), noise(rng));
      s.features[v].px.push_back(px);
      s.features[v].xy.push_back(s.K.undistort(Vec2((px.x() - s.K.cx) / s.K.fx, (px.y() - s.K.cy) / s.K.fy)));
    }
  return s;
}

TEST(ReconstructFeatures, TracksTriangulateToTruth) {
  auto s = synthetic(200);
  std::vector<PairMatches> pairs{{0, 1, {}}, {1, 2, {}}};
  for (int i = 0; i < 200; ++i) pairs[0].matches.emplace_back(i, i), pairs[1].matches.emplace_back(i, i);
  // An ambiguous chain: feature 0 of view 1 also matched to feature 1 of view 2 → two features
  // of view 2 in one track, which is dropped.
  pairs[1].matches.emplace_back(0, 1);
  const auto tracks = build_tracks({200, 200, 200}, pairs);
  EXPECT_EQ(tracks.size(), 198u);  // tracks 0 and 1 merged into one conflicting track, dropped
  double worst = 0;
  for (auto track : tracks) {
    ASSERT_EQ(track.size(), 3u);
    const auto X = triangulate_track(track, s.features, s.R, s.t, s.K, {});
    ASSERT_TRUE(X.has_value());
    worst = std::max(worst, (*X - s.points[track[0].second]).norm());
  }
  // 0.3 px at 4 m with f = 850 and a 1 m baseline: depth noise ≈ z² σ / (f b) ≈ 6 mm.
  EXPECT_LT(worst, 0.03);
}

TEST(ReconstructFeatures, TriangulationDropsABadObservation) {
  auto s = synthetic(1);
  // Across the epipolar lines (the baseline is along x): a mismatch the other two views expose.
  s.features[2].px[0] += Vec2(0, 25);
  s.features[2].xy[0] += Vec2(0, 25 / s.K.fy);
  std::vector<Observation> track{{0, 0}, {1, 0}, {2, 0}};
  const auto X = triangulate_track(track, s.features, s.R, s.t, s.K, {});
  ASSERT_TRUE(X.has_value());
  EXPECT_EQ(track.size(), 2u);
  EXPECT_LT((*X - s.points[0]).norm(), 0.05);
}

TEST(ReconstructFeatures, TriangulationRejectsNarrowAngleAndBehind) {
  auto s = synthetic(1);
  std::vector<Observation> track{{0, 0}, {1, 0}};
  TriangulationChecks checks;
  checks.min_angle_rad = deg2rad(20);  // the rays meet at ~7°
  EXPECT_FALSE(triangulate_track(track, s.features, s.R, s.t, s.K, checks).has_value());
  checks = {};
  checks.max_depth_m = 2.0;
  track = {{0, 0}, {1, 0}};
  EXPECT_FALSE(triangulate_track(track, s.features, s.R, s.t, s.K, checks).has_value());
}

TEST(ReconstructFeatures, EpipolarFilterKeepsTrueMatches) {
  auto s = synthetic(100);
  std::vector<std::pair<int, int>> candidates;
  for (int i = 0; i < 100; ++i) candidates.emplace_back(i, i);
  for (int i = 0; i < 20; ++i) candidates.emplace_back(i, (i + 37) % 100);  // wrong, and claims twice
  const Mat3 R_b_a = s.R[1] * s.R[0].transpose();
  const Vec3 t_b_a = s.t[1] - R_b_a * s.t[0];
  const auto kept = epipolar_filter(s.features[0], s.features[1], candidates, R_b_a, t_b_a, 2.0, 850);
  std::size_t right = 0;
  for (const auto& [a, b] : kept) right += a == b;
  EXPECT_EQ(right, kept.size());
  EXPECT_GT(kept.size(), 70u);
}

TEST(ReconstructFeatures, GuidedMatchingFindsWhatLookAlikesHideFromTheRatioTest) {
  auto s = synthetic(60);
  cv::Mat base(60, 128, CV_32F), noise_a(60, 128, CV_32F), noise_b(60, 128, CV_32F);
  cv::randn(base, 0, 1);
  cv::randn(noise_a, 0, 0.05);
  cv::randn(noise_b, 0, 0.05);
  ViewFeatures& a = s.features[0];
  ViewFeatures& b = s.features[1];
  a.descriptors = base + noise_a;
  b.descriptors = base + noise_b;
  // Look-alikes of the first 30 features 200 px above them, far off their epipolar lines (the
  // baseline is along x), as the board's corners are to one another: the plain ratio test picks
  // them, and the epipolar filter then drops the match.
  for (int i = 0; i < 30; ++i) {
    const Vec2 px = b.px[i] - Vec2(0, 200);
    b.px.push_back(px);
    b.xy.push_back(s.K.undistort(Vec2((px.x() - s.K.cx) / s.K.fx, (px.y() - s.K.cy) / s.K.fy)));
    b.descriptors.push_back(a.descriptors.row(i).clone());  // nearer to a's than the true one
  }
  // Feature 59 is not seen in b: its only candidate on the line looks nothing like it.
  cv::randn(b.descriptors.row(59), 0, 1);
  const Mat3 R_b_a = s.R[1] * s.R[0].transpose();
  const Vec3 t_b_a = s.t[1] - R_b_a * s.t[0];

  const auto plain = epipolar_filter(a, b, ratio_matches(a, b, 0.8), R_b_a, t_b_a, 2.0, 850);
  EXPECT_LE(plain.size(), 29u);  // none of the 30 with look-alikes
  const auto guided = guided_matches(a, b, R_b_a, t_b_a, 0.8, 2.0, 850);
  std::size_t right = 0;
  for (const auto& [i, j] : guided) right += i == j;
  EXPECT_EQ(right, guided.size());
  EXPECT_EQ(guided.size(), 59u);
  for (const auto& [i, j] : guided) EXPECT_NE(i, 59);
}

// Points along the camera's axis (identity pose: depth = z), spread across 0.3 m sideways.
std::vector<Vec3> at_depths(std::size_t count, double z_from, double z_to, std::mt19937& rng) {
  std::uniform_real_distribution<double> z(z_from, z_to), side(-0.15, 0.15);
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < count; ++i) out.emplace_back(side(rng), side(rng), z(rng));
  return out;
}

TEST(DepthRange, ThePanelBeforeATexturedWallNotTheWall) {
  // A rooftop panel 4.2 m away with ~30 features before a textured wall with ten times as many.
  std::mt19937 rng(3);
  auto points = at_depths(30, 4.2, 4.5, rng);
  const auto wall = at_depths(300, 17.5, 18.5, rng);  // more than five times the panel's
  points.insert(points.end(), wall.begin(), wall.end());
  const auto range = nearest_depth_cluster(points, Mat3::Identity(), Vec3::Zero(), 3);
  ASSERT_TRUE(range);
  EXPECT_EQ(range->support, 30u);
  EXPECT_LT(range->near, 4.2);
  EXPECT_GT(range->far, 4.5);
  EXPECT_LT(range->far, 5.0);
  EXPECT_NEAR(range->centre_board.z(), 4.35, 0.05);
}

TEST(DepthRange, AFewStraysBeforeThePanelAreNoObject) {
  // Three features on the board's edge 2 m nearer than a panel of 60: the panel's range.
  std::mt19937 rng(4);
  auto points = at_depths(3, 2.0, 2.1, rng);
  const auto panel = at_depths(60, 4.0, 4.4, rng);
  points.insert(points.end(), panel.begin(), panel.end());
  const auto range = nearest_depth_cluster(points, Mat3::Identity(), Vec3::Zero(), 3);
  ASSERT_TRUE(range);
  EXPECT_EQ(range->support, 60u);
  EXPECT_GT(range->near, 3.0);
  // Below kObjectSupport a fifth of the fullest window still rules: 10 strays before 200 points.
  auto crowd = at_depths(10, 2.0, 2.1, rng);
  const auto big = at_depths(200, 4.0, 4.4, rng);
  crowd.insert(crowd.end(), big.begin(), big.end());
  EXPECT_EQ(nearest_depth_cluster(crowd, Mat3::Identity(), Vec3::Zero(), 3)->support, 200u);
  // No points: no range; too few anywhere: the support says so.
  EXPECT_FALSE(nearest_depth_cluster({}, Mat3::Identity(), Vec3::Zero(), 3));
  EXPECT_EQ(nearest_depth_cluster(at_depths(2, 4.0, 4.1, rng), Mat3::Identity(), Vec3::Zero(), 3)->support, 2u);
}

}  // namespace
}  // namespace antpose::reconstruction::detail
