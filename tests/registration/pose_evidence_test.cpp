#include "antpose/registration/pose_evidence.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/model/sampling.hpp"
#include "antpose/registration/pose_selection.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SyntheticScene;

PoseEvidence with_outline(std::vector<double> outline) {
  PoseEvidence e;
  e.outline = std::move(outline);
  return e;
}

TEST(PoseEvidence, ADifferenceThePhotosAgreeOnIsDecisive) {
  const EvidenceOptions o;
  const auto better = with_outline({0.10, 0.12, 0.09, 0.11, 0.10, 0.13, 0.12, 0.10});
  const auto worse = with_outline({0.18, 0.19, 0.17, 0.20, 0.18, 0.21, 0.19, 0.18});
  const Comparison c = compare_shape(better, worse, o);
  EXPECT_NEAR(c.difference, 0.07875, 1e-9);
  EXPECT_EQ(c.units, 8u);
  EXPECT_TRUE(c.decisive);
}

// Where the photos' outline errors are common to them all, they are one unit: a difference is
// weighed against their scatter, and one that only the number of photos made decisive is not.
TEST(PoseEvidence, WithCommonOutlineErrorsThePhotosAreOneUnit) {
  EvidenceOptions o;
  const auto better = with_outline({0.10, 0.12, 0.09, 0.11, 0.10, 0.13, 0.12, 0.10});
  const auto worse = with_outline({0.12, 0.22, 0.11, 0.19, 0.10, 0.20, 0.17, 0.14});
  const Comparison independent = compare_shape(better, worse, o);
  EXPECT_TRUE(independent.decisive);
  o.outline_errors_common = true;
  const Comparison common = compare_shape(better, worse, o);
  EXPECT_DOUBLE_EQ(common.difference, independent.difference);
  EXPECT_NEAR(common.standard_error, std::sqrt(8.0) * independent.standard_error, 1e-12);
  EXPECT_FALSE(common.decisive);
  auto placed = [](PoseEvidence e) {
    e.placement = e.outline;
    return e;
  };
  o.outline_errors_common = false;
  EXPECT_TRUE(compare_placement(placed(better), placed(worse), o).decisive);
  o.outline_errors_common = true;
  EXPECT_FALSE(compare_placement(placed(better), placed(worse), o).decisive) << "the placement is the photos' too";
  // A difference far beyond the photos' scatter still decides.
  EXPECT_TRUE(compare_shape(better, with_outline({0.60, 0.63, 0.58, 0.62, 0.61, 0.64, 0.62, 0.60}), o).decisive);
}

TEST(PoseEvidence, ADifferenceOnePhotoMakesIsNot) {
  const EvidenceOptions o;
  // The same mean difference, all of it from one photo (a clutter edge there).
  const auto better = with_outline({0.10, 0.12, 0.09, 0.11, 0.10, 0.13, 0.12, 0.10});
  auto one = better.outline;
  one[3] += 0.65;
  const Comparison c = compare_shape(better, with_outline(one), o);
  EXPECT_NEAR(c.difference, 0.08125, 1e-9);
  EXPECT_FALSE(c.decisive);
  // And a tie is never decisive, however consistent.
  auto tie = better.outline;
  for (double& v : tie) v += 0.005;
  EXPECT_FALSE(compare_shape(better, with_outline(tie), o).decisive);
}

TEST(PoseEvidence, UnitsEitherPoseLacksDoNotEnter) {
  const EvidenceOptions o;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Comparison c = compare_shape(with_outline({0.1, nan, 0.1}), with_outline({0.3, 0.3, nan}), o);
  EXPECT_EQ(c.units, 1u);
  EXPECT_FALSE(c.decisive) << "one unit alone cannot be decisive";
}

// The fixture's panel with points on what the cameras see of it, 5 mm noise.
PointCloud seen_points(const SyntheticScene& s) {
  const auto model = model::parametric_panel({});
  std::vector<Vec3> viewpoints_antenna;
  const Iso3 T_antenna_board = s.T_board_antenna.inverse();
  for (const auto& v : s.views)
    viewpoints_antenna.push_back(T_antenna_board * camera::camera_centre(v.R_camera_board, v.t_camera_board));
  PointCloud cloud =
      transformed(model::visible_surface(model.mesh_antenna, viewpoints_antenna, 0.02, 5), s.T_board_antenna);
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0.0, 0.005);
  for (Vec3& p : cloud.points) p += Vec3(n(rng), n(rng), n(rng));
  return cloud;
}

TEST(PoseEvidence, TheTruePoseBeatsAnotherYawDecisively) {
  const SyntheticScene s = make_scene();
  const auto model = model::parametric_panel({});
  const PointCloud points = seen_points(s);
  EvidenceScene scene{&s.views, s.intrinsics, &points, {}, s.mast.up_board};
  for (const auto& v : s.views)
    scene.viewpoints_board.push_back(camera::camera_centre(v.R_camera_board, v.t_camera_board));
  const EvidenceJudge judge(model, scene, {});
  const PoseEvidence truth = judge(s.T_board_antenna);
  Iso3 yawed = s.T_board_antenna;
  yawed.linear() = Eigen::AngleAxisd(deg2rad(25.0), s.T_board_antenna.linear().col(2)) * yawed.linear();
  const PoseEvidence other = judge(yawed);
  EXPECT_LT(truth.score(judge.options()), other.score(judge.options()));
  EXPECT_TRUE(compare_shape(truth, other, judge.options()).decisive);
  // Turned round, the box's outline is the same: the shape units barely differ.
  const PoseEvidence turned = judge(turned_round(s.T_board_antenna));
  EXPECT_FALSE(compare_shape(truth, turned, judge.options()).decisive);
}

// Where one long side of the panel is as bright as what lies behind it, that stretch of its
// outline has no edge: the outline's cost counts its samples as misses, the placement leaves them
// out and stays what it was.
TEST(PoseEvidence, AFaintStretchOfOutlineCostsButDoesNotMisplace) {
  const SyntheticScene s = make_scene();
  const auto model = model::parametric_panel({});
  SilhouetteOptions o;
  o.outline_box_m = model.size_m;
  const auto seen = evaluate_outline(model.mesh_antenna, s.T_board_antenna, s.views, s.intrinsics, o);
  std::vector<SilhouetteView> faint = s.views;
  for (auto& v : faint) {
    const auto centre = s.intrinsics.project(v.R_camera_board * s.T_board_antenna.translation() + v.t_camera_board);
    ASSERT_TRUE(centre);
    v.image = v.image.clone();
    const int from = static_cast<int>(centre->x());
    v.image.colRange(from, v.image.cols).setTo(128);  // the panel's right half and its background alike
  }
  const auto half = evaluate_outline(model.mesh_antenna, s.T_board_antenna, faint, s.intrinsics, o);
  ASSERT_EQ(half.cost.size(), seen.cost.size());
  for (std::size_t i = 0; i < seen.cost.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_LT(seen.placement[i], 0.1);
    EXPECT_GT(half.cost[i], seen.cost[i] + 0.25) << "the faint side's samples are misses";
    EXPECT_LT(half.placement[i], seen.placement[i] + 0.05) << "the edges it meets lie where they did";
  }
}

}  // namespace
}  // namespace antpose::registration
