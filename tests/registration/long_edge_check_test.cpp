#include "antpose/registration/long_edge_check.hpp"

#include <cstdio>

#include <gtest/gtest.h>

#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SceneSpec;

SilhouetteOptions polish(const model::AntennaModel& model) {
  SilhouetteOptions o;
  o.max_level = 0;
  o.search_range_px = o.fine_search_px;
  o.rival_yaw_offsets_rad.clear();
  o.outline_box_m = model.size_m;
  return o;
}

// The rounded panel (30 mm) seen from its front and right (+x) side over 30°, as the model is, or
// with its front-left (−x+y) long edge, an outline in every photo, rounded by `radius_m` instead:
// an outline that edge shows inside the model's, by an amount that changes with the view, as a
// shading edge fixed on the rounding (before a background of the rounding's own brightness) does.
struct Case {
  model::PanelSpec spec = [] {
    model::PanelSpec spec;
    spec.edge_radius_m = 0.03;
    return spec;
  }();
  model::AntennaModel model = model::parametric_panel(spec);
  fixture::SyntheticScene scene;
  SilhouetteResult whole;
  std::vector<LongEdgeLeftOut> left_out;

  explicit Case(double radius_m) {
    SceneSpec scene_spec;
    scene_spec.panel = spec;
    scene_spec.view_offsets_deg = {0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0};
    if (radius_m != spec.edge_radius_m) {
      auto rounder = spec;
      rounder.edge_radius_m = radius_m;
      const auto other = model::parametric_panel(rounder).mesh_antenna;  // the same vertices, moved
      scene_spec.rendered = model.mesh_antenna;
      const Vec3 half = model.size_m / 2;
      for (std::size_t i = 0; i < other.vertices.size(); ++i)
        if (other.vertices[i].x() < -(half.x() - radius_m - 1e-6) && other.vertices[i].y() > half.y() - radius_m - 1e-6)
          scene_spec.rendered.vertices[i] = other.vertices[i];
    }
    scene = make_scene(scene_spec);
    whole =
        refine_by_silhouette(model.mesh_antenna, scene.T_board_antenna, scene.views, scene.intrinsics, polish(model));
    left_out =
        check_long_edges(model.mesh_antenna, whole.T_board_antenna, scene.views, scene.intrinsics, polish(model), {});
    for (const auto& e : left_out)
      std::printf("%s: turn %.2f°, distance %.1f\n", long_edge_name(e.edge).c_str(), rad2deg(e.turn_rad), e.distance);
  }
  double error_deg(const Iso3& T) const {
    return rad2deg(rotation_distance(T.linear(), scene.T_board_antenna.linear()));
  }
};

TEST(LongEdgeCheck, AnOutlineWhoseEdgesAgreeKeepsItsPose) {
  const Case c(0.03);
  ASSERT_GE(c.left_out.size(), 2u);
  for (const auto& e : c.left_out) {
    EXPECT_FALSE(e.disagrees) << long_edge_name(e.edge);
    EXPECT_LT(e.distance, LongEdgeCheckOptions{}.max_distance);
  }
}

// The whole outline's pose turns to fit the rounder edge. Left out, that edge gives a pose near
// the truth, beyond both poses' σ; the other edges, left out, move the pose within them.
TEST(LongEdgeCheck, AnEdgeThatDecidesThePoseAgainstTheOthersIsFound) {
  const Case c(0.07);
  const double whole = c.error_deg(c.whole.T_board_antenna);
  std::printf("whole outline: %.2f° from the truth\n", whole);
  ASSERT_GT(whole, 1.0);
  int disagreeing = 0;
  for (const auto& e : c.left_out) {
    if (!e.disagrees) continue;
    ++disagreeing;
    EXPECT_EQ(long_edge_name(e.edge), "-x+y");
    EXPECT_LT(c.error_deg(e.T_board_antenna), 0.5 * whole);
    EXPECT_GT(rad2deg(e.turn_rad), 0.8 * whole);  // the σ it widens covers the error
  }
  EXPECT_EQ(disagreeing, 1);
}

// Only an edge that disagrees and turns the pose as far as a rival stands leaves a second pose.
TEST(LongEdgeCheck, AnEdgeThatTurnsThePoseAsFarAsARivalLeavesAnotherPose) {
  const double rival = deg2rad(10.0);
  LongEdgeLeftOut agrees, near, far;
  agrees.turn_rad = deg2rad(20.0);  // loosely held without it, but within both σ
  near.disagrees = far.disagrees = true;
  near.turn_rad = deg2rad(4.0), far.turn_rad = deg2rad(20.0);
  EXPECT_FALSE(leaves_another_pose({}, rival));
  EXPECT_FALSE(leaves_another_pose({agrees, near}, rival));
  EXPECT_TRUE(leaves_another_pose({agrees, near, far}, rival));
  EXPECT_FALSE(leaves_another_pose({far}, deg2rad(25.0)));
}

TEST(LongEdgeCheck, LongEdgesAreNamedByTheFacesThatMeetThere) {
  EXPECT_EQ(long_edge_of(Vec3(0.1, 0.05, -0.5), Vec3(0.1, 0.05, 0.5)), 3);
  EXPECT_EQ(long_edge_of(Vec3(-0.1, 0.05, 0.5), Vec3(-0.1, 0.05, -0.5)), 2);
  EXPECT_EQ(long_edge_of(Vec3(0.1, -0.05, -0.5), Vec3(0.1, -0.05, 0.5)), 1);
  EXPECT_EQ(long_edge_of(Vec3(-0.1, -0.05, -0.5), Vec3(-0.1, -0.05, 0.5)), 0);
  EXPECT_FALSE(long_edge_of(Vec3(-0.1, 0.05, 0.5), Vec3(0.1, 0.05, 0.5)));  // an end's edge
  EXPECT_FALSE(long_edge_of(Vec3::Zero(), Vec3::Zero()));
  EXPECT_EQ(long_edge_name(0), "-x-y");
  EXPECT_EQ(long_edge_name(3), "+x+y");
}

TEST(LongEdgeCheck, OptionsSayWhatIsWrongWithThem) {
  LongEdgeCheckOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.max_distance = 0;
  o.min_views = 0;
  const auto problems = o.Check();
  EXPECT_FALSE(problems.ok());
  EXPECT_NE(problems.message().find("max_distance"), std::string::npos);
  EXPECT_NE(problems.message().find("min_views"), std::string::npos);
}

}  // namespace
}  // namespace antpose::registration
