#include <numeric>

#include <gtest/gtest.h>

#include "antpose/model/antenna_model.hpp"
#include "antpose/registration/silhouette_detail.hpp"

namespace antpose::registration::detail {
namespace {

double triangle_area(const EdgeMesh& m, std::uint32_t f) {
  const auto& t = m.triangles[f];
  return 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
}

// A facet's area by its loop (as wound: positive about its triangles' normal), and whether every
// turn of the loop keeps to that side (convex) with every vertex in the plane.
double facet_area(const EdgeMesh& m, const EdgeMesh::Facet& f, bool& convex) {
  const Vec3 n = m.normals[f.triangle].normalized();
  const Vec3& origin = m.vertices[f.loop.front()];
  const std::size_t k = f.loop.size();
  double twice = 0;
  convex = true;
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3 a = m.vertices[f.loop[i]] - origin, b = m.vertices[f.loop[(i + 1) % k]] - origin;
    const Vec3 c = m.vertices[f.loop[(i + 2) % k]] - origin;
    twice += a.cross(b).dot(n);
    convex = convex && (b - a).cross(c - b).dot(n) >= -1e-12 && std::abs(a.dot(n)) < 1e-9;
  }
  return 0.5 * twice;
}

// The facets cover the mesh: as much area as its triangles, each triangle's plane once, every
// facet convex and planar.
void expect_facets_cover(const EdgeMesh& m) {
  double triangles = 0, facets = 0;
  for (std::uint32_t f = 0; f < m.triangles.size(); ++f) triangles += triangle_area(m, f);
  for (const auto& f : m.facets) {
    bool convex = false;
    facets += facet_area(m, f, convex);
    EXPECT_TRUE(convex) << "a facet of " << f.loop.size() << " corners";
  }
  EXPECT_NEAR(facets, triangles, 1e-9 * triangles);
}

TEST(EdgeMesh, APanelsCoplanarTrianglesAreFewConvexFacets) {
  model::PanelSpec spec;
  spec.end_cap_height_m = 0.05, spec.end_cap_rim_m = 0.01;
  const EdgeMesh m = weld(model::parametric_panel(spec).mesh_antenna);
  ASSERT_TRUE(m.closed);
  expect_facets_cover(m);
  // The long sides, split at the brackets' heights and into triangles, are one facet each.
  EXPECT_LT(m.facets.size(), m.triangles.size() / 2);
}

// An L in one plane is not convex: its triangles stay facets of their own.
TEST(EdgeMesh, ANonConvexPlanarPieceKeepsItsTriangles) {
  model::Mesh l;
  l.vertices = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}, {0, 1, 0}};
  l.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 6}, {6, 3, 4}, {6, 4, 5}};
  const EdgeMesh m = weld(l);
  EXPECT_EQ(m.facets.size(), l.triangles.size());
  expect_facets_cover(m);

  model::Mesh square;  // the same plane, convex: one facet
  square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0, 0}};
  square.triangles = {{0, 4, 3}, {4, 1, 2}, {4, 2, 3}};
  const EdgeMesh one = weld(square);
  ASSERT_EQ(one.facets.size(), 1u);
  EXPECT_EQ(one.facets.front().loop.size(), 5u);  // the collinear vertex kept in the loop
  expect_facets_cover(one);
}

}  // namespace
}  // namespace antpose::registration::detail
