#include "antpose/registration/shape_fit.hpp"

#include <algorithm>
#include <cmath>
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
// 30° from 15° off its front.
fixture::SyntheticScene rounder_panel() {
  SceneSpec spec;
  spec.panel.edge_radius_m = 0.045;
  spec.view_offsets_deg = {0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0};
  return make_scene(spec);
}

// Fitted with the model's rounding the yaw makes up for it.
TEST(ShapeFit, TheRadomesRoundingIsFittedAndTheYawWithIt) {
  const auto s = rounder_panel();
  const auto model = model::parametric_panel({});  // 20 mm
  ASSERT_TRUE(model.panel);
  auto o = polish();
  o.outline_box_m = model.size_m;
  const auto as_modelled = refine_by_silhouette(model.mesh_antenna, s.T_board_antenna, s.views, s.intrinsics, o);
  const auto fit = fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {});
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
  ASSERT_FALSE(fit.within.empty());
  EXPECT_TRUE(std::any_of(fit.within.begin(), fit.within.end(),
                          [&](std::size_t k) { return fit.radii_m[k] == fit.radius_m && fit.rims_m[k] == fit.rim_m; }));
  EXPECT_GE(fit.spread_board.trace(), 0.0);
  // The spread weighs the shapes not ruled out by their likelihood against the best's: 1 for the
  // best, no less than at the paired test's bound for those not ruled out, less for the rest, and
  // falling away from the best along its rim's radii (the profile has one peak).
  const EvidenceOptions evidence;
  const double bound = std::exp(-0.5 * evidence.decisive_z * evidence.decisive_z);
  ASSERT_EQ(fit.likelihoods.size(), fit.radii_m.size());
  std::vector<std::pair<double, double>> best_rim;  // (radius, likelihood)
  for (std::size_t k = 0; k < fit.likelihoods.size(); ++k) {
    const bool in = std::find(fit.within.begin(), fit.within.end(), k) != fit.within.end();
    if (fit.radii_m[k] == fit.radius_m && fit.rims_m[k] == fit.rim_m) {
      EXPECT_EQ(fit.likelihoods[k], 1.0);
    }
    EXPECT_EQ(in, fit.likelihoods[k] >= bound * (1 - 1e-12)) << k;
    if (fit.rims_m[k] == fit.rim_m) best_rim.emplace_back(fit.radii_m[k], fit.likelihoods[k]);
  }
  std::sort(best_rim.begin(), best_rim.end());
  for (std::size_t i = 1; i < best_rim.size(); ++i) {
    if (best_rim[i].first <= fit.radius_m) {
      EXPECT_LT(best_rim[i - 1].second, best_rim[i].second) << best_rim[i].first;
    } else {
      EXPECT_GT(best_rim[i - 1].second, best_rim[i].second) << best_rim[i].first;
    }
  }
}

// The profile's spread carried to another refinement of the answer: refined as the profile was
// from the best shape's pose, each shape lands where the profile put it and the spread is the
// profile's; a panel not profiled has none.
TEST(ShapeFit, TheShapesSpreadRefinedAsTheProfileWasIsTheProfiles) {
  const auto s = rounder_panel();
  const auto model = model::parametric_panel({});
  const auto fit = fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {});
  ASSERT_TRUE(fit.fitted);
  ASSERT_GE(fit.within.size(), 2u);
  const Mat3 spread =
      spread_of_shapes(fit, fit.model, fit.outline.T_board_antenna, s.views, s.intrinsics, polish(), {});
  std::printf("spread %.3f°, the profile's %.3f° (root of the traces)\n", rad2deg(std::sqrt(spread.trace())),
              rad2deg(std::sqrt(fit.spread_board.trace())));
  EXPECT_NEAR(std::sqrt(spread.trace()), std::sqrt(fit.spread_board.trace()),
              0.25 * std::sqrt(fit.spread_board.trace()) + deg2rad(0.01));
  ShapeFit none;
  EXPECT_TRUE(spread_of_shapes(none, model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}).isZero());
}

