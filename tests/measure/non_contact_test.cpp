#include "antpose/measure/non_contact.hpp"

#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

using registration::RegistrationVerdict;

// Three panels of one model registered beside each other, 1 m apart along x.
struct Panels {
  NonContactSetup setup;
  std::vector<AntennaMeasurement> antennas;
};

Panels three_panels() {
  Panels f;
  model::AntennaModel panel;
  panel.name = "panel";
  panel.size_m = Vec3(0.3, 0.15, 1.2);
  f.setup.models.push_back(panel);
  for (int k = 0; k < 3; ++k) {
    AntennaMeasurement& m = f.antennas.emplace_back();
    m.p_board_antenna = Vec3(static_cast<double>(k), 0.0, 10.0);
  }
  return f;
}

TEST(SettledNeighbours, EveryOtherRegisteredPanelIsKnown) {
  const auto f = three_panels();
  const auto known = settled_neighbours(f.antennas, f.setup, 1);
  ASSERT_EQ(known.size(), 2u);
  EXPECT_DOUBLE_EQ(known[0].T_board_box.translation().x(), 0.0);
  EXPECT_DOUBLE_EQ(known[1].T_board_box.translation().x(), 2.0);
  EXPECT_TRUE(known[0].size_m.isApprox(f.setup.models[0].size_m));
}

TEST(SettledNeighbours, AnAmbiguousNeighbourIsNotKnown) {
  // Its reported pose may stand on the target itself: taken as known, it would rule out the
  // target's true pose.
  auto f = three_panels();
  f.antennas[0].verdict = RegistrationVerdict::kAmbiguousShape;
  f.antennas[0].p_board_antenna = f.antennas[1].p_board_antenna;
  const auto known = settled_neighbours(f.antennas, f.setup, 1);
  ASSERT_EQ(known.size(), 1u);
  EXPECT_DOUBLE_EQ(known[0].T_board_box.translation().x(), 2.0);
}

TEST(SettledNeighbours, FrontAndBackOpenStillSettleTheBox) {
  auto f = three_panels();
  f.antennas[2].verdict = RegistrationVerdict::kFrontBackOpen;
  EXPECT_EQ(settled_neighbours(f.antennas, f.setup, 1).size(), 2u);
}

TEST(SettledNeighbours, RefusedAndModelFreeAntennasAreNotKnown) {
  auto f = three_panels();
  f.antennas[0].error = "refused";
  EXPECT_EQ(settled_neighbours(f.antennas, f.setup, 1).size(), 1u);
  f.setup.models.clear();  // model-free: no box to know
  EXPECT_TRUE(settled_neighbours(f.antennas, f.setup, 1).empty());
}

reconstruction::Mast pole_at(double x, double y, double radius = 0.05) {
  reconstruction::Mast m;
  m.axis_point_board = Vec3(x, y, 8.0);  // the height along the axis does not matter
  m.up_board = Vec3::UnitZ();
  m.radius_m = radius;
  return m;
}

TEST(NeighboursMast, AMastFoundForAPanelBesideItWithinReachIsItsToo) {
  auto f = three_panels();
  f.antennas[2].mast = pole_at(1.6, 0.5);  // 0.78 m from panel 1, 1.68 m from panel 0
  const auto adopted = neighbours_mast(f.antennas, f.setup, 1, 1.2);
  ASSERT_TRUE(adopted.has_value());
  EXPECT_TRUE(adopted->axis_point_board.isApprox(Vec3(1.6, 0.5, 8.0)));
  EXPECT_FALSE(neighbours_mast(f.antennas, f.setup, 0, 1.2).has_value());  // beyond reach
  EXPECT_FALSE(neighbours_mast(f.antennas, f.setup, 2, 1.2).has_value());  // its own is not a neighbour's
}

TEST(NeighboursMast, TheNearestClearOfThePanelIsTaken) {
  auto f = three_panels();
  f.antennas[0].mast = pole_at(0.5, -0.6);  // 0.78 m from panel 1
  f.antennas[2].mast = pole_at(1.3, 0.4);   // 0.5 m from panel 1: nearer
  EXPECT_TRUE(neighbours_mast(f.antennas, f.setup, 1, 1.2)->axis_point_board.isApprox(Vec3(1.3, 0.4, 8.0)));
  // A pole through the panel's own box is not one it hangs on.
  f.antennas[2].mast = pole_at(1.1, 0.05);
  EXPECT_TRUE(neighbours_mast(f.antennas, f.setup, 1, 1.2)->axis_point_board.isApprox(Vec3(0.5, -0.6, 8.0)));
}

TEST(FrontBackMasts, OnlyAnAntennaLeftOpenWithoutItsOwnMastTakesItsNeighbours) {
  auto f = three_panels();
  f.antennas[1].mast = pole_at(0.9, 0.6);
  f.antennas[0].verdict = RegistrationVerdict::kFrontBackOpen;
  f.antennas[0].error = "front and back cannot be told apart";
  f.antennas[2].verdict = RegistrationVerdict::kFrontBackOpen;
  f.antennas[2].mast = pole_at(2.0, 0.7);  // its own, which did not decide
  const auto masts = front_back_masts(f.antennas, f.setup, 2.0);
  ASSERT_EQ(masts.size(), 3u);
  ASSERT_TRUE(masts[0].has_value());
  EXPECT_TRUE(masts[0]->axis_point_board.isApprox(Vec3(0.9, 0.6, 8.0)));
  EXPECT_FALSE(masts[1].has_value());                                       // decided
  EXPECT_FALSE(masts[2].has_value());                                       // has its own
  EXPECT_FALSE(front_back_masts(f.antennas, f.setup, 0.5)[0].has_value());  // beyond reach
}

TEST(NeighboursMast, ANegativeReachIsRefusedByTheOptionsCheck) {
  NonContactOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.shared_mast_reach_m = -0.5;
  EXPECT_FALSE(o.Check().ok());
}

TEST(NeighboursMast, ARefusedAntennasMastAndAModelFreeTargetTakeNone) {
  auto f = three_panels();
  f.antennas[2].mast = pole_at(1.6, 0.5);
  f.antennas[2].error = "refused";
  EXPECT_FALSE(neighbours_mast(f.antennas, f.setup, 1, 1.2).has_value());
  f.antennas[2].error.reset();
  f.setup.models.clear();  // model-free: no box to hang
  EXPECT_FALSE(neighbours_mast(f.antennas, f.setup, 1, 1.2).has_value());
}

}  // namespace
}  // namespace antpose::measure
