#include "antpose/core/statistics.hpp"

#include <gtest/gtest.h>

namespace antpose {
namespace {

TEST(Statistics, MedianIsTheMiddleOrUpperMiddleValue) {
  EXPECT_DOUBLE_EQ(median(std::vector<double>{5, 1, 3}), 3.0);
  EXPECT_DOUBLE_EQ(median(std::vector<double>{4, 1, 3, 2}), 3.0);  // rank n/2 of 1 2 3 4
  EXPECT_DOUBLE_EQ(median(std::vector<float>{2.5f}), 2.5);
  EXPECT_DOUBLE_EQ(median(std::vector<double>{}), 0.0);
  // Robust: one wild value does not move it.
  EXPECT_DOUBLE_EQ(median(std::vector<double>{1.0, 1.1, 0.9, 1e9, 1.05}), 1.05);
}

TEST(Statistics, MedianLeavesTheCallersValuesAlone) {
  const std::vector<double> v{9, 7, 8, 1};
  EXPECT_DOUBLE_EQ(median(v), 8.0);
  EXPECT_EQ(v, (std::vector<double>{9, 7, 8, 1}));
}

TEST(Statistics, QuantileByRank) {
  const std::vector<double> v{50, 10, 40, 20, 30};
  EXPECT_DOUBLE_EQ(quantile(v, 0.0), 10.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.25), 20.0);
  EXPECT_DOUBLE_EQ(quantile(v, 0.5), 30.0);
  EXPECT_DOUBLE_EQ(quantile(v, 1.0), 50.0);
  EXPECT_DOUBLE_EQ(quantile(v, 7.0), 50.0);  // clamped
  EXPECT_DOUBLE_EQ(quantile(std::vector<double>{}, 0.5), 0.0);
}

}  // namespace
}  // namespace antpose
