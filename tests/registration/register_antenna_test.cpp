#include "antpose/registration/register_antenna.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/model/box_file.hpp"
#include "antpose/model/sampling.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SyntheticScene;

// What the reconstruction would give: points on the panel's faces the cameras see and on the
// mast and arms behind it (where the fixture's mast stands), 5 mm noise.
PointCloud region_points(const SyntheticScene& s, const model::PanelSpec& panel) {
  const auto model = model::parametric_panel(panel);
  const Iso3 T_antenna_board = s.T_board_antenna.inverse();
  std::vector<Vec3> viewpoints;
  for (const auto& v : s.views)
    viewpoints.push_back(T_antenna_board * camera::camera_centre(v.R_camera_board, v.t_camera_board));
  PointCloud cloud = transformed(model::visible_surface(model.mesh_antenna, viewpoints, 0.02, 5), s.T_board_antenna);
  const Vec3 up = s.mast.up_board.normalized(), side = up.unitOrthogonal(), other = up.cross(side);
  for (double h = -0.8; h <= 0.8; h += 0.02)
    for (int k = 0; k < 12; ++k) {
      const double a = 2 * M_PI * k / 12;
      cloud.points.push_back(s.mast.axis_point_board + h * up +
                             s.mast.radius_m * (std::cos(a) * side + std::sin(a) * other));
    }
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 0.005);
  for (Vec3& p : cloud.points) p += Vec3(n(rng), n(rng), n(rng));
  return cloud;
}

AntennaScene antenna_scene(const SyntheticScene& s, const model::PanelSpec& panel = {}) {
  AntennaScene a;
  a.views = s.views;
  a.intrinsics = s.intrinsics;
  for (const auto& v : s.views) a.viewpoints_board.push_back(camera::camera_centre(v.R_camera_board, v.t_camera_board));
  a.up_board = s.mast.up_board;
  a.points_board = region_points(s, panel);
  a.region_view = 3;
  const Vec3 size = model::parametric_panel(panel).size_m;
  for (std::size_t v = 0; v < s.views.size(); ++v) {
    Eigen::AlignedBox2d box;
    for (const Vec3& c : model::box_corners(size))
      box.extend(
          *s.intrinsics.project(s.views[v].R_camera_board * (s.T_board_antenna * c) + s.views[v].t_camera_board));
    const cv::Rect r(static_cast<int>(box.min().x()) - 12, static_cast<int>(box.min().y()) - 12,
                     static_cast<int>(box.sizes().x()) + 24, static_cast<int>(box.sizes().y()) + 24);
    if (v == a.region_view) a.roi = r;
    a.areas.emplace_back(cv::Rect(r.x - r.width / 4, r.y - r.height / 4, r.width * 3 / 2, r.height * 3 / 2));
  }
  return a;
}

// The same with the mast known beside the panel.
AntennaScene antenna_scene_with_mast(const SyntheticScene& s, const model::PanelSpec& panel = {}) {
  AntennaScene a = antenna_scene(s, panel);
  a.mast = s.mast;
  return a;
}

TEST(RegisterAntenna, FindsThePanelAndItsFrontWithTheMastKnown) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene_with_mast(s);
  const auto r = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_TRUE(r.found) << r.why_not;
  EXPECT_LT(rad2deg(rotation_distance(r.T_board_antenna.linear(), s.T_board_antenna.linear())), 1.0);
  EXPECT_LT((r.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.02);
  EXPECT_EQ(r.verdict, RegistrationVerdict::kUnique);
  EXPECT_EQ(r.selection.front_back_cue, FrontBackCue::kMast);
  EXPECT_GE(r.proposed, 2u);
}

TEST(RegisterAntenna, WithoutAMastTheMountsPointsDecideFrontAndBack) {
  const SyntheticScene s = make_scene();
  const auto r = register_antenna(model::parametric_panel({}), antenna_scene(s), {});
  ASSERT_TRUE(r.found) << r.why_not;
  EXPECT_LT(rad2deg(boresight_angle(r.T_board_antenna.linear(), s.T_board_antenna.linear())), 1.0);
  EXPECT_EQ(r.selection.front_back_cue, FrontBackCue::kEvidence);
}

