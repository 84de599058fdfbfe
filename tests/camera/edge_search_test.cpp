#include "antpose/camera/edge_search.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace antpose::camera {
namespace {

// A photo of a vertical step from dark to light at x = edge (px; pixel centres at integers, so a
// pixel straddling the edge is mixed): linear radiance blurred by the optics, then encoded with a
// gamma of 2.2 as a phone does.
cv::Mat step_image(double edge, int width = 80, int height = 40) {
  cv::Mat radiance(height, width, CV_32F);
  for (int x = 0; x < width; ++x) {
    const double cover = std::clamp(x + 0.5 - edge, 0.0, 1.0);  // share of pixel x right of the edge
    radiance.col(x).setTo(cv::Scalar(0.05 + 0.75 * cover));
  }
  cv::GaussianBlur(radiance, radiance, cv::Size(), 0.8);
  cv::Mat encoded;
  cv::pow(radiance, 1.0 / 2.2, encoded);
  encoded.convertTo(encoded, CV_8UC1, 255.0);
  return encoded;
}

// Half-pixel samples of bilinearly interpolated gradients and a parabola through the peak: the
// position is biased towards the samples by up to a quarter pixel, which averages out over an
// outline's many samples at random phases.
TEST(EdgeSearch, FindsAStepToAQuarterPixelInLinearIntensity) {
  std::vector<double> scratch;
  for (const double edge : {30.0, 30.25, 30.5, 31.8}) {
    const auto [gx, gy] = smoothed_gradients(linear_intensity(step_image(edge), 2.2), 1.0);
    // From left and right of the edge, along +x: the signed distance to it.
    for (const double from : {24.0, 36.0}) {
      const auto d =
          nearest_edge(gx, gy, Vec2(from, 20.0), Vec2(1.0, 0.0), EdgeSearchSpan::symmetric(10.0), 3.0, scratch);
      ASSERT_TRUE(d.has_value()) << edge << " " << from;
      EXPECT_NEAR(from + *d, edge, 0.27) << edge << " " << from;
    }
    // Out of reach, or along the edge: none.
    EXPECT_FALSE(nearest_edge(gx, gy, Vec2(10.0, 20.0), Vec2(1.0, 0.0), EdgeSearchSpan::symmetric(5.0), 3.0, scratch)
                     .has_value());
    EXPECT_FALSE(nearest_edge(gx, gy, Vec2(30.0, 20.0), Vec2(0.0, 1.0), EdgeSearchSpan::symmetric(10.0), 3.0, scratch)
                     .has_value());
  }
}

// Of two edges the nearer strong one wins, a weak one (below half the strongest) never; where
// the gradients are zeroed (a masked object), nothing is found there. The steps are sharp (the
// bilinear samples of a sharp gradient peak have a flat top, so a quarter pixel is as close as
// it gets).
TEST(EdgeSearch, TakesTheNearestStrongEdgeAndNeverAMaskedOne) {
  cv::Mat m(40, 100, CV_8UC1, cv::Scalar(40));
  m.colRange(30, 100).setTo(200);  // strong step at 29.5
  m.colRange(60, 100).setTo(230);  // weak step at 59.5
  m.colRange(70, 100).setTo(20);   // strong step at 69.5
  auto [gx, gy] = smoothed_gradients(linear_intensity(m, 0.0), 1.0);
  std::vector<double> scratch;
  const auto nearest = [&](double x) {
    return nearest_edge(gx, gy, Vec2(x, 20.0), Vec2(1.0, 0.0), EdgeSearchSpan::symmetric(25.0), 3.0, scratch);
  };
  ASSERT_TRUE(nearest(45.0).has_value());
  EXPECT_NEAR(45.0 + *nearest(45.0), 29.5, 0.3);  // 15.5 px left; the weak step 14.5 px right is ignored
  EXPECT_NEAR(52.0 + *nearest(52.0), 69.5, 0.3);
  cv::Mat mask = cv::Mat::zeros(gx.size(), CV_8UC1);
  mask.colRange(64, 76).setTo(255);
  gx.setTo(0, mask), gy.setTo(0, mask);
  ASSERT_TRUE(nearest(52.0).has_value());
  EXPECT_NEAR(52.0 + *nearest(52.0), 29.5, 0.3);  // the masked step is not there any more
}

// A panel narrower than the search range, 20 px wide: its edge against a dark mast (left) is
// weaker in linear intensity than its far edge against the bright sky. Searched both ways the far
// edge is the nearest strong one; with the line behind the outline ending at the panel's middle,
// the panel's own edge is found.
TEST(EdgeSearch, ALineEndingBehindAtThePanelsMiddleFindsItsOwnWeakerEdge) {
  cv::Mat m(40, 100, CV_8UC1, cv::Scalar(100));  // mast
  m.colRange(30, 50).setTo(150);                 // panel: edges at 29.5 and 49.5
  m.colRange(50, 100).setTo(235);                // sky
  const auto [gx, gy] = smoothed_gradients(linear_intensity(m, 2.2), 1.0);
  std::vector<double> scratch;
  const Vec2 outward(-1.0, 0.0);  // the panel's left outline, predicted at x = 31
  const auto both_ways = nearest_edge(gx, gy, Vec2(31.0, 20.0), outward, EdgeSearchSpan::symmetric(25.0), 3.0, scratch);
  ASSERT_TRUE(both_ways.has_value());
  EXPECT_NEAR(31.0 - *both_ways, 49.5, 0.3);
  const auto own = nearest_edge(gx, gy, Vec2(31.0, 20.0), outward, {10.0, 25.0}, 3.0, scratch);
  ASSERT_TRUE(own.has_value());
  EXPECT_NEAR(31.0 - *own, 29.5, 0.3);
}

// The gradient along a normal is the bilinear blend of the four pixels about the point, for both
// images with the same weights, and 0 where the four are not all inside (the search line's end).
TEST(EdgeSearch, GradientAlongANormalBlendsTheFourPixelsAboutThePoint) {
  cv::Mat gx(4, 5, CV_32F), gy(4, 5, CV_32F);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x)
      gx.at<float>(y, x) = static_cast<float>(10 * x + y), gy.at<float>(y, x) = static_cast<float>(x * y);
  const Vec2 normal(0.6, 0.8);
  // At (1.25, 2.5): gx is linear, 10·1.25 + 2.5 = 15; gy blends 2, 3 (row 2) and 3, 4.5 (row 3).
  const double gy_here = 0.5 * (0.75 * 2 + 0.25 * 4) + 0.5 * (0.75 * 3 + 0.25 * 6);
  EXPECT_NEAR(gradient_along(gx, gy, Vec2(1.25, 2.5), normal), 0.6 * 15.0 + 0.8 * gy_here, 1e-5);
  EXPECT_NEAR(gradient_along(gx, gy, Vec2(3.0, 1.0), normal), 0.6 * 31.0 + 0.8 * 3.0, 1e-5);
  for (const Vec2& off : {Vec2(-0.1, 1.0), Vec2(4.0, 1.0), Vec2(1.0, 3.0), Vec2(2.0, -0.5)})
    EXPECT_EQ(gradient_along(gx, gy, off, normal), 0.0) << off.transpose();
}

}  // namespace
}  // namespace antpose::camera
