#include "antpose/registration/pose_selection.hpp"

#include <set>
#include <string>

#include <gtest/gtest.h>

namespace antpose::registration {
namespace {

// A candidate facing `azimuth_deg` about the board's z (up), at `p`, with given outline costs.
PoseCandidate facing(double azimuth_deg, const Vec3& p, std::vector<double> outline) {
  PoseCandidate c;
  c.T_board_antenna = isometry(rot_z(-deg2rad(azimuth_deg)), p);
  c.evidence.outline = std::move(outline);
  c.score = c.evidence.score({});
  return c;
}

// The candidate with the region's points' costs, slice by slice, too.
PoseCandidate with_points(PoseCandidate c, std::vector<double> points) {
  c.evidence.points = std::move(points);
  c.score = c.evidence.score({});
  return c;
}

// Side units: the outline cost of the vertical structure behind the pose, photo by photo.
PoseEvidence side(std::vector<double> mount_outline) {
  PoseEvidence e;
  e.mount_outline = std::move(mount_outline);
  return e;
}

TEST(PoseSelection, AnotherYawThePhotosDoNotRuleOutIsARival) {
  const std::vector<PoseCandidate> candidates{
      facing(40, Vec3::Zero(), {0.10, 0.11, 0.09, 0.10, 0.12, 0.10}),
      facing(75, Vec3::Zero(), {0.09, 0.16, 0.10, 0.13, 0.10, 0.14}),    // about as good: a rival
      facing(130, Vec3::Zero(), {0.30, 0.32, 0.29, 0.31, 0.33, 0.30}),   // clearly worse
      facing(222, Vec3::Zero(), {0.10, 0.11, 0.09, 0.10, 0.12, 0.10})};  // the best turned round: not a rival
  const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0}));
  const Selection s = select_pose(candidates, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_EQ(s.rivals.size(), 1u);
  EXPECT_EQ(s.rivals[0], 1u);
  ASSERT_TRUE(s.runner_up);
  EXPECT_FALSE(s.runner_up->decisive);
}

// A candidate a few degrees off that the photos do not rule out is the same answer (no rival, no
// ambiguity), but its σ must cover it; one they rule out is left alone. Turned round about its long
// axis a box lies where it lay: so too where the candidates face the other way (front and back are
// decided apart).
TEST(PoseSelection, ANearPoseThePhotosDoNotRuleOutIsANearRival) {
  for (const double turn : {0.0, 180.0}) {
    const std::vector<PoseCandidate> candidates{
        facing(40, Vec3::Zero(), {0.10, 0.11, 0.09, 0.10, 0.12, 0.10}),
        facing(43 + turn, Vec3::Zero(), {0.11, 0.10, 0.10, 0.11, 0.11, 0.10}),   // about as good: near rival
        facing(36 + turn, Vec3::Zero(), {0.30, 0.32, 0.29, 0.31, 0.33, 0.30})};  // clearly worse
    const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0}));
    const Selection s = select_pose(candidates, twins, std::nullopt, {}, {});
    EXPECT_EQ(s.best, 0u) << turn;
    EXPECT_TRUE(s.rivals.empty()) << turn;
    EXPECT_FALSE(s.runner_up) << turn;
    ASSERT_EQ(s.near_rivals.size(), 1u) << turn;
    EXPECT_EQ(s.near_rivals[0], 1u) << turn;
  }
}