TEST(RegisterAntenna, ARectangleOnTheSkyFindsNothingAndSaysWhy) {
  const SyntheticScene s = make_scene();
  AntennaScene scene = antenna_scene(s);
  scene.roi = cv::Rect(20, 20, 120, 300);  // the top left corner: sky and ground, no antenna
  for (auto& a : scene.areas) a = cv::Rect(0, 0, 200, 400);
  scene.points_board.points.clear();
  const auto r = register_antenna(model::parametric_panel({}), scene, {});
  EXPECT_FALSE(r.found);
  EXPECT_NE(r.why_not.find("rectangle"), std::string::npos) << r.why_not;
}

// A second registration in a scene that knows more (here the mast) starts from the first's
// candidates: those whose rounding was profiled keep that profile, and the answer stays.
TEST(RegisterAntenna, ASecondRegistrationKeepsTheProfiledRounding) {
  const SyntheticScene s = make_scene();
  AntennaScene scene = antenna_scene(s);
  const auto first = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_TRUE(first.found) << first.why_not;
  ASSERT_TRUE(first.panel_shape && first.panel_shape->fitted);
  const auto profiled = std::count_if(first.candidates.begin(), first.candidates.end(),
                                      [](const PoseCandidate& c) { return c.panel_shape != nullptr; });
  EXPECT_GE(profiled, 1);
  scene.mast = s.mast;
  RegisterOptions again;
  again.turns.of_best = 0;  // the first registration's turns are among its candidates
  const auto second = register_antenna(model::parametric_panel({}), scene, again, first.candidates);
  ASSERT_TRUE(second.found) << second.why_not;
  ASSERT_TRUE(second.panel_shape);
  EXPECT_EQ(second.panel_shape->radius_m, first.panel_shape->radius_m);
  EXPECT_EQ(second.panel_shape->scores, first.panel_shape->scores) << "the profile is the first's";
  EXPECT_LT(rad2deg(rotation_distance(second.T_board_antenna.linear(), s.T_board_antenna.linear())), 1.0);
  EXPECT_NEAR(second.rotation_covariance_board().trace(), first.rotation_covariance_board().trace(),
              0.5 * first.rotation_covariance_board().trace());
  // The covariance by its sources: the outline's parts and the profiled shape's spread.
  std::vector<std::string> sources;
  for (const auto& part : second.rotation_covariance_sources) sources.push_back(part.source);
  EXPECT_EQ(sources, (std::vector<std::string>{"outline noise", "model shape tolerance", "edge bias", "outline width",
                                               "panel shape profile"}));
}

// Started only in a mirror yaw's basin (yaw_turns.hpp), where the outline alone would keep it,
// the registration turns that pose about its long axis: one of the turns finds the panel.
TEST(RegisterAntenna, AStartInAMirrorYawsBasinIsTurnedToThePanel) {
  fixture::SceneSpec spec;
  spec.panel.width_m = 0.43, spec.panel.depth_m = 0.23;
  spec.view_offsets_deg = {-4.0, -2.0, 0.0, 2.0, 4.0};
  const SyntheticScene s = make_scene(spec);
  const AntennaScene scene = antenna_scene_with_mast(s, spec.panel);
  const auto model = model::parametric_panel(spec.panel);
  const auto turns = mirror_turns(s.T_board_antenna, model::outline_box(model), scene.viewpoints_board);
  const auto far = std::find_if(turns.begin(), turns.end(), [](double t) { return std::abs(t) > deg2rad(20.0); });
  ASSERT_NE(far, turns.end());
  Iso3 mirror = s.T_board_antenna;
  mirror.linear() = exp_so3(*far * mirror.linear().col(2)) * mirror.linear();
  const std::vector<PoseCandidate> start{{mirror, Strategy::kGiven, {}, 0.0, nullptr}};
  RegisterOptions without;
  without.turns.of_best = 0, without.crease_twins = false;
  const auto stuck = register_antenna(model, scene, without, start);
  ASSERT_TRUE(stuck.found) << stuck.why_not;
  EXPECT_GT(rad2deg(box_angle(stuck.T_board_antenna.linear(), s.T_board_antenna.linear())), 10.0)
      << "the mirror is a basin of its own";

  const auto r = register_antenna(model, scene, {}, start);
  ASSERT_TRUE(r.found) << r.why_not;
  EXPECT_LT(rad2deg(rotation_distance(r.T_board_antenna.linear(), s.T_board_antenna.linear())), 1.0);
  EXPECT_EQ(r.candidates[r.selection.best].strategy, Strategy::kTurned);
}

