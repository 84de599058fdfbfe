#include "antpose/registration/outline_search.hpp"

#include <gtest/gtest.h>

#include "antpose/model/box_file.hpp"
#include "antpose/registration/pose_selection.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SyntheticScene;

// The box's orientation error, its half-turn about the long axis allowed (the outline's symmetry).
double box_error_deg(const Mat3& R, const Mat3& R_true) { return rad2deg(box_angle(R, R_true)); }

// The projected box's bounding rectangle in a view, widened by `margin` of its size (a user's).
cv::Rect rectangle_around(const SyntheticScene& s, std::size_t view, const Vec3& size, double margin) {
  Eigen::AlignedBox2d box;
  for (const Vec3& c : model::box_corners(size))
    box.extend(
        *s.intrinsics.project(s.views[view].R_camera_board * (s.T_board_antenna * c) + s.views[view].t_camera_board));
  const Vec2 grow = margin * box.sizes();
  return {static_cast<int>(box.min().x() - grow.x()), static_cast<int>(box.min().y() - grow.y()),
          static_cast<int>(box.sizes().x() + 2 * grow.x()), static_cast<int>(box.sizes().y() + 2 * grow.y())};
}

OutlineSearchInput input_for(const SyntheticScene& s, const Vec3& size, const Vec3& start) {
  OutlineSearchInput in;
  in.box_size_m = size;
  in.views = &s.views;
  for (std::size_t v = 0; v < s.views.size(); ++v) {
    const cv::Rect r = rectangle_around(s, v, size, 0.3);
    in.areas.emplace_back(r);
  }
  in.region_view = 3;
  in.expected_width_px = rectangle_around(s, 3, size, 0.0).width;
  in.up_board = s.mast.up_board;
  in.starts_board = {start};
  return in;
}

