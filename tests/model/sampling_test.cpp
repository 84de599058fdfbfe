#include "antpose/model/sampling.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "antpose/model/antenna_model.hpp"

namespace antpose::model {
namespace {
using ::testing::HasSubstr;

// Appends a cube of side `s` centred at `c`, wound outwards (two triangles per face).
void add_cube(Mesh& m, double s, const Vec3& c) {
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (int k = 0; k < 8; ++k)
    m.vertices.push_back(c + s / 2 * Vec3((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1));
  // Quads counter-clockwise seen from outside: −z, +z, −y, +y, −x, +x.
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({base + q[0], base + q[1], base + q[2]});
    m.triangles.push_back({base + q[0], base + q[2], base + q[3]});
  }
}

Mesh cube(double s) {
  Mesh m;
  add_cube(m, s, Vec3::Zero());
  return m;
}

// Index 0..5 of the cube face a point lies on (−x, +x, −y, +y, −z, +z), or −1.
int face_of(const Vec3& p, double half) {
  for (int a = 0; a < 3; ++a) {
    if (std::abs(p[a] + half) < 1e-12) return 2 * a;
    if (std::abs(p[a] - half) < 1e-12) return 2 * a + 1;
  }
  return -1;
}

TEST(Sampling, PointsLieOnTheSurfaceWithOutwardNormals) {
  const PointCloud cloud = sample_surface(cube(0.5), 0.02, 1);
  ASSERT_TRUE(cloud.has_normals());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int face = face_of(cloud.points[i], 0.25);
    ASSERT_GE(face, 0) << cloud.points[i].transpose();
    Vec3 expected = Vec3::Zero();
    expected[face / 2] = face % 2 ? 1 : -1;
    ASSERT_LT((cloud.normals[i] - expected).norm(), 1e-15);
  }
}

TEST(Sampling, DensityIsOnePointPerSpacingSquared) {
  const double spacing = 0.011, per_triangle = 0.125 / (spacing * spacing);  // 1033.06
  const PointCloud cloud = sample_surface(cube(0.5), spacing, 2);
  // Stratified: each triangle gets ⌊m⌋ or ⌈m⌉ points, each face two triangles.
  std::array<int, 6> count{};
  for (const auto& p : cloud.points) ++count[face_of(p, 0.25)];
  for (int f = 0; f < 6; ++f) {
    EXPECT_GE(count[f], 2 * std::floor(per_triangle)) << f;
    EXPECT_LE(count[f], 2 * std::ceil(per_triangle)) << f;
  }
  // A mesh with very unequal triangles: the panel. Total within a few standard deviations
  // (each triangle adds at most a Bernoulli variance of 1/4).
  const Mesh panel = parametric_panel(PanelSpec{}).mesh_antenna;
  const double expected = surface_area(panel) / (0.01 * 0.01);
  const double sigma = std::sqrt(static_cast<double>(panel.triangles.size()) / 4);
  EXPECT_NEAR(static_cast<double>(sample_surface(panel, 0.01, 3).size()), expected, 5 * sigma + 1);
}

TEST(Sampling, UniformWithinEachFace) {
  // 4 × 4 cells per face, ~625 points each; Pearson χ² with 15 degrees of freedom. The threshold
  // 37.7 is the 0.1 % quantile (a fixed seed makes the outcome deterministic anyway).
  const PointCloud cloud = sample_surface(cube(0.5), 0.005, 4);
  std::array<std::array<int, 16>, 6> cells{};
  std::array<int, 6> total{};
  for (const auto& p : cloud.points) {
    const int f = face_of(p, 0.25);
    const int u = (f / 2 + 1) % 3, v = (f / 2 + 2) % 3;
    const int cu = std::min(3, static_cast<int>((p[u] + 0.25) / 0.125));
    const int cv = std::min(3, static_cast<int>((p[v] + 0.25) / 0.125));
    ++cells[f][cu * 4 + cv], ++total[f];
  }
  for (int f = 0; f < 6; ++f) {
    const double e = total[f] / 16.0;
    double chi2 = 0;
    for (int c : cells[f]) chi2 += (c - e) * (c - e) / e;
    EXPECT_LT(chi2, 37.7) << "face " << f;
  }
}

TEST(Sampling, ReproducibleForASeed) {
  const Mesh m = cube(0.5);
  const PointCloud a = sample_surface(m, 0.03, 11), b = sample_surface(m, 0.03, 11), c = sample_surface(m, 0.03, 12);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
}

TEST(Sampling, BadArgumentsAreRefused) {
  const auto refusal = [](const Mesh& m, double spacing) -> std::string {
    try {
      sample_surface(m, spacing, 1);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    ADD_FAILURE() << "no std::invalid_argument thrown";
    return "";
  };
  EXPECT_THAT(refusal(cube(0.5), 0.0), HasSubstr("sample spacing 0 m: must be > 0"));
  EXPECT_THAT(refusal(cube(0.5), -0.01), HasSubstr("sample spacing -0.01 m: must be > 0"));
  EXPECT_THAT(refusal(cube(0.5), 1e-6), HasSubstr("gives 1.5e+12 points on 1.5 m²"));
  Mesh points;
  points.vertices = {Vec3::Zero(), Vec3::UnitX()};
  EXPECT_THAT(refusal(points, 0.01), HasSubstr("cannot sample a mesh without triangles"));
}

TEST(Sampling, VisibleFromTheFrontSeesOnlyTheFront) {
  const PanelSpec s;
  const Mesh panel = parametric_panel(s).mesh_antenna;
  const double spacing = 0.01;
  const PointCloud seen = visible_surface(panel, Vec3(0, 100, 0), spacing, 5);
  for (const auto& n : seen.normals) ASSERT_GT(n.y(), 0);
  // The front face and the front halves of the two rounded front edges (inscribed arcs).
  const double r = s.edge_radius_m, chord = 2 * r * std::sin(std::numbers::pi / 4 / s.arc_segments);
  const double area = (s.width_m - 2 * r + 2 * s.arc_segments * chord) * s.height_m;
  EXPECT_NEAR(seen.size() * spacing * spacing / area, 1.0, 0.02);
  // A subset of the full sample with the same seed.
  const PointCloud all = sample_surface(panel, spacing, 5);
  std::size_t j = 0;
  for (const auto& p : seen.points) {
    while (j < all.size() && all.points[j] != p) ++j;
    ASSERT_LT(j, all.size());
  }
}

TEST(Sampling, VisibleSurfaceIsOccluded) {
  Mesh m;
  add_cube(m, 0.5, Vec3::Zero());
  add_cube(m, 1.0, Vec3(0, 3, 0));
  // From far along +y the big cube hides the small one completely.
  for (const auto& p : visible_surface(m, Vec3(0, 100, 0), 0.02, 6).points) ASSERT_NEAR(p.y(), 3.5, 1e-12);
  // From far along −y the small cube casts a shadow on the big cube's back face (y = 2.5).
  std::size_t small = 0, around = 0;
  for (const auto& p : visible_surface(m, Vec3(0, -100, 0), 0.02, 6).points) {
    if (std::abs(p.y() + 0.25) < 1e-12) ++small;
    if (std::abs(p.y() - 2.5) > 1e-12) continue;
    ASSERT_FALSE(std::abs(p.x()) < 0.24 && std::abs(p.z()) < 0.24) << p.transpose();
    ++around;
  }
  EXPECT_NEAR(small * 0.02 * 0.02, 0.25, 0.01);
  EXPECT_NEAR(around * 0.02 * 0.02, 1.0 - 0.25 * std::pow(102.5 / 99.75, 2), 0.03);
}

// From several viewpoints: each sample once, those any of them sees (front and back here, which
// share no sample), in the full sample's order.
TEST(Sampling, VisibleFromSeveralViewpointsIsTheUnion) {
  const Mesh panel = parametric_panel(PanelSpec{}).mesh_antenna;
  const Vec3 front(0, 100, 0), back(0, -100, 0);
  const PointCloud seen_front = visible_surface(panel, front, 0.01, 5);
  const PointCloud seen_back = visible_surface(panel, back, 0.01, 5);
  const PointCloud both = visible_surface(panel, std::vector<Vec3>{front, back, front}, 0.01, 5);
  ASSERT_EQ(both.size(), seen_front.size() + seen_back.size());
  std::size_t f = 0, b = 0;
  for (const auto& p : both.points) {
    if (f < seen_front.size() && p == seen_front.points[f])
      ++f;
    else
      ASSERT_EQ(p, seen_back.points[b++]);
  }
  EXPECT_TRUE(visible_surface(panel, std::vector<Vec3>{}, 0.01, 5).empty());
}

}  // namespace
}  // namespace antpose::model