// Where a stretch of the true outline is too faint to be seen, a pose a few degrees off that lays
// its outline on the crease beside it meets more edges and costs less in every photo alike; the
// edges it meets lie worse on it. That lower cost does not rule out the pose whose outline lies
// better on what it meets: a near rival. One whose placement is no better is left alone.
TEST(PoseSelection, ANearPoseThatMeetsItsEdgesBetterIsANearRival) {
  auto with_placement = [](PoseCandidate c, std::vector<double> placement) {
    c.evidence.placement = std::move(placement);
    return c;
  };
  const std::vector<PoseCandidate> candidates{
      with_placement(facing(40, Vec3::Zero(), {0.14, 0.12, 0.13, 0.12, 0.12, 0.12}),
                     {0.12, 0.10, 0.11, 0.10, 0.09, 0.08}),
      with_placement(facing(48, Vec3::Zero(), {0.38, 0.34, 0.28, 0.24, 0.27, 0.14}),
                     {0.10, 0.05, 0.09, 0.07, 0.06, 0.07}),  // fewer edges, better placed
      with_placement(facing(34, Vec3::Zero(), {0.38, 0.34, 0.28, 0.24, 0.27, 0.14}),
                     {0.16, 0.12, 0.15, 0.14, 0.11, 0.12})};  // fewer edges, placed no better
  const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0}));
  EXPECT_TRUE(compare_shape(candidates[0].evidence, candidates[1].evidence, {}).decisive);
  const Selection s = select_pose(candidates, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_EQ(s.near_rivals.size(), 1u);
  EXPECT_EQ(s.near_rivals[0], 1u);
}

// A crease twin of the winner (yaw_turns.hpp) is the crease error at its full size, further off than
// a near rival: where it meets fewer edges but lies better on those it meets, it is a rival however
// decisively the winner's cost beats it. The same pair proposed otherwise (not a box laid on the
// other's crease) is decided by the cost.
TEST(PoseSelection, ACreaseTwinThatMeetsItsEdgesBetterIsARival) {
  PoseCandidate best = facing(40, Vec3::Zero(), {0.14, 0.12, 0.13, 0.12, 0.12, 0.12});
  best.evidence.placement = {0.12, 0.10, 0.11, 0.10, 0.09, 0.08};
  PoseCandidate twin = facing(62, Vec3::Zero(), {0.38, 0.34, 0.28, 0.24, 0.27, 0.14});
  twin.evidence.placement = {0.10, 0.05, 0.09, 0.07, 0.06, 0.07};
  twin.strategy = Strategy::kCreaseTwin;
  const std::vector<PoseEvidence> twins(2, side({0.0, 0.0}));
  ASSERT_TRUE(compare_shape(best.evidence, twin.evidence, {}).decisive);
  const Selection s = select_pose({best, twin}, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_EQ(s.rivals.size(), 1u);
  EXPECT_EQ(s.rivals[0], 1u);

  twin.strategy = Strategy::kTurned;
  EXPECT_TRUE(select_pose({best, twin}, twins, std::nullopt, {}, {}).rivals.empty());
  twin.strategy = Strategy::kCreaseTwin;
  twin.evidence.placement = {0.16, 0.12, 0.15, 0.14, 0.11, 0.12};  // placed no better
  EXPECT_TRUE(select_pose({best, twin}, twins, std::nullopt, {}, {}).rivals.empty());
}

// A pose further off whose outline costs more in every photo (a stretch of it too faint to meet an
// edge) but that the region's points fit much better: the winner's lower score rests on the weight
// of the points against the outline, which is known only within a range, and at its end the pose
// is not ruled out: a rival. One the points fit a little better is ruled out: it stays second at
// every weight.
TEST(PoseSelection, AnotherYawThePointsFitMuchBetterIsARival) {
  const std::vector<PoseCandidate> candidates{
      with_points(facing(40, Vec3::Zero(), {0.28, 0.26, 0.27, 0.29, 0.25, 0.27}), {0.55, 0.52, 0.58, 0.54}),
      with_points(facing(65, Vec3::Zero(), {0.64, 0.60, 0.66, 0.62, 0.63, 0.61}), {0.38, 0.36, 0.40, 0.37}),
      with_points(facing(100, Vec3::Zero(), {0.64, 0.60, 0.66, 0.62, 0.63, 0.61}), {0.52, 0.49, 0.55, 0.51})};
  const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0}));
  EXPECT_TRUE(compare_shape(candidates[0].evidence, candidates[1].evidence, {}).decisive);
  const Selection s = select_pose(candidates, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_EQ(s.rivals.size(), 1u);
  EXPECT_EQ(s.rivals[0], 1u);

  EvidenceOptions exact;  // with the weight taken as known, the score rules both out
  exact.points_weight_range = 1.0;
  EXPECT_TRUE(select_pose(candidates, twins, std::nullopt, exact, {}).rivals.empty());
}