// A short panel with end caps standing 8 mm out of its radome, seen from well below over a
// narrow arc: its downtilt is read from where its ends lie, which the caps move. Fitted without
// caps the downtilt makes up for them; with the caps' rim profiled it does not.
TEST(ShapeFit, TheEndCapsRimIsFittedAndTheDowntiltWithIt) {
  SceneSpec spec;
  spec.panel.height_m = 0.7, spec.panel.width_m = 0.4, spec.panel.depth_m = 0.18;
  spec.panel.end_cap_height_m = 0.04, spec.panel.end_cap_rim_m = 0.008;
  spec.antenna_height_m = 5.0, spec.distance_m = 4.0, spec.below_m = 3.5, spec.focal_px = 1400;
  spec.view_offsets_deg = {-6.0, -3.0, 0.0, 3.0, 6.0};
  const auto s = make_scene(spec);
  auto datasheet = spec.panel;
  datasheet.end_cap_height_m = datasheet.end_cap_rim_m = 0;
  const auto model = model::parametric_panel(datasheet);
  ShapeOptions no_caps;
  no_caps.rim_steps = 0;
  const auto without = fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, no_caps);
  const auto fit = fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {});
  ASSERT_TRUE(fit.fitted && without.fitted);
  EXPECT_NEAR(fit.rim_m, 0.008, 0.003);
  EXPECT_LT(fit.outline.score, without.outline.score);
  const auto error = [&](const ShapeFit& f) {
    return rad2deg(rotation_distance(f.outline.T_board_antenna.linear(), s.T_board_antenna.linear()));
  };
  std::printf("rim %.4f m, radius %.4f m, error %.2f°; without caps %.2f° (radius %.4f m)\n", fit.rim_m, fit.radius_m,
              error(fit), error(without), without.radius_m);
  EXPECT_LT(error(fit), 0.3);
  EXPECT_LT(2 * error(fit), error(without));
}

// A radome whose edges show further inside than the roundest model's outline (here one rounder
// than the range, as shading on a pale rounded radome shows): the profile presses against the
// largest radius, is not bracketed, and weighs the shapes against the photos' scatter, not their
// mean's standard error: more shapes stay within, and their poses' spread covers the error of the
// best one.
TEST(ShapeFit, EdgesFurtherInsideThanAnyRoundingLeaveTheShapeOpen) {
  SceneSpec spec;
  spec.panel.edge_radius_m = 0.075;
  spec.view_offsets_deg = {0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0};
  const auto s = make_scene(spec);
  const auto model = model::parametric_panel({});
  const auto fit = fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {});
  ASSERT_TRUE(fit.fitted);
  EXPECT_FALSE(fit.bracketed);
  EXPECT_DOUBLE_EQ(fit.radius_m, 0.06);
  const Vec3 error = log_so3(fit.outline.T_board_antenna.linear() * s.T_board_antenna.linear().transpose());
  const double sigma = std::sqrt(fit.spread_board.trace());
  std::printf("within %zu of %zu shapes, spread %.2f°, error of the best %.2f°\n", fit.within.size(),
              fit.radii_m.size(), rad2deg(sigma), rad2deg(error.norm()));
  EXPECT_EQ(fit.within.size(), fit.radii_m.size());  // against the photos' scatter none is ruled out here
  EXPECT_LT(error.norm(), 3 * sigma);

  SceneSpec round;  // the panel the model describes, its edges rounded within the range: bracketed
  round.panel.edge_radius_m = 0.03;
  round.view_offsets_deg = spec.view_offsets_deg;
  const auto r = make_scene(round);
  EXPECT_TRUE(fit_shape(model, r.T_board_antenna, r.views, r.intrinsics, polish(), {}, {}).bracketed);
}

TEST(ShapeFit, AMeshFromAFileKeepsItsShape) {
  const auto s = make_scene();
  auto model = model::parametric_panel({});
  model.panel.reset();  // as a scanned mesh: its shape is measured, not a guess
  EXPECT_FALSE(fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, {}).fitted);
  ShapeOptions off;
  off.enabled = false;
  ShapeOptions bad;
  bad.rim_steps = 1;
  EXPECT_THROW(fit_shape(model, s.T_board_antenna, s.views, s.intrinsics, polish(), {}, bad), std::invalid_argument);
  EXPECT_FALSE(
      fit_shape(model::parametric_panel({}), s.T_board_antenna, s.views, s.intrinsics, polish(), {}, off).fitted);
}

}  // namespace
}  // namespace antpose::registration
