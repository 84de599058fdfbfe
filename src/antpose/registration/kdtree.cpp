#include "antpose/registration/kdtree.hpp"

#include <cmath>

#include <nanoflann.hpp>

namespace antpose::registration {

struct KdTree::Impl {
  // nanoflann's dataset interface over the stored points.
  struct Adaptor {
    const std::vector<Vec3>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][static_cast<int>(dim)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree =
      nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>, Adaptor, 3, std::size_t>;

  explicit Impl(std::vector<Vec3> p)
      : points(std::move(p)), adaptor{&points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {}

  std::vector<Vec3> points;
  Adaptor adaptor;
  Tree tree;
};

KdTree::KdTree(std::vector<Vec3> points) : impl_(std::make_unique<Impl>(std::move(points))) {}
KdTree::~KdTree() = default;
KdTree::KdTree(KdTree&&) noexcept = default;
KdTree& KdTree::operator=(KdTree&&) noexcept = default;

const std::vector<Vec3>& KdTree::points() const { return impl_->points; }

bool KdTree::nearest(const Vec3& query, std::size_t& index, double& squared_distance,
                     double max_squared_distance) const {
  if (impl_->points.empty()) return false;
  nanoflann::KNNResultSet<double, std::size_t> result(1);
  result.init(&index, &squared_distance);
  // The result set's worst distance is the search's pruning bound, and nanoflann takes a point
  // only strictly closer than it: the next double above the bound keeps points at the bound.
  if (max_squared_distance < std::numeric_limits<double>::infinity())
    squared_distance = std::nextafter(max_squared_distance, std::numeric_limits<double>::infinity());
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.size() > 0;
}

std::size_t KdTree::knn(const Vec3& query, std::size_t k, std::vector<std::size_t>& indices,
                        std::vector<double>& squared_distances) const {
  k = std::min(k, impl_->points.size());
  indices.resize(k);
  squared_distances.resize(k);
  if (k == 0) return 0;
  const std::size_t found = impl_->tree.knnSearch(query.data(), k, indices.data(), squared_distances.data());
  indices.resize(found);
  squared_distances.resize(found);
  return found;
}

}  // namespace antpose::registration
