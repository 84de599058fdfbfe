#include "antpose/registration/known_object_masks.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "antpose/registration/edge_pyramid.hpp"

namespace antpose::registration {
namespace {

// A photo with a bright bar (edges to mask) and a view of it with an occluder over the bar's
// left end and a background edge across its right end.
struct MaskScene {
  cv::Mat image = cv::Mat(600, 800, CV_8UC1, cv::Scalar(60));
  SilhouetteView view;
  std::shared_ptr<EdgePyramid> edges;

  MaskScene() {
    cv::rectangle(image, cv::Rect(200, 250, 400, 100), cv::Scalar(200), cv::FILLED);
    view.image = image;
    view.occluders = {{{180, 230}, {300, 230}, {300, 370}, {180, 370}}};
    view.background_edges = {{{500.5f, 220}, {520.5f, 380}}};
    edges = std::make_shared<EdgePyramid>(image);
    view.edges = edges;
  }
};

// The masked images a refinement prepares on its own: the mask drawn over its crop, the edge
// images zeroed under it.
MaskedEdges drawn_alone(const SilhouetteView& view, const EdgeLevels& levels, int level, double guard_px) {
  MaskedEdges out;
  const auto l = static_cast<std::size_t>(level);
  out.mask = known_object_mask(view, Vec2(levels.crop.x, levels.crop.y), levels.gx[l].size(), level, guard_px);
  out.gx = levels.gx[l].clone(), out.gy = levels.gy[l].clone();
  out.gx.setTo(0, out.mask), out.gy.setTo(0, out.mask);
  return out;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Crops that lie inside one kept crop are served from one drawing per level, and each is what a
// refinement would have drawn on its own (no known object lies near their borders).
TEST(KnownObjectMasks, CropsInsideAKeptCropShareOneDrawingAndMatchTheirOwn) {
  MaskScene s;
  KnownObjectMasks masks;
  for (const cv::Rect crop : {cv::Rect(150, 200, 500, 200), cv::Rect(160, 208, 480, 184)}) {
    const EdgeLevels levels = s.edges->gradients(crop, 3, 2.2, 1.0);
    ASSERT_EQ(levels.gx.size(), 3u);
    for (int level = 0; level < 3; ++level) {
      const auto l = static_cast<std::size_t>(level);
      const auto kept = masks.masked(s.view, levels.gx[l], levels.gy[l], Vec2(levels.crop.x, levels.crop.y), level, 3);
      const auto alone = drawn_alone(s.view, levels, level, 3);
      EXPECT_TRUE(same(kept.mask, alone.mask)) << "level " << level;
      EXPECT_TRUE(same(kept.gx, alone.gx)) << "level " << level;
      EXPECT_TRUE(same(kept.gy, alone.gy)) << "level " << level;
      EXPECT_GT(cv::countNonZero(kept.mask), 0);
    }
  }
  EXPECT_EQ(s.edges->crops_computed(), 1u);
  EXPECT_EQ(masks.drawn(), 3u);  // one per level
}

// Another set of known objects in the same photo is drawn anew, and a view without any in its
// crop keeps the edge images as they are.
TEST(KnownObjectMasks, OtherObjectsAreDrawnAnew) {
  MaskScene s;
  KnownObjectMasks masks;
  const EdgeLevels levels = s.edges->gradients(cv::Rect(150, 200, 500, 200), 1, 2.2, 1.0);
  const Vec2 origin(levels.crop.x, levels.crop.y);
  const auto first = masks.masked(s.view, levels.gx[0], levels.gy[0], origin, 0, 3);
  SilhouetteView moved = s.view;
  moved.occluders = {{{5, 5}, {20, 5}, {20, 20}}};  // far outside the crop
  moved.background_edges.clear();
  const auto second = masks.masked(moved, levels.gx[0], levels.gy[0], origin, 0, 3);
  EXPECT_EQ(masks.drawn(), 2u);
  EXPECT_GT(cv::countNonZero(first.mask), 0);
  EXPECT_EQ(cv::countNonZero(second.mask), 0);
  EXPECT_TRUE(same(second.gx, levels.gx[0]));
  EXPECT_EQ(second.gx.data, levels.gx[0].data);  // not copied
}

}  // namespace
}  // namespace antpose::registration
