// The model welded into edges and convex facets for the silhouette refinement
// (silhouette_detail.hpp).
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include "antpose/registration/silhouette_detail.hpp"

namespace antpose::registration::detail {
namespace {

// Triangles that share an edge and a plane, joined (union–find by root).
std::vector<std::uint32_t> coplanar_groups(const EdgeMesh& m) {
  std::vector<std::uint32_t> root(m.triangles.size());
  std::iota(root.begin(), root.end(), 0u);
  const auto find = [&](std::uint32_t f) {
    while (root[f] != f) f = root[f] = root[root[f]];
    return f;
  };
  double extent = 1.0;
  for (const Vec3& v : m.vertices) extent = std::max(extent, v.cwiseAbs().maxCoeff());
  const auto plane = [&](std::uint32_t f) {
    const Vec3 n = m.normals[f].normalized();
    return std::make_pair(n, n.dot(m.vertices[m.triangles[f][0]]));
  };
  for (const auto& e : m.edges) {
    if (e.faces.size() != 2) continue;
    const auto [na, da] = plane(e.faces[0]);
    const auto [nb, db] = plane(e.faces[1]);
    if (na.dot(nb) > 1 - 1e-12 && std::abs(da - db) < 1e-9 * extent) root[find(e.faces[0])] = find(e.faces[1]);
  }
  for (std::uint32_t f = 0; f < root.size(); ++f) root[f] = find(f);
  return root;
}

// The boundary of coplanar triangles as one loop, wound as they are, where it is one convex
// polygon (collinear vertices allowed); else nothing.
std::optional<std::vector<std::uint32_t>> convex_loop(const EdgeMesh& m, const std::vector<std::uint32_t>& group) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto f : group)
    for (int k = 0; k < 3; ++k) ++directed[{m.triangles[f][k], m.triangles[f][(k + 1) % 3]}];
  std::map<std::uint32_t, std::uint32_t> next;
  for (const auto& [edge, count] : directed) {
    if (directed.count({edge.second, edge.first})) continue;  // inside the polygon
    if (count != 1 || !next.emplace(edge.first, edge.second).second) return std::nullopt;
  }
  if (next.size() < 3) return std::nullopt;
  std::vector<std::uint32_t> loop{next.begin()->first};
  while (loop.size() <= next.size()) {
    const auto it = next.find(loop.back());
    if (it == next.end()) return std::nullopt;
    if (it->second == loop.front()) break;
    loop.push_back(it->second);
  }
  if (loop.size() != next.size()) return std::nullopt;  // a hole, or several pieces
  const Vec3 n = m.normals[group.front()];
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Vec3& a = m.vertices[loop[k]];
    const Vec3& b = m.vertices[loop[(k + 1) % loop.size()]];
    const Vec3& c = m.vertices[loop[(k + 2) % loop.size()]];
    const Vec3 ab = b - a, bc = c - b;
    if (ab.cross(bc).dot(n) < -1e-9 * ab.norm() * bc.norm() * n.norm()) return std::nullopt;
  }
  return loop;
}

// Coplanar neighbouring triangles merged into convex polygons, each filled in one go where the
// projection is drawn (a panel's long sides are a few such polygons instead of tens of triangles);
// triangles whose group is not one convex polygon stay facets of their own.
std::vector<EdgeMesh::Facet> convex_facets(const EdgeMesh& m) {
  const auto root = coplanar_groups(m);
  std::map<std::uint32_t, std::vector<std::uint32_t>> groups;
  for (std::uint32_t f = 0; f < root.size(); ++f) groups[root[f]].push_back(f);
  std::vector<EdgeMesh::Facet> facets;
  for (const auto& [r, group] : groups) {
    if (group.size() > 1)
      if (auto loop = convex_loop(m, group)) {
        facets.push_back({std::move(*loop), group.front()});
        continue;
      }
    for (const auto f : group) facets.push_back({{m.triangles[f][0], m.triangles[f][1], m.triangles[f][2]}, f});
  }
  return facets;
}

}  // namespace

EdgeMesh weld(const model::Mesh& mesh) {
  EdgeMesh m;
  std::map<std::tuple<long long, long long, long long>, std::uint32_t> index;
  std::vector<std::uint32_t> remap(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    const auto key = std::make_tuple(std::llround(v.x() * 1e7), std::llround(v.y() * 1e7), std::llround(v.z() * 1e7));
    const auto [it, inserted] = index.emplace(key, static_cast<std::uint32_t>(m.vertices.size()));
    if (inserted) m.vertices.push_back(v);
    remap[i] = it->second;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> edge_index;
  for (const auto& t : mesh.triangles) {
    const std::array<std::uint32_t, 3> w{remap.at(t[0]), remap.at(t[1]), remap.at(t[2])};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;
    const auto f = static_cast<std::uint32_t>(m.triangles.size());
    m.triangles.push_back(w);
    m.normals.push_back((m.vertices[w[1]] - m.vertices[w[0]]).cross(m.vertices[w[2]] - m.vertices[w[0]]));
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(w[k], w[(k + 1) % 3]);
      const auto [it, inserted] = edge_index.emplace(key, m.edges.size());
      if (inserted) m.edges.push_back({key.first, key.second, {}});
      m.edges[it->second].faces.push_back(f);
    }
  }
  m.closed = std::all_of(m.edges.begin(), m.edges.end(), [](const EdgeMesh::Edge& e) { return e.faces.size() >= 2; });
  m.facets = convex_facets(m);
  return m;
}

}  // namespace antpose::registration::detail
