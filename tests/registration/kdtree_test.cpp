#include "antpose/registration/kdtree.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace antpose::registration {
namespace {

// The nearest point, bounded or not, is the brute-force nearest: the bound only says whether it
// counts, a point exactly at the bound included.
TEST(KdTree, NearestWithinABoundIsTheBruteForceNearestOrNone) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> points(2000);
  for (auto& p : points) p = Vec3(u(rng), u(rng), 0.2 * u(rng));
  const KdTree tree(points);
  int found_within = 0, none_within = 0;
  for (int q = 0; q < 500; ++q) {
    const Vec3 query(1.5 * u(rng), 1.5 * u(rng), u(rng));
    std::size_t best = 0;
    for (std::size_t i = 1; i < points.size(); ++i)
      if ((points[i] - query).squaredNorm() < (points[best] - query).squaredNorm()) best = i;
    const double best_d2 = (points[best] - query).squaredNorm();

    std::size_t index = 0;
    double d2 = 0.0;
    ASSERT_TRUE(tree.nearest(query, index, d2));
    EXPECT_EQ(index, best);
    EXPECT_DOUBLE_EQ(d2, best_d2);

    const double bound = 0.01;
    const bool within = tree.nearest(query, index, d2, bound);
    EXPECT_EQ(within, best_d2 <= bound) << best_d2;
    if (within) {
      EXPECT_EQ(index, best);
      ++found_within;
    } else {
      ++none_within;
    }
  }
  EXPECT_GT(found_within, 50);  // both cases were exercised
  EXPECT_GT(none_within, 50);
}

TEST(KdTree, APointExactlyAtTheBoundCountsAndAnEmptyTreeHasNone) {
  const KdTree tree({Vec3(0.0, 0.0, 0.0), Vec3(3.0, 0.0, 0.0)});
  std::size_t index = 9;
  double d2 = 0.0;
  ASSERT_TRUE(tree.nearest(Vec3(1.0, 0.0, 0.0), index, d2, 1.0));
  EXPECT_EQ(index, 0u);
  EXPECT_EQ(d2, 1.0);
  EXPECT_FALSE(tree.nearest(Vec3(1.0, 0.0, 0.0), index, d2, std::nextafter(1.0, 0.0)));

  const KdTree empty(std::vector<Vec3>{});
  EXPECT_FALSE(empty.nearest(Vec3::Zero(), index, d2));
}

}  // namespace
}  // namespace antpose::registration