// A pose further off that both halves fit worse, the points unevenly: with the points weighed at
// the top of their range, their scatter swamps the margin, which is then no longer decisive. The
// winner still ranks first at every weight, and the margin is real at the nominal one: no rival.
TEST(PoseSelection, AMarginThePointsScatterAtTheEndOfTheRangeStillRulesOut) {
  const std::vector<PoseCandidate> candidates{
      with_points(facing(40, Vec3::Zero(), {0.28, 0.26, 0.27, 0.29, 0.25, 0.27}), {0.30, 0.32, 0.31, 0.29}),
      with_points(facing(90, Vec3::Zero(), {0.64, 0.60, 0.66, 0.62, 0.63, 0.61}), {0.35, 0.90, 0.30, 0.80})};
  const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0}));
  EvidenceOptions points_heavy;
  points_heavy.points_weight *= points_heavy.points_weight_range;
  ASSERT_TRUE(compare_shape(candidates[0].evidence, candidates[1].evidence, {}).decisive);
  ASSERT_FALSE(compare_shape(candidates[0].evidence, candidates[1].evidence, points_heavy).decisive);
  const Selection s = select_pose(candidates, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  EXPECT_TRUE(s.rivals.empty());
}

// A pose further off whose outline is decisively better in the photos, beaten by the winner's
// points alone (as where the region's points are of the mount behind the panel): each half decides
// against the other, and no weight of the points makes that noise: a rival, though the winner
// ranks first at either end of the weight's range. Where the outline's margin is within its
// scatter, the points decide.
TEST(PoseSelection, AnotherYawWhoseOutlineIsDecisivelyBetterIsARival) {
  const auto best = with_points(facing(40, Vec3::Zero(), {0.74, 0.71, 0.75, 0.72, 0.73, 0.72}), {0.36, 0.35, 0.37});
  const auto other = with_points(facing(80, Vec3::Zero(), {0.62, 0.60, 0.63, 0.61, 0.60, 0.62}), {0.86, 0.87, 0.86});
  const std::vector<PoseEvidence> twins(2, side({0.0, 0.0}));
  EvidenceOptions outline_light;
  outline_light.points_weight /= outline_light.points_weight_range;
  ASSERT_GT(compare_shape(best.evidence, other.evidence, outline_light).difference, 0.0);
  const Selection s = select_pose({best, other}, twins, std::nullopt, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_EQ(s.rivals.size(), 1u);
  EXPECT_EQ(s.rivals[0], 1u);

  auto unclear = other;  // better by as much on average, but not in every photo
  unclear.evidence.outline = {0.40, 0.85, 0.45, 0.80, 0.42, 0.80};
  unclear.score = unclear.evidence.score({});
  EXPECT_TRUE(select_pose({best, unclear}, twins, std::nullopt, {}, {}).rivals.empty());
}

TEST(PoseSelection, AMastBehindDecidesFrontAndBackWhateverTheDowntilt) {
  // The panel 0.4 m north of the mast; as registered it faces south, at its mast: turned round
  // it faces north, away from it. An uptilt as registered changes nothing.
  reconstruction::Mast mast;
  mast.axis_point_board = Vec3::Zero(), mast.up_board = Vec3::UnitZ(), mast.radius_m = 0.06;
  PoseCandidate c = facing(180, Vec3(0.0, 0.4, 0.0), {0.1, 0.1});
  c.T_board_antenna.linear() = c.T_board_antenna.linear() * rot_x(deg2rad(8.0));
  const Selection s = select_pose({c}, {side({0.0, 0.0})}, mast, {}, {});
  EXPECT_TRUE(s.turned);
  EXPECT_EQ(s.front_back_cue, FrontBackCue::kMast);
  EXPECT_FALSE(s.front_back_open);
}

TEST(PoseSelection, MastBearingIsTheBoresightsAngleToTheMastEitherWay) {
  reconstruction::Mast mast;
  mast.axis_point_board = Vec3(0.0, 0.0, 5.0), mast.up_board = Vec3::UnitZ(), mast.radius_m = 0.2;
  const Vec3 north(0.0, 0.9, 0.0);  // the panel 0.9 m north of the mast's axis
  EXPECT_NEAR(*mast_bearing(mast, facing(0, north, {}).T_board_antenna), 0.0, 1e-9);
  EXPECT_NEAR(*mast_bearing(mast, facing(180, north, {}).T_board_antenna), 0.0, 1e-9);
  EXPECT_NEAR(rad2deg(*mast_bearing(mast, facing(-80, north, {}).T_board_antenna)), 80.0, 1e-9);
  EXPECT_NEAR(rad2deg(*mast_bearing(mast, facing(110, north, {}).T_board_antenna)), 70.0, 1e-9);
  // A downtilt does not change it: the bearing is taken across the mast's axis.
  PoseCandidate tilted = facing(30, north, {});
  tilted.T_board_antenna.linear() = tilted.T_board_antenna.linear() * rot_x(deg2rad(-12.0));
  EXPECT_NEAR(rad2deg(*mast_bearing(mast, tilted.T_board_antenna)), 30.0, 1e-9);
  EXPECT_FALSE(mast_bearing(mast, facing(0, Vec3(0.1, 0.0, 0.0), {}).T_board_antenna));  // within the mast
}

// A near-square box fits its outline a quarter turn off; the mast behind the panel contradicts
// that pose, and the best pose that faces the mast becomes its rival though it scores worse. With
// the mast behind the best, the same scores rule that pose out.
TEST(PoseSelection, APoseSideOnToTheMastHasTheBestPoseFacingItAsARival) {
  reconstruction::Mast mast;
  mast.axis_point_board = Vec3::Zero(), mast.up_board = Vec3::UnitZ(), mast.radius_m = 0.25;
  const Vec3 p(0.0, 1.0, 0.0);  // the panel 1 m north of the mast: its back faces south
  const std::vector<double> good{0.20, 0.22, 0.19, 0.21, 0.20, 0.22}, worse{0.40, 0.43, 0.41, 0.42, 0.40, 0.44},
      worst{0.60, 0.63, 0.61, 0.62, 0.60, 0.64};
  const std::vector<PoseCandidate> side_on{facing(95, p, good), facing(75, p, worse), facing(3, p, worse),
                                           facing(-20, p, worst)};
  const std::vector<PoseEvidence> twins(side_on.size(), side({0.0, 0.0, 0.0, 0.0, 0.0, 0.0}));
  ASSERT_TRUE(compare_shape(side_on[0].evidence, side_on[2].evidence, {}).decisive);
  const Selection s = select_pose(side_on, twins, mast, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_TRUE(s.mast_rival);
  EXPECT_EQ(*s.mast_rival, 2u);  // at 75° the second turns a side to the mast too
  EXPECT_TRUE(s.versus_mast_rival.decisive);
  ASSERT_EQ(s.rivals.size(), 1u);
  EXPECT_EQ(s.rivals[0], 2u);

  std::vector<PoseCandidate> facing_mast = side_on;
  facing_mast[0] = facing(175, p, good);  // the best's back to the mast: nothing to contradict
  const Selection t = select_pose(facing_mast, twins, mast, {}, {});
  EXPECT_EQ(t.best, 0u);
  EXPECT_FALSE(t.mast_rival);
  EXPECT_TRUE(t.rivals.empty());
  EXPECT_TRUE(t.turned);  // facing south, at its mast: turned round
  EXPECT_EQ(t.front_back_cue, FrontBackCue::kMast);
}

// A candidate whose outline is too faint to be the answer is never the best, however it scores,
// nor an ordinary rival; it is weighed only as the pose facing the mast.
TEST(PoseSelection, AFaintOutlineIsOnlyEverTheMastsRival) {
  reconstruction::Mast mast;
  mast.axis_point_board = Vec3::Zero(), mast.up_board = Vec3::UnitZ(), mast.radius_m = 0.25;
  const Vec3 p(0.0, 1.0, 0.0);
  const std::vector<double> good{0.20, 0.22, 0.19, 0.21}, alike{0.21, 0.20, 0.22, 0.20};
  std::vector<PoseCandidate> candidates{facing(95, p, good), facing(40, p, alike), facing(-4, p, alike)};
  candidates[1].score = 0.1, candidates[2].score = 0.15;  // better than the best by score alone
  candidates[1].faint_outline = candidates[2].faint_outline = true;
  const std::vector<PoseEvidence> twins(candidates.size(), side({0.0, 0.0, 0.0, 0.0}));
  const Selection s = select_pose(candidates, twins, mast, {}, {});
  EXPECT_EQ(s.best, 0u);
  ASSERT_TRUE(s.mast_rival);
  EXPECT_EQ(*s.mast_rival, 1u);  // 40° from the mast's direction: not side-on, and the better score
  EXPECT_EQ(s.rivals, std::vector<std::size_t>{1u});
  EXPECT_FALSE(s.runner_up);
  const Selection without_mast = select_pose(candidates, twins, std::nullopt, {}, {});
  EXPECT_EQ(without_mast.best, 0u);
  EXPECT_TRUE(without_mast.rivals.empty());
}

TEST(PoseSelection, WithoutACueFrontAndBackStayOpen) {
  PoseCandidate c = facing(10, Vec3::Zero(), {0.1, 0.1, 0.1});
  c.evidence.mount_outline = {0.32, 0.30, 0.33};
  // Turned round, a structure behind fits about as well in some photos and worse in others.
  const Selection open = select_pose({c}, {side({0.30, 0.35, 0.31})}, std::nullopt, {}, {});
  EXPECT_TRUE(open.front_back_open);
  EXPECT_EQ(open.front_back_cue, FrontBackCue::kNone);
  // Where every photo shows a pole behind the pose and none behind its twin, the evidence decides.
  const Selection decided = select_pose({c}, {side({0.60, 0.62, 0.65})}, std::nullopt, {}, {});
  EXPECT_FALSE(decided.front_back_open);
  EXPECT_FALSE(decided.turned);
  EXPECT_EQ(decided.front_back_cue, FrontBackCue::kEvidence);
}

// A box turned upside down about its boresight is the same box: the pose keeps its boresight and
// its long axis turns upward; an upright pose is left alone.
TEST(PoseSelection, UprightTurnsAnUpsideDownPoseAboutItsBoresight) {
  const Mat3 R_board_level = exp_so3(Vec3(0.2, -0.1, 0.4));  // the board is not level
  const Vec3 up_board = R_board_level * Vec3::UnitZ();
  const Mat3 R = R_board_level * rot_z(-deg2rad(40)) * rot_x(-deg2rad(6)) * rot_y(deg2rad(2));
  EXPECT_TRUE(upright(R, up_board).isApprox(R));
  const Mat3 upside_down = R * rot_y(M_PI);
  const Mat3 fixed = upright(upside_down, up_board);
  EXPECT_LT(rotation_distance(fixed, R), 1e-9);
  const Iso3 T = upright(isometry(upside_down, Vec3(1, 2, 3)), up_board);
  EXPECT_LT(rotation_distance(T.linear(), R), 1e-9);
  EXPECT_TRUE(T.translation().isApprox(Vec3(1, 2, 3)));
}

// Reports name every strategy, each by its own name.
TEST(PoseSelection, EveryStrategyHasItsOwnName) {
  const std::set<std::string> names{
      to_string(Strategy::kGiven),      to_string(Strategy::kOutlineSearch), to_string(Strategy::kPointsStart),
      to_string(Strategy::kPointsHeld), to_string(Strategy::kTurned),        to_string(Strategy::kTurnedAndPlaced),
      to_string(Strategy::kSlid),       to_string(Strategy::kFacingMast),    to_string(Strategy::kCreaseTwin)};
  EXPECT_EQ(names.size(), 9u);
  EXPECT_EQ(to_string(Strategy::kOutlineSearch), "outline search");
}

}  // namespace
}  // namespace antpose::registration
