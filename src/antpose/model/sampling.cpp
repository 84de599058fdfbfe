#include "antpose/model/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

namespace antpose::model {

namespace {

// Beyond this a cloud takes gigabytes: a spacing in the wrong unit, not a request.
constexpr double kMaxPoints = 50e6;

// Uniform in [0, 1) from the top 53 bits: the standard's distributions are implementation-defined,
// the engine's output is not, so this keeps samples identical across standard libraries.
double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

struct Samples {
  PointCloud cloud;
  std::vector<std::size_t> triangle;  // of each point
};

Samples sample(const Mesh& mesh, double spacing_m, std::uint64_t seed) {
  if (!(spacing_m > 0) || !std::isfinite(spacing_m))
    throw std::invalid_argument(fmt::format("sample spacing {} m: must be > 0", spacing_m));
  if (mesh.triangles.empty()) throw std::invalid_argument("cannot sample a mesh without triangles");
  const double per_m2 = 1.0 / (spacing_m * spacing_m);
  const double expected = surface_area(mesh) * per_m2;
  if (expected > kMaxPoints)
    throw std::invalid_argument(fmt::format("sample spacing {} m gives {:.3g} points on {:.3g} m², more than {:g}",
                                            spacing_m, expected, surface_area(mesh), kMaxPoints));
  std::mt19937_64 rng(seed);
  Samples out;
  out.cloud.points.reserve(static_cast<std::size_t>(expected) + mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const double m = triangle_area(mesh, i) * per_m2;
    const auto count = static_cast<std::size_t>(m) + (uniform(rng) < m - std::floor(m) ? 1 : 0);
    const Vec3 n = triangle_normal(mesh, i);
    const auto& t = mesh.triangles[i];
    const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    for (std::size_t k = 0; k < count; ++k) {
      // Uniform in the triangle: s = √u1 spreads the points evenly from vertex a to edge bc.
      const double s = std::sqrt(uniform(rng)), r = uniform(rng);
      out.cloud.points.push_back((1 - s) * a + s * (1 - r) * b + s * r * c);
      out.cloud.normals.push_back(n);
      out.triangle.push_back(i);
    }
  }
  return out;
}

// Möller–Trumbore: does the segment p + t d, t in (ε, 1), cross triangle (a, a + e1, a + e2)?
bool segment_hits(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& e1, const Vec3& e2) {
  // ε in the segment's parameter: the start point lies on its own surface, and a neighbouring
  // triangle through it must not count as an obstacle at t ≈ 0.
  constexpr double kTMin = 1e-9;
  const Vec3 q = d.cross(e2);
  const double det = e1.dot(q);
  if (det == 0) return false;  // parallel to the plane
  const double inv = 1.0 / det;
  const Vec3 s = p - a;
  const double u = s.dot(q) * inv;
  if (u < 0 || u > 1) return false;
  const Vec3 r = s.cross(e1);
  const double v = d.dot(r) * inv;
  if (v < 0 || u + v > 1) return false;
  const double t = e2.dot(r) * inv;
  return t > kTMin && t < 1;
}

bool occluded(const Mesh& mesh, std::size_t own, const Vec3& p, const Vec3& viewpoint) {
  const Vec3 d = viewpoint - p;
  for (std::size_t j = 0; j < mesh.triangles.size(); ++j) {
    if (j == own) continue;
    const auto& t = mesh.triangles[j];
    const Vec3& a = mesh.vertices[t[0]];
    if (segment_hits(p, d, a, mesh.vertices[t[1]] - a, mesh.vertices[t[2]] - a)) return true;
  }
  return false;
}

}  // namespace

PointCloud sample_surface(const Mesh& mesh, double spacing_m, std::uint64_t seed) {
  return sample(mesh, spacing_m, seed).cloud;
}

PointCloud visible_surface(const Mesh& mesh, const Vec3& viewpoint, double spacing_m, std::uint64_t seed) {
  return visible_surface(mesh, std::vector<Vec3>{viewpoint}, spacing_m, seed);
}

PointCloud visible_surface(const Mesh& mesh, const std::vector<Vec3>& viewpoints, double spacing_m,
                           std::uint64_t seed) {
  const Samples all = sample(mesh, spacing_m, seed);
  PointCloud out;
  for (std::size_t k = 0; k < all.cloud.size(); ++k) {
    const Vec3& p = all.cloud.points[k];
    const Vec3& n = all.cloud.normals[k];
    const auto sees = [&](const Vec3& viewpoint) {
      return n.dot(viewpoint - p) > 0 && !occluded(mesh, all.triangle[k], p, viewpoint);
    };
    if (std::none_of(viewpoints.begin(), viewpoints.end(), sees)) continue;
    out.points.push_back(p);
    out.normals.push_back(n);
  }
  return out;
}

}  // namespace antpose::model
