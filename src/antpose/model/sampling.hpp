// Point samples of a mesh's surface: the model cloud that registration matches a reconstruction
// against, and simulated partial scans of it.
//
// Samples are in the mesh's frame and units (metres); each carries the unit normal of its
// triangle, which follows the triangle's winding. Built-in panels are wound outwards; a mesh from
// a file is only as consistent as its winding (scans are often mixed), which this code does not
// repair.
#pragma once

#include <cstdint>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/model/mesh.hpp"

namespace antpose::model {

/// Uniform samples by area, about one per spacing_m² (stratified per triangle: triangle i gets
/// ⌊A_i/s²⌋ points and one more with probability equal to the remainder, so a triangle smaller than
/// s² may get none), at uniform positions inside each triangle. Degenerate triangles get none.
/// Reproducible for a seed on every platform. std::invalid_argument for spacing_m ≤ 0, a mesh
/// without triangles, or more than 50 million expected points.
PointCloud sample_surface(const Mesh& mesh, double spacing_m, std::uint64_t seed);

/// The samples of sample_surface(mesh, spacing_m, seed) that `viewpoint` (same frame) sees:
/// their triangle faces it ((viewpoint − p)·n > 0, by winding) and the segment from the point to
/// the viewpoint crosses no triangle of the mesh. Brute force, O(points × triangles), meant for
/// models of a few thousand triangles (a built-in panel has a few hundred); no self-shadowing
/// tolerance beyond floating point, so coplanar neighbours do not hide each other.
PointCloud visible_surface(const Mesh& mesh, const Vec3& viewpoint, double spacing_m, std::uint64_t seed);

/// The samples that any of `viewpoints` sees (as above; each sample once): what a photo series
/// can have reconstructed of the model, so that points behind it (a mast, arms) find no back face.
PointCloud visible_surface(const Mesh& mesh, const std::vector<Vec3>& viewpoints, double spacing_m, std::uint64_t seed);

}  // namespace antpose::model
