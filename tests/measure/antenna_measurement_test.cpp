#include "antpose/measure/antenna_measurement.hpp"

#include <gtest/gtest.h>

namespace antpose::measure {
namespace {

// An attitude whose budget holds the board's share and the outline's (σ in degrees).
AntennaAttitudeResult attitude_with(double board_az, double outline_az, double board_tilt, double outline_tilt) {
  AntennaAttitudeResult a;
  const auto share = [](const char* source, double az, double tilt) {
    SigmaShare s;
    s.source = source, s.sigma.azimuth = deg2rad(az), s.sigma.downtilt = deg2rad(tilt), s.sigma.roll = 0.0;
    return s;
  };
  a.budget = {share("board attitude in the world", board_az, board_tilt),
              share("outline noise", outline_az, outline_tilt)};
  a.sigma.azimuth = deg2rad(std::hypot(board_az, outline_az));
  a.sigma.downtilt = deg2rad(std::hypot(board_tilt, outline_tilt));
  a.sigma.roll = 0.0;
  return a;
}

TEST(ImprecisionWarning, NoneWhereBothAnglesAreNarrow) {
  EXPECT_FALSE(imprecision_warning(attitude_with(0.5, 1.0, 0.05, 0.3), AntennaOptions{}).has_value());
}

TEST(ImprecisionWarning, AWideAzimuthNamesItsSigmaAndTheOutlineThatLimitsIt) {
  const auto w = imprecision_warning(attitude_with(0.5, 7.9, 0.05, 0.3), AntennaOptions{});
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find("the azimuth to ±7.9°"), std::string::npos) << *w;
  EXPECT_EQ(w->find("downtilt to"), std::string::npos) << *w;
  EXPECT_NE(w->find("mostly from the outline noise"), std::string::npos) << *w;
  EXPECT_NE(w->find("from nearer"), std::string::npos) << *w;
}

TEST(ImprecisionWarning, ACompassThatLimitsTheAzimuthAsksForAnotherWalk) {
  const auto w = imprecision_warning(attitude_with(4.0, 0.5, 0.05, 0.2), AntennaOptions{});
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find("mostly from the board attitude in the world"), std::string::npos) << *w;
  EXPECT_NE(w->find("away from steel"), std::string::npos) << *w;
}

TEST(ImprecisionWarning, AWideDowntiltAloneIsNamedWithItsLimit) {
  AntennaOptions o;
  o.warn_sigma_downtilt_deg = 0.5;
  const auto w = imprecision_warning(attitude_with(0.5, 1.0, 0.1, 0.8), o);
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find("the downtilt to ±0.8°"), std::string::npos) << *w;
  EXPECT_EQ(w->find("azimuth to"), std::string::npos) << *w;
  EXPECT_NE(w->find("outline noise"), std::string::npos) << *w;
}

TEST(ImprecisionWarning, BadThresholdsAreRefusedByTheOptionsCheck) {
  AntennaOptions o;
  o.warn_sigma_azimuth_deg = 0.0;
  EXPECT_FALSE(o.Check().ok());
}

TEST(AntennaOptions, ANegativeSameMastToleranceIsRefusedByTheCheck) {
  AntennaOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.same_mast_m = -0.01;
  const auto problems = o.Check();
  EXPECT_FALSE(problems.ok());
  EXPECT_NE(problems.message().find("same_mast_m"), std::string::npos) << problems.message();
}

}  // namespace
}  // namespace antpose::measure
