#include "antpose/registration/shape_fit.hpp"

#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SceneSpec;

SilhouetteOptions polish() {
  SilhouetteOptions o;
  o.max_level = 0;
  o.search_range_px = o.fine_search_px;
  o.rival_yaw_offsets_rad.clear();
  return o;
}

// A panel whose vertical edges are rounder (45 mm) than its datasheet model's (20 mm), seen over
// 30° from 15° off its front: fitted with the model's rounding the yaw makes up for it.
TEST(EdgeRadius, TheRadomesRoundingIsFittedAndTheYawWithIt) {
  SceneSpec spec;
  spec.panel.edge_radius_m = 0.045;
  spec.view_offsets_deg = {0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0};
  const auto s = make_scene(spec);
  const auto model = model::parametric_panel({});  // 20 mm
  ASSERT_TRUE(model.panel);
  auto o = polish();
  o.outline_box_m = model.size_m;
  const auto as_modelled = refine_by_silhouette(model.mesh_antenna, s.T_board_antenna, s.views, s.intrinsics, o);
  const auto fit = fit_edge_radius(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {});
  ASSERT_TRUE(fit.fitted);
  EXPECT_NEAR(fit.radius_m, 0.045, 0.006);
  EXPECT_LT(fit.outline.score, as_modelled.score);
  const double error = rad2deg(rotation_distance(fit.outline.T_board_antenna.linear(), s.T_board_antenna.linear()));
  const double modelled_error =
      rad2deg(rotation_distance(as_modelled.T_board_antenna.linear(), s.T_board_antenna.linear()));
  std::printf("radius %.3f m, error %.2f°; with the model's rounding %.2f°\n", fit.radius_m, error, modelled_error);
  EXPECT_LT(error, 1.0);
  EXPECT_LT(3 * error, modelled_error);
  // The radii the photos do not rule out include the best, and their spread is the σ's share.
  EXPECT_NE(std::find(fit.within_m.begin(), fit.within_m.end(), fit.radius_m), fit.within_m.end());
  EXPECT_GE(fit.spread_board.trace(), 0.0);
}

TEST(EdgeRadius, AMeshFromAFileKeepsItsShape) {
  const auto s = make_scene();
  auto model = model::parametric_panel({});
  model.panel.reset();  // as a scanned mesh: its shape is measured, not a guess
  EXPECT_FALSE(fit_edge_radius(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {}).fitted);
  EdgeRadiusOptions off;
  off.enabled = false;
  EXPECT_FALSE(
      fit_edge_radius(model::parametric_panel({}), s.T_board_antenna, s.views, s.intrinsics, polish(), {}, off).fitted);
}

}  // namespace
}  // namespace antpose::registration