// Held where a faint side face would leave it, turned by atan(d / w) with its diagonal along the
// panel's front face (yaw_turns.hpp), the registration places that pose's crease twin on the panel;
// the panel's own outline, all four long edges seen here, then wins.
TEST(RegisterAntenna, APoseLyingOnTheCreaseHasThePanelAsItsTwin) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene(s);
  const auto model = model::parametric_panel({});
  const Vec3 box = model::outline_box(model);
  const Vec3 z = s.T_board_antenna.linear().col(2), y = s.T_board_antenna.linear().col(1);
  // The fixture's photos face the front (+y_a): its middle is d/2 along y_a.
  Iso3 on_crease = s.T_board_antenna;
  on_crease.linear() = exp_so3(std::atan2(box.y(), box.x()) * z) * on_crease.linear();
  on_crease.translation() += 0.5 * box.y() * y;
  RegisterOptions o;
  o.turns.of_best = 0, o.slide.of_best = 0, o.points_start = false;
  const std::vector<PoseCandidate> start{{on_crease, Strategy::kPointsHeld, {}, 0.0, nullptr}};
  const auto r = register_antenna(model, scene, o, start);
  ASSERT_TRUE(r.found) << r.why_not;
  const auto at_panel = [&](const PoseCandidate& c) {
    return c.strategy == Strategy::kCreaseTwin &&
           rad2deg(box_angle(c.T_board_antenna.linear(), s.T_board_antenna.linear())) < 0.5 &&
           (c.T_board_antenna.translation() - s.T_board_antenna.translation()).norm() < 0.01;
  };
  EXPECT_EQ(std::count_if(r.candidates.begin(), r.candidates.end(), at_panel), 1);
  EXPECT_LT(rad2deg(box_angle(r.T_board_antenna.linear(), s.T_board_antenna.linear())), 0.5);
  EXPECT_GT(r.rotation_covariance_board().trace(), 0.0) << "the twin's rotation is measured, not held";

  // Without the twins only the pose on the crease is left, and it meets too little of its outline
  // to be an answer.
  o.crease_twins = false;
  const auto without = register_antenna(model, scene, o, start);
  EXPECT_FALSE(without.found) << rad2deg(box_angle(without.T_board_antenna.linear(), s.T_board_antenna.linear()))
                              << "° from the panel";
  EXPECT_NE(without.why_not.find("along little of its outline"), std::string::npos) << without.why_not;
}

// The points' starts are also candidates where the points place them: with the region's points
// 5 cm off across the panel, the outline's descent takes the pose to the photos' edges, and the
// points' own pose is kept beside it, not descended.
TEST(RegisterAntenna, ThePointsPoseIsKeptWhereThePointsPlaceIt) {
  const SyntheticScene s = make_scene();
  AntennaScene scene = antenna_scene_with_mast(s);
  const Vec3 shift = 0.05 * s.T_board_antenna.linear().col(0);
  for (Vec3& p : scene.points_board.points) p += shift;
  // The distance of the nearest held candidate from where the points lie.
  const auto held = [&](const AntennaRegistration& r) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& c : r.candidates)
      if (c.strategy == Strategy::kPointsHeld &&
          rad2deg(rotation_distance(c.T_board_antenna.linear(), s.T_board_antenna.linear())) < 2.0)
        nearest = std::min(nearest, (c.T_board_antenna.translation() - s.T_board_antenna.translation() - shift).norm());
    return nearest;
  };
  RegisterOptions o;  // the points' pose meets few of the fixture's sharp edges: kept however faint
  o.max_faint_outline_score = 1.0;
  const auto r = register_antenna(model::parametric_panel({}), scene, o);
  ASSERT_TRUE(r.found) << r.why_not;
  EXPECT_LT((r.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.01);
  EXPECT_LT(held(r), 0.01);

  o.hold_points_poses = false;
  const auto without = register_antenna(model::parametric_panel({}), scene, o);
  ASSERT_TRUE(without.found) << without.why_not;
  EXPECT_FALSE(std::isfinite(held(without)));
}

