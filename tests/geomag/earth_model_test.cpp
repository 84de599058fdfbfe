// geomag/earth_model: WGS84 normal gravity and the Earth's rotation.
#include "antpose/geomag/earth_model.hpp"

#include <gtest/gtest.h>

namespace antpose::geomag {
namespace {

TEST(EarthModel, NormalGravityAndRotationMatchWgs84) {
  // NIMA TR8350.2 Table 3.4: γ at the equator and the pole; free air −3.086e-6 s^-2 per metre.
  EXPECT_NEAR(normal_gravity(0.0, 0.0), 9.7803253359, 1e-9);
  EXPECT_NEAR(normal_gravity(90.0, 0.0), 9.8321849378, 1e-8);
  EXPECT_NEAR(normal_gravity(45.0, 1000.0), 9.806199 - 3.086e-3, 1e-5);
  EXPECT_NEAR(earth_rate_enu(90.0).z(), 7.292115e-5, 1e-15);
  EXPECT_NEAR(earth_rate_enu(0.0).y(), 7.292115e-5, 1e-15);
  EXPECT_EQ(earth_rate_enu(30.0).x(), 0.0);
}

}  // namespace
}  // namespace antpose::geomag
