#include "antpose/reconstruction/features.hpp"

#include <random>

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

}  // namespace
}  // namespace antpose::reconstruction::detail
