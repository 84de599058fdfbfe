#include "antpose/registration/edge_pyramid.hpp"

#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/edge_search.hpp"
#include "antpose/registration/silhouette.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

// A photo with edges everywhere: smooth noise, so that every gradient differs.
cv::Mat textured(int cols, int rows) {
  cv::Mat noise(rows, cols, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(), 2.0);
  return noise;
}

// Largest difference between two images over their inside, `border` px from every side.
double inner_difference(const cv::Mat& a, const cv::Mat& b, int border) {
  const cv::Rect inside(border, border, a.cols - 2 * border, a.rows - 2 * border);
  return cv::norm(a(inside), b(inside), cv::NORM_INF);
}

TEST(EdgePyramid, AlignsCropsOutwardToTheCoarsestGrid) {
  const cv::Rect photo(0, 0, 100, 80);
  EXPECT_EQ(align_to_grid(cv::Rect(9, 17, 10, 10), 8, photo), cv::Rect(8, 16, 16, 16));
  EXPECT_EQ(align_to_grid(cv::Rect(-5, 70, 20, 20), 8, photo), cv::Rect(0, 64, 16, 16));  // clipped
  EXPECT_EQ(align_to_grid(cv::Rect(3, 3, 4, 4), 1, photo), cv::Rect(3, 3, 4, 4));
}

TEST(EdgePyramid, ACropInsideAKeptOneIsItsSubImageAndMatchesItsOwnPreparation) {
  const cv::Mat image = textured(640, 480);
  EdgePyramid shared(image);
  const auto first = shared.gradients(cv::Rect(200, 150, 120, 100), 3, 2.2, 1.0);
  ASSERT_EQ(first.gx.size(), 3u);
  EXPECT_EQ(first.crop.x % 4, 0);
  EXPECT_EQ(first.crop.y % 4, 0);
  // A nearby start's crop comes from the kept (grown) crop: nothing is computed again.
  const auto near = shared.gradients(cv::Rect(210, 160, 110, 96), 3, 2.2, 1.0);
  EXPECT_EQ(shared.crops_computed(), 1u);
  // It is what a preparation of that crop alone gives, away from the border the alone one reflects.
  EdgePyramid alone(image, EdgePyramidSettings::single_use(2.2, 1.0));
  const auto own = alone.gradients(cv::Rect(210, 160, 110, 96), 3, 2.2, 1.0);
  ASSERT_EQ(own.crop, near.crop);
  for (std::size_t l = 0; l < 3; ++l) {
    ASSERT_EQ(own.gx[l].size(), near.gx[l].size()) << "level " << l;
    EXPECT_LT(inner_difference(own.gx[l], near.gx[l], 8), 1e-3) << "level " << l;
    EXPECT_LT(inner_difference(own.gy[l], near.gy[l], 8), 1e-3) << "level " << l;
  }
  // Level 0 at full resolution is the photo's own linear-intensity gradient.
  const auto [gx, gy] = camera::smoothed_gradients(camera::linear_intensity(image, 2.2), 1.0);
  EXPECT_LT(cv::norm(gx(near.crop), near.gx[0], cv::NORM_INF), 1e-3);
}

TEST(EdgePyramid, KeepsTheMostRecentlyUsedCrops) {
  const cv::Mat image = textured(640, 480);
  EdgePyramidSettings settings;
  settings.growth = 0.0, settings.max_crops = 2;
  EdgePyramid p(image, settings);
  const cv::Rect a(0, 0, 64, 64), b(256, 0, 64, 64), c(0, 256, 64, 64);
  p.gradients(a, 2, 2.2, 1.0);
  p.gradients(b, 2, 2.2, 1.0);
  p.gradients(a, 2, 2.2, 1.0);  // a used last: b goes when c comes
  EXPECT_EQ(p.crops_computed(), 2u);
  p.gradients(c, 2, 2.2, 1.0);
  p.gradients(a, 2, 2.2, 1.0);
  EXPECT_EQ(p.crops_computed(), 3u);
  p.gradients(b, 2, 2.2, 1.0);
  EXPECT_EQ(p.crops_computed(), 4u);
  // A deeper pyramid than any kept is computed anew.
  p.gradients(b, 5, 2.2, 1.0);
  EXPECT_EQ(p.crops_computed(), 5u);
}

TEST(EdgePyramid, RefusesAnotherPreparationAndBadInput) {
  EdgePyramid p(textured(64, 64));
  EXPECT_TRUE(p.serves(2.2, 1.0));
  EXPECT_FALSE(p.serves(0.0, 1.0));
  EXPECT_THROW(p.gradients(cv::Rect(0, 0, 32, 32), 2, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(p.gradients(cv::Rect(0, 0, 32, 32), 0, 2.2, 1.0), std::invalid_argument);
  EXPECT_TRUE(p.gradients(cv::Rect(100, 100, 8, 8), 1, 2.2, 1.0).gx.empty());  // off the photo
  EXPECT_THROW(EdgePyramid(cv::Mat(8, 8, CV_32F)), std::invalid_argument);
}

// The outline refinement gives the same pose with its photos' edge images shared as with each
// descent preparing its own, and the shared ones are prepared once per photo.
TEST(EdgePyramid, SharedByARefinementGivesItsPose) {
  const auto s = fixture::make_scene();
  auto views = s.views;
  for (auto& v : views) v.edges = std::make_shared<EdgePyramid>(v.image);
  const Iso3 T = s.T_board_antenna;
  Iso3 start = T;
  start.translation() += Vec3(0.02, -0.02, 0.01);
  const auto own = refine_by_silhouette(s.mesh_antenna, start, s.views, s.intrinsics, {});
  const auto shared = refine_by_silhouette(s.mesh_antenna, start, views, s.intrinsics, {});
  const auto again = refine_by_silhouette(s.mesh_antenna, T, views, s.intrinsics, {});
  ASSERT_TRUE(own.converged);
  ASSERT_TRUE(shared.converged);
  EXPECT_LT(rad2deg(log_so3(own.T_board_antenna.linear() * shared.T_board_antenna.linear().transpose()).norm()), 0.02);
  EXPECT_LT((own.T_board_antenna.translation() - shared.T_board_antenna.translation()).norm(), 5e-4);
  EXPECT_TRUE(again.converged);
  for (const auto& v : views) EXPECT_EQ(v.edges->crops_computed(), 1u);
}

}  // namespace
}  // namespace antpose::registration