TEST(RegisterAntenna, AContinuingRegistrationMakesNoTurnsOfItsOwn) {
  RegisterOptions o;
  ASSERT_GT(o.turns.of_best, 0u);
  const auto c = continuing(o);
  EXPECT_EQ(c.turns.of_best, 0u);
  EXPECT_EQ(c.slide.of_best, o.slide.of_best);
  EXPECT_EQ(c.refine_candidates, o.refine_candidates);
  EXPECT_TRUE(c.Check().ok());
}

// Two panels cannot share volume: with a neighbour known where this panel hangs, no candidate
// passes through it, and the panel is not found there.
TEST(RegisterAntenna, NoCandidatePassesThroughAKnownNeighbour) {
  const SyntheticScene s = make_scene();
  AntennaScene scene = antenna_scene_with_mast(s);
  const auto model = model::parametric_panel({});
  const OrientedBox neighbour{s.T_board_antenna, model.size_m};
  scene.neighbours_board.push_back(neighbour);
  const RegisterOptions o;
  const auto r = register_antenna(model, scene, o);
  for (const auto& c : r.candidates)
    EXPECT_FALSE(boxes_overlap(*shrunk({c.T_board_antenna, model.size_m}, o.neighbour_clearance_m),
                               *shrunk(neighbour, o.neighbour_clearance_m)))
        << to_string(c.strategy);
  if (r.found) {
    EXPECT_GT((r.T_board_antenna.translation() - s.T_board_antenna.translation()).norm(), 0.05);
  }
}

// No panel hangs inside its mast: with the known mast standing where the panel's outline is
// (its axis through the panel's centre), every pose that fits the outline hangs in it, and the
// result is no answer that says so, marked as the mast's (not to be retried without it).
TEST(RegisterAntenna, EveryPoseInTheKnownMastIsNoAnswer) {
  const SyntheticScene s = make_scene();
  AntennaScene scene = antenna_scene_with_mast(s);
  scene.mast->axis_point_board = s.T_board_antenna.translation();
  scene.mast->radius_m = 0.06;
  const auto r = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_FALSE(r.found) << "found "
                        << rad2deg(rotation_distance(r.T_board_antenna.linear(), s.T_board_antenna.linear()))
                        << "° from the panel";
  EXPECT_TRUE(r.against_mast);
  EXPECT_NE(r.why_not.find("hangs against or through the mast found behind it:"), std::string::npos) << r.why_not;
}

// With the mast where it stands, the panel's poses stand clear of it and are kept: the panel is
// found as without the check.
TEST(RegisterAntenna, AMastBehindThePanelDropsNoPoseOfIt) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene_with_mast(s);
  RegisterOptions without;
  without.min_mast_gap_m = -1.0;  // never dropped
  const auto r = register_antenna(model::parametric_panel({}), scene, {});
  const auto u = register_antenna(model::parametric_panel({}), scene, without);
  ASSERT_TRUE(r.found && u.found);
  EXPECT_FALSE(r.against_mast);
  EXPECT_LT(rad2deg(rotation_distance(r.T_board_antenna.linear(), u.T_board_antenna.linear())), 0.01);
}

// Where no pose meets its outline well, the poses that meet it faintly are measured, with a
// warning; beyond the faint limit nothing is. The limits are set about this scene's own outline.
TEST(RegisterAntenna, AnOutlineMetOnlyFaintlyIsMeasuredWithAWarning) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene_with_mast(s);
  const auto clear = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_TRUE(clear.found) << clear.why_not;
  EXPECT_TRUE(clear.warnings.empty());

  RegisterOptions o;
  o.max_outline_score = 0.5 * clear.outline_score;
  const auto faint = register_antenna(model::parametric_panel({}), scene, o);
  ASSERT_TRUE(faint.found) << faint.why_not;
  EXPECT_LT(rad2deg(rotation_distance(faint.T_board_antenna.linear(), s.T_board_antenna.linear())), 1.0);
  ASSERT_EQ(faint.warnings.size(), 1u);
  EXPECT_NE(faint.warnings[0].find("only faintly"), std::string::npos) << faint.warnings[0];

  o.max_faint_outline_score = o.max_outline_score;
  const auto none = register_antenna(model::parametric_panel({}), scene, o);
  EXPECT_FALSE(none.found);
  EXPECT_NE(none.why_not.find("fits its outline"), std::string::npos) << none.why_not;
}