TEST(OutlineSearch, FindsThePanelFromAFarStartWithoutTexture) {
  const SyntheticScene s = make_scene();
  const Vec3 size = model::parametric_panel({}).size_m;
  // A start 0.25 m off the panel's centre, as a rectangle's depth guess may be.
  const Vec3 start = s.T_board_antenna.translation() + Vec3(0.15, -0.1, 0.17);
  const auto result = search_box_outline(input_for(s, size, start), s.intrinsics, {});
  ASSERT_FALSE(result.candidates.empty());
  const auto& best = result.candidates.front();
  EXPECT_LT(box_error_deg(best.T_board_antenna.linear(), s.T_board_antenna.linear()), 6.0);
  EXPECT_LT((best.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.06);
  EXPECT_EQ(best.views, s.views.size());
  EXPECT_LT(best.cost, 0.3);
  // The rest lie elsewhere or at other orientations, and fit worse.
  for (std::size_t k = 1; k < result.candidates.size(); ++k) EXPECT_GE(result.candidates[k].cost, best.cost);
}

// With no start but the user's rectangle: drawn tight or with wide margins (the box filling from
// all of it down to three fifths of its larger side), the box is found at the depth that fills it.
TEST(OutlineSearch, FindsThePanelFromTheRectangleHoweverItIsDrawn) {
  const SyntheticScene s = make_scene();
  const Vec3 size = model::parametric_panel({}).size_m;
  for (const double margin : {0.0, 0.12, 0.3}) {
    SCOPED_TRACE(margin);
    OutlineSearchInput in = input_for(s, size, Vec3::Zero());
    in.starts_board.clear();
    in.roi = rectangle_around(s, in.region_view, size, margin);
    const auto result = search_box_outline(in, s.intrinsics, {});
    ASSERT_FALSE(result.candidates.empty());
    const auto& best = result.candidates.front();
    EXPECT_LT(box_error_deg(best.T_board_antenna.linear(), s.T_board_antenna.linear()), 6.0);
    EXPECT_LT((best.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.06);
    EXPECT_LT(best.cost, 0.3);
  }
}

// A thin panel in a loose rectangle, its margins a share of the panel's length as a user draws
// them: it fills a quarter of the rectangle's area but spans most of its larger side, and fits;
// a box beside it, or one a third as long, does not.
TEST(OutlineSearch, TakesTheRectangleByItsLargerSide) {
  const auto box = [](double x0, double y0, double x1, double y1) {
    return Eigen::AlignedBox2d(Vec2(x0, y0), Vec2(x1, y1));
  };
  const Eigen::AlignedBox2d panel = box(100, 100, 550, 160);  // 450 × 60 px
  const double m = 0.15 * 450;
  const cv::Rect roi(static_cast<int>(100 - m), static_cast<int>(100 - m), static_cast<int>(450 + 2 * m),
                     static_cast<int>(60 + 2 * m));
  const auto fit = rectangle_fit(panel, roi);
  EXPECT_TRUE(fit.centred);
  EXPECT_NEAR(fit.span, 450.0 / roi.width, 0.01);
  EXPECT_LT(panel.volume() / (roi.width * roi.height), 0.3);
  EXPECT_GT(fit.span, OutlineSearchInput{}.min_roi_span);
  // Beside it: half of it in the rectangle, its centre out.
  EXPECT_FALSE(rectangle_fit(box(100, 180, 550, 380), roi).centred);
  EXPECT_LT(rectangle_fit(box(250, 100, 400, 160), roi).span, OutlineSearchInput{}.min_roi_span);
  // A tall rectangle is taken along its height; a box outside it spans nothing.
  const cv::Rect tall(0, 0, 100, 400);
  EXPECT_NEAR(rectangle_fit(box(40, 50, 60, 350), tall).span, 0.75, 0.01);
  const auto outside = rectangle_fit(box(500, 500, 600, 600), tall);
  EXPECT_EQ(outside.span, 0.0);
  EXPECT_FALSE(outside.centred);
}

// A pose proposed by its orientation, its centre a panel's depth and more off (a turn about another
// orientation's centre): placed by the outline, the box lands on the panel; a start placed where
// the panel is stays there.
TEST(OutlineSearch, PlacesProposedOrientationsOnThePanel) {
  const SyntheticScene s = make_scene();
  const Vec3 size = model::parametric_panel({}).size_m;
  const Vec3 off = s.T_board_antenna.linear() * Vec3(0.09, -0.08, 0.04);
  Iso3 far = s.T_board_antenna, there = s.T_board_antenna;
  far.translation() += off;
  const OutlineSearchInput in = input_for(s, size, Vec3::Zero());
  const auto placed = place_box_outlines(in, s.intrinsics, {}, {far, there});
  ASSERT_EQ(placed.candidates.size(), 2u);
  for (const auto& c : placed.candidates) {
    EXPECT_LT(box_error_deg(c.T_board_antenna.linear(), s.T_board_antenna.linear()), 3.0);
    EXPECT_LT((c.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.03);
    EXPECT_EQ(c.views, s.views.size());
    EXPECT_LT(c.cost, 0.3);
  }
  EXPECT_GT(off.norm(), 0.12);
  EXPECT_TRUE(place_box_outlines(in, s.intrinsics, {}, {}).candidates.empty());
}

TEST(OutlineSearch, ChecksItsOptionsAndInputs) {
  OutlineSearchOptions o;
  o.yaw_step_deg = 0;
  o.tilt_deg.clear();
  EXPECT_FALSE(o.Check().ok());
  EXPECT_NE(o.Check().message().find("yaw_step_deg"), std::string::npos);
  const SyntheticScene s = make_scene();
  OutlineSearchInput in = input_for(s, Vec3(0.3, 0.16, 1.31), s.T_board_antenna.translation());
  in.region_view = 99;
  EXPECT_THROW(search_box_outline(in, s.intrinsics, {}), std::invalid_argument);
  in.region_view = 3;
  in.roi = rectangle_around(s, 3, Vec3(0.3, 0.16, 1.31), 0.1);
  in.min_roi_span = 0;  // would sweep the depth for ever
  EXPECT_THROW(search_box_outline(in, s.intrinsics, {}), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::registration
