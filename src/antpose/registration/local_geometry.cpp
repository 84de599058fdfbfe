#include "antpose/registration/local_geometry.hpp"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace antpose::registration {
namespace {

/// Covariance of point i's k-neighbourhood; false when it has fewer than 3 points.
bool neighbourhood_covariance(const KdTree& tree, std::size_t i, std::size_t k, Mat3& C) {
  thread_local std::vector<std::size_t> idx;
  thread_local std::vector<double> d2;
  const auto& pts = tree.points();
  const std::size_t n = tree.knn(pts[i], k, idx, d2);
  if (n < 3) return false;
  Vec3 mean = Vec3::Zero();
  for (std::size_t j = 0; j < n; ++j) mean += pts[idx[j]];
  mean /= static_cast<double>(n);
  C.setZero();
  for (std::size_t j = 0; j < n; ++j) {
    const Vec3 d = pts[idx[j]] - mean;
    C += d * d.transpose();
  }
  C /= static_cast<double>(n);
  return true;
}

template <class F>
void for_each_point(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
  });
}

}  // namespace

std::vector<Vec3> estimate_normals(const KdTree& tree, std::size_t k, const std::optional<Vec3>& viewpoint) {
  std::vector<Vec3> normals(tree.size(), Vec3::UnitZ());
  for_each_point(tree.size(), [&](std::size_t i) {
    Mat3 C;
    if (!neighbourhood_covariance(tree, i, k, C)) return;
    const Eigen::SelfAdjointEigenSolver<Mat3> es(C);
    Vec3 n = es.eigenvectors().col(0);  // eigenvalues ascending
    if (viewpoint && n.dot(*viewpoint - tree.points()[i]) < 0) n = -n;
    normals[i] = n;
  });
  return normals;
}

std::vector<Mat3> estimate_covariances(const KdTree& tree, std::size_t k, double epsilon) {
  std::vector<Mat3> covariances(tree.size(), Vec3(1.0, 1.0, epsilon).asDiagonal());
  for_each_point(tree.size(), [&](std::size_t i) {
    Mat3 C;
    if (!neighbourhood_covariance(tree, i, k, C)) return;
    const Eigen::SelfAdjointEigenSolver<Mat3> es(C);
    const Mat3& U = es.eigenvectors();
    covariances[i] = U * Vec3(epsilon, 1.0, 1.0).asDiagonal() * U.transpose();
  });
  return covariances;
}

}  // namespace antpose::registration