// A radome rounder than the shapes profiled (shape_fit.hpp): its edges lie further inside than any
// rounding the profile tries, the shape stays open, and the answer says so and carries its poses.
TEST(RegisterAntenna, EdgesInsideTheRoundestOutlineAreMeasuredWithAWarning) {
  fixture::SceneSpec spec;
  spec.panel.edge_radius_m = 0.075;
  const SyntheticScene s = make_scene(spec);
  const auto r = register_antenna(model::parametric_panel({}), antenna_scene_with_mast(s, spec.panel), {});
  ASSERT_TRUE(r.found) << r.why_not;
  ASSERT_TRUE(r.panel_shape);
  EXPECT_FALSE(r.panel_shape->bracketed);
  const auto warned = std::any_of(r.warnings.begin(), r.warnings.end(), [](const std::string& w) {
    return w.find("further inside its box than the outline of its roundest radome") != std::string::npos &&
           w.find("the σ covers every rounding") != std::string::npos;
  });
  EXPECT_TRUE(warned);
  const double error = rotation_distance(r.T_board_antenna.linear(), s.T_board_antenna.linear());
  EXPECT_LT(error, 3 * std::sqrt(r.rotation_covariance_board().trace()));
}

// An answer must meet edges along enough of its outline to be told from what stands round it:
// with the answer's limit set under this scene's own outline, the pose that meets it is no answer,
// and the refusal says why and what would help.
TEST(RegisterAntenna, AnAnswerMeetingTooLittleOfItsOutlineIsNone) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene_with_mast(s);
  const auto clear = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_TRUE(clear.found) << clear.why_not;

  RegisterOptions o;
  o.max_outline_score = o.max_answer_outline_score = 0.5 * clear.outline_score;
  ASSERT_TRUE(o.Check().ok());
  const auto none = register_antenna(model::parametric_panel({}), scene, o);
  EXPECT_FALSE(none.found);
  EXPECT_GT(none.proposed, 0u);
  EXPECT_NE(none.why_not.find("meets the photos' edges along little of its outline"), std::string::npos)
      << none.why_not;
  EXPECT_NE(none.why_not.find("against a contrasting background"), std::string::npos) << none.why_not;

  o.max_answer_outline_score = 0.5 * o.max_outline_score;
  EXPECT_FALSE(o.Check().ok()) << "an answer's limit under the clear outline's";
}

