// Nearest-neighbour search over a fixed set of 3-D points: a k-d tree (nanoflann, J. L. Blanco &
// P. K. Rai, https://github.com/jlblancoc/nanoflann). Thread-safe for concurrent queries.
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "antpose/geometry/rotation.hpp"

namespace antpose::registration {

class KdTree {
 public:
  /// Builds the tree over a copy of `points` (metres, any frame).
  explicit KdTree(std::vector<Vec3> points);
  ~KdTree();
  KdTree(KdTree&&) noexcept;
  KdTree& operator=(KdTree&&) noexcept;

  const std::vector<Vec3>& points() const;
  std::size_t size() const { return points().size(); }

  /// The nearest point within `max_squared_distance` (m²): its index and squared distance, or
  /// false where there is none (an empty tree). A bound prunes the search: ICP and scores ask
  /// only about nearby points, and most of the tree lies beyond them.
  bool nearest(const Vec3& query, std::size_t& index, double& squared_distance,
               double max_squared_distance = std::numeric_limits<double>::infinity()) const;
  /// Up to k nearest points, closest first; returns how many were found.
  std::size_t knn(const Vec3& query, std::size_t k, std::vector<std::size_t>& indices,
                  std::vector<double>& squared_distances) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace antpose::registration
