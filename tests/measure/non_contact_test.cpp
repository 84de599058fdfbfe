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

}  // namespace
}  // namespace antpose::measure
