// The local surface around each point, from its k nearest neighbours: normals (Hoppe, DeRose,
// Duchamp, McDonald & Stuetzle, "Surface reconstruction from unorganized points", SIGGRAPH 1992:
// the eigenvector of the smallest eigenvalue of the neighbourhood covariance) and the
// plane-like covariances of generalized ICP (Segal, Haehnel & Thrun, "Generalized-ICP", RSS
// 2009, §III-B: eigenvalues replaced by (ε, 1, 1), so a point is a small disc on its surface).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/registration/kdtree.hpp"

namespace antpose::registration {

/// Unit normals of `points` (indexed by `tree`, built over the same points). With a viewpoint,
/// each normal points towards it (a scanner or camera sees the outer side); without, the sign is
/// arbitrary. A point with fewer than 3 neighbours gets (0, 0, 1).
std::vector<Vec3> estimate_normals(const KdTree& tree, std::size_t k = 10,
                                   const std::optional<Vec3>& viewpoint = std::nullopt);

/// GICP covariances (m², same frame as the points), scaled so the in-plane variances are 1 and
/// the normal one `epsilon`.
std::vector<Mat3> estimate_covariances(const KdTree& tree, std::size_t k = 20, double epsilon = 1e-3);

}  // namespace antpose::registration