// A pipe where the panel should be: the panel's model fits it about as well at every turn about
// its long axis. Met clearly, the σ covers the turns; met only faintly, nothing shows that the
// object is a panel at all (a mast, a mount's pipe), and its downtilt and roll keep only the range
// panels hang in.
TEST(RegisterAntenna, AFaintAnswerThatShowsNoFacesKeepsOnlyHowPanelsHang) {
  const model::PanelSpec panel;
  fixture::SceneSpec spec;
  spec.rendered = sim::cylinder_mesh(Vec3(0, 0, -0.5 * panel.height_m), Vec3(0, 0, 0.5 * panel.height_m),
                                     0.25 * (panel.width_m + panel.depth_m), 32);
  const SyntheticScene s = make_scene(spec);
  AntennaScene scene = antenna_scene_with_mast(s, panel);
  std::vector<Vec3> viewpoints;
  for (const Vec3& c : scene.viewpoints_board) viewpoints.push_back(s.T_board_antenna.inverse() * c);
  scene.points_board = transformed(model::visible_surface(spec.rendered, viewpoints, 0.02, 5), s.T_board_antenna);
  const auto axis_source = [](const AntennaRegistration& r) {
    return std::find_if(r.rotation_covariance_sources.begin(), r.rotation_covariance_sources.end(),
                        [](const UncertaintySource& u) { return u.source == "long axis not shown to be the panel's"; });
  };

  const auto model = model::parametric_panel(panel);
  const auto clear = register_antenna(model, scene, {});
  ASSERT_TRUE(clear.found) << clear.why_not;
  EXPECT_EQ(axis_source(clear), clear.rotation_covariance_sources.end());
  double open = 0.0;
  for (const Iso3& T : clear.rivals) {
    const double angle = angle_between(T.linear().col(1), clear.T_board_antenna.linear().col(1));
    open = std::max(open, std::min(angle, M_PI - angle));
  }
  ASSERT_GT(rad2deg(open), 45.0) << "the pipe must leave the panel's facing open";

  RegisterOptions o;
  o.max_outline_score = 0.5 * clear.outline_score;
  const auto faint = register_antenna(model, scene, o);
  ASSERT_TRUE(faint.found) << faint.why_not;
  const auto source = axis_source(faint);
  ASSERT_NE(source, faint.rotation_covariance_sources.end());
  const Mat3& R = faint.T_board_antenna.linear();
  const auto sigma_about = [&](const Vec3& axis) { return rad2deg(std::sqrt(axis.dot(source->covariance * axis))); };
  EXPECT_NEAR(sigma_about(R.col(0)), 30.0 / std::sqrt(12.0), 1e-9);  // downtilt: −12…+18°
  EXPECT_NEAR(sigma_about(R.col(1)), 10.0 / std::sqrt(12.0), 1e-9);  // roll: ±5°
  EXPECT_NEAR(sigma_about(R.col(2)), 0.0, 1e-6);
  const bool warned = std::any_of(faint.warnings.begin(), faint.warnings.end(), [](const std::string& w) {
    return w.find("nothing shows that the object is this panel") != std::string::npos &&
           w.find("the range panels hang in (-12…+18° of downtilt") != std::string::npos;
  });
  EXPECT_TRUE(warned);

  o.max_faint_open_facing_deg = 90.0;  // no facing too open: the σ covers the rivals alone
  const auto allowed = register_antenna(model, scene, o);
  ASSERT_TRUE(allowed.found) << allowed.why_not;
  EXPECT_EQ(axis_source(allowed), allowed.rotation_covariance_sources.end());

  o.max_faint_open_facing_deg = 0.0;
  EXPECT_FALSE(o.Check().ok());
  o.max_faint_open_facing_deg = 45.0;
  o.hanging_roll_deg = {5.0, -5.0};
  EXPECT_FALSE(o.Check().ok());
}

// The clear outline limit only warns: a candidate whose outline fits worse than it, but within the
// faint limit, still takes part in the selection, where only the comparison with the best can rule
// it out.
TEST(RegisterAntenna, TheClearOutlineLimitCutsNoCandidate) {
  const SyntheticScene s = make_scene();
  const AntennaScene scene = antenna_scene_with_mast(s);
  const auto all = register_antenna(model::parametric_panel({}), scene, {});
  ASSERT_TRUE(all.found) << all.why_not;
  const auto outline_of = [](const PoseCandidate& c) {  // over the photos that measured it
    double sum = 0.0;
    int n = 0;
    for (const double v : c.evidence.outline)
      if (std::isfinite(v)) sum += v, ++n;
    return n ? sum / n : 1.0;
  };
  const auto& best = all.candidates[all.selection.best];
  const bool a_worse_outline = std::any_of(all.candidates.begin(), all.candidates.end(), [&](const PoseCandidate& c) {
    return outline_of(c) > 1.5 * outline_of(best);
  });
  ASSERT_TRUE(a_worse_outline) << "the scene must give a candidate fitting its outline worse than the best";

  RegisterOptions o;
  o.max_outline_score = 1.2 * all.outline_score;
  const auto r = register_antenna(model::parametric_panel({}), scene, o);
  ASSERT_TRUE(r.found) << r.why_not;
  EXPECT_EQ(r.candidates.size(), all.candidates.size());
  EXPECT_TRUE(r.warnings.empty());
}

}  // namespace
}  // namespace antpose::registration
