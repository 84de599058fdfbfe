#include "antpose/reconstruction/mast_search.hpp"

#include <optional>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "antpose/model/box_file.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::reconstruction {
namespace {

using registration::fixture::SyntheticScene;

struct Inputs {
  std::vector<PosedView> views;
  std::vector<std::vector<std::vector<cv::Point2f>>> occluders;  // the panel, in every photo
};

Inputs inputs(const SyntheticScene& s, const Vec3& size) {
  Inputs in;
  for (const auto& v : s.views) {
    PosedView& p = in.views.emplace_back();
    p.image = v.image, p.R_camera_board = v.R_camera_board, p.t_camera_board = v.t_camera_board;
    std::vector<cv::Point2f> corners, hull;
    for (const Vec3& c : model::box_corners(size)) {
      const auto uv = *s.intrinsics.project(v.R_camera_board * (s.T_board_antenna * c) + v.t_camera_board);
      corners.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
    }
    cv::convexHull(corners, hull);
    in.occluders.push_back({hull});
  }
  return in;
}

// The mast found by its outline in the fixture's scene, and how far (horizontally) its axis lies
// from the pole's.
struct Found {
  SyntheticScene scene;
  std::optional<Mast> mast;
  double axis_offset_m = 0.0;
};

Found find_in(const registration::fixture::SceneSpec& spec) {
  Found f{registration::fixture::make_scene(spec), std::nullopt, 0.0};
  const SyntheticScene& s = f.scene;
  const Vec3 size = model::parametric_panel({}).size_m;
  const Inputs in = inputs(s, size);
  f.mast = find_mast_by_outline(in.views, s.intrinsics, s.mast.up_board, s.T_board_antenna, size, in.occluders, {});
  if (f.mast) {
    const Vec3 d = f.mast->axis_point_board - s.mast.axis_point_board;
    f.axis_offset_m = (d - d.dot(s.mast.up_board) * s.mast.up_board).norm();
  }
  return f;
}

// The fixture's pole stands 0.35 m behind the panel and has no texture at all.
TEST(MastSearch, APlainPoleIsFoundByItsOutlineAlone) {
  const Found f = find_in({});
  ASSERT_TRUE(f.mast);
  EXPECT_LT(f.axis_offset_m, 0.03);
  EXPECT_NEAR(f.mast->radius_m, f.scene.mast.radius_m, 0.01);
}

// A panel high above the board on a short pole (a rooftop mast photographed from a street-level
// board): the pole stands only near the panel, so its outline must be sought at the panel's height.
TEST(MastSearch, AShortPoleFarAboveTheBoardIsFound) {
  registration::fixture::SceneSpec spec;
  spec.antenna_height_m = 7.0, spec.mast_base_m = 4.5;
  const Found f = find_in(spec);
  ASSERT_TRUE(f.mast);
  EXPECT_LT(f.axis_offset_m, 0.03);
}

// A panel hanging with its foot a few decimetres above the roof the photos are taken from (a long
// panel on a short rooftop pole): no stretch of the pole below it lies above the roof, so the pole
// is sought above the panel alone.
registration::fixture::SceneSpec foot_near_the_roof() {
  registration::fixture::SceneSpec spec;
  spec.antenna_height_m = 1.0, spec.below_m = -0.5;  // the foot 0.35 m above the roof, the phone 1.5 m
  return spec;
}

TEST(MastSearch, APoleAboveAPanelWhoseFootNearsTheRoofIsFound) {
  const Found f = find_in(foot_near_the_roof());
  ASSERT_TRUE(f.mast);
  EXPECT_LT(f.axis_offset_m, 0.03);
}

MountSides mount_sides(const SyntheticScene& s, const MastSearchOptions& options = {}) {
  const Vec3 size = model::parametric_panel({}).size_m;
  const Inputs in = inputs(s, size);
  return search_mount_sides(in.views, s.intrinsics, s.mast.up_board, s.T_board_antenna, size, in.occluders, options);
}

double axis_offset(const Mast& found, const Mast& truth) {
  const Vec3 d = found.axis_point_board - truth.axis_point_board;
  return (d - d.dot(truth.up_board) * truth.up_board).norm();
}

TEST(MastSearch, TheStructureBehindThePanelFitsBetterThanAnyBeforeIt) {
  const SyntheticScene s = registration::fixture::make_scene();
  const Inputs in = inputs(s, model::parametric_panel({}).size_m);
  const auto sides = mount_sides(s);
  ASSERT_TRUE(sides.behind && sides.before);
  EXPECT_LT(sides.behind->cost + 0.2, sides.before->cost);
  int better = 0;
  for (std::size_t i = 0; i < in.views.size(); ++i)
    better += sides.behind->view_costs[i] < sides.before->view_costs[i] ? 1 : 0;
  EXPECT_GE(better, static_cast<int>(in.views.size()) - 1);
}

// A pole whose radius and axis lie between the grid's nodes: each side's best cylinder is refined
// onto it, not left at the nearest node (whose outline lies beyond the chamfer's truncation).
TEST(MastSearch, ThePoleBehindIsRefinedBetweenTheGridsNodes) {
  registration::fixture::SceneSpec spec;
  spec.mast_radius_m = 0.17, spec.mast_behind_m = 0.47;
  const SyntheticScene s = registration::fixture::make_scene(spec);
  const auto sides = mount_sides(s);
  ASSERT_TRUE(sides.behind && sides.before);
  EXPECT_LT(axis_offset(sides.behind->cylinder, s.mast), 0.015);
  EXPECT_NEAR(sides.behind->cylinder.radius_m, spec.mast_radius_m, 0.008);
  EXPECT_LT(sides.behind->cost + 0.2, sides.before->cost);
}

TEST(MastSearch, TheMountOfAPanelWhoseFootNearsTheRoofIsBehindIt) {
  const SyntheticScene s = registration::fixture::make_scene(foot_near_the_roof());
  const auto sides = mount_sides(s);
  ASSERT_TRUE(sides.behind && sides.before);
  EXPECT_LT(axis_offset(sides.behind->cylinder, s.mast), 0.03);
  EXPECT_LT(sides.behind->cost + 0.2, sides.before->cost);
}

// A pipe whose foot lies within the panel's height, searched up to the panel's top only: only the
// stretch beside the panel shows it, from the oblique photos (the ends show nothing of it).
TEST(MastSearch, APipeNoLongerThanThePanelIsFoundBesideIt) {
  registration::fixture::SceneSpec spec;
  spec.mast_base_m = spec.antenna_height_m - 0.3, spec.mast_behind_m = 0.5;
  spec.view_offsets_deg = {-40.0, -30.0, -20.0, 0.0, 20.0, 30.0, 40.0};
  const SyntheticScene s = registration::fixture::make_scene(spec);
  MastSearchOptions o;
  o.above_m = 0.01;
  const auto sides = mount_sides(s, o);
  ASSERT_TRUE(sides.behind && sides.before);
  EXPECT_LT(axis_offset(sides.behind->cylinder, s.mast), 0.03);
  EXPECT_LT(sides.behind->cost, sides.before->cost);
}

TEST(MastSearch, ChecksItsOptions) {
  MastSearchOptions o;
  o.step_m = 0.0;
  EXPECT_THROW(find_mast_by_outline({}, {}, Vec3::UnitZ(), Iso3::Identity(), Vec3::Ones(), {}, o),
               std::invalid_argument);
  o = {};
  o.refine_evaluations = -1;
  EXPECT_THROW(search_mount_sides({}, {}, Vec3::UnitZ(), Iso3::Identity(), Vec3::Ones(), {}, o), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::reconstruction
