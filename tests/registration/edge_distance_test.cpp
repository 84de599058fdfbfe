#include "antpose/registration/edge_distance.hpp"

#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace antpose::registration {
namespace {

// A pale rectangle on a slightly brighter sky (5 grey levels), with sensor noise of σ 1.
cv::Mat faint_panel(double noise, std::uint64_t seed) {
  cv::Mat f(400, 300, CV_32F, cv::Scalar(230));
  f(cv::Rect(100, 50, 80, 300)).setTo(225);
  cv::Mat n(f.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(n, cv::RNG::NORMAL, 0.0, noise);
  cv::Mat out;
  cv::Mat(f + n).convertTo(out, CV_8U);
  return out;
}

TEST(EdgeDistance, FindsAFaintOutlineAboveTheNoiseWhateverTheLight) {
  const cv::Mat image = faint_panel(1.0, 3);
  const EdgeDistance map(image, cv::Rect(0, 0, image.cols, image.rows), 0.5, {}, {});
  EXPECT_NEAR(map.noise_grey(), 0.5, 0.3) << "σ 1 halved by the resize's averaging of 2 × 2 pixels";
  // The left edge runs along y: its normal along x. A point 6 px (3 map px) to its right.
  EdgeLookup status;
  const int across = map.bin(Vec2(1.0, 0.0));
  const double d = map.distance(Vec2(106.0, 200.0), across, status);
  EXPECT_EQ(status, EdgeLookup::kMeasured);
  EXPECT_NEAR(d, 3.0, 1.0);
  // An edge running the other way is far: the top edge's normal is along y.
  const double along = map.distance(Vec2(106.0, 200.0), map.bin(Vec2(0.0, 1.0)), status);
  EXPECT_GT(along, 20.0);
  // Noise alone gives almost no edges at these thresholds.
  const cv::Mat sky = image(cv::Rect(200, 0, 100, 400)).clone();
  const EdgeDistance plain(sky, cv::Rect(0, 0, sky.cols, sky.rows), 0.5, {}, {});
  EXPECT_LT(cv::countNonZero(plain.edges()), 10);
}

TEST(EdgeDistance, AnOutlineMeetsEdgesOfItsOwnDirectionOrTheNextOnly) {
  // A dark parallelogram whose left side's gradient runs at 15° (mod 180°), the middle of the
  // first of six 30° bins; its other sides run along x, far from the point looked up.
  cv::Mat image(400, 400, CV_8UC1, cv::Scalar(230));
  const std::vector<cv::Point> shape{{189, 55}, {289, 55}, {211, 345}, {111, 345}};
  cv::fillConvexPoly(image, shape, cv::Scalar(200), cv::LINE_AA);
  const EdgeDistance map(image, cv::Rect(0, 0, image.cols, image.rows), 0.5, {}, {});
  // 6 px (3 map px) from the left side, along its normal.
  const double a = deg2rad(15.0);
  const Vec2 p = Vec2(150.0, 200.0) - 6.0 * Vec2(std::cos(a), std::sin(a));
  const auto at = [&](double degrees) {
    EdgeLookup status;
    const double b = deg2rad(degrees);
    const double d = map.distance(p, map.bin(Vec2(std::cos(b), std::sin(b))), status);
    EXPECT_EQ(status, EdgeLookup::kMeasured);
    return d;
  };
  EXPECT_EQ(map.bin(Vec2(std::cos(a), std::sin(a))), 0);
  EXPECT_NEAR(at(15.0), 3.0, 1.0);
  // The next bins either side (1 and 5) take it too; bins 2 and 4 do not.
  EXPECT_NEAR(at(50.0), 3.0, 1.0);
  EXPECT_NEAR(at(-20.0), 3.0, 1.0);
  EXPECT_GT(at(75.0), 20.0);
  EXPECT_GT(at(-45.0), 20.0);
}

TEST(EdgeDistance, KnownOccludersAndTheOutsideSayTheirName) {
  const cv::Mat image = faint_panel(1.0, 4);
  const std::vector<std::vector<cv::Point2f>> board{{{90, 150}, {200, 150}, {200, 250}, {90, 250}}};
  const EdgeDistance map(image, cv::Rect(20, 20, 250, 360), 1.0, board, {});
  EdgeLookup status;
  map.distance(Vec2(140.0, 200.0), 0, status);
  EXPECT_EQ(status, EdgeLookup::kMasked);
  map.distance(Vec2(5.0, 5.0), 0, status);
  EXPECT_EQ(status, EdgeLookup::kOutside);
  // Beside the board the left edge is found as usual.
  const double above = map.distance(Vec2(100.0, 140.0), map.bin(Vec2(1.0, 0.0)), status);
  EXPECT_EQ(status, EdgeLookup::kMeasured);
  EXPECT_LT(above, 2.0);
}

}  // namespace
}  // namespace antpose::registration
