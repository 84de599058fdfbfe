#include "antpose/measure/field_check.hpp"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/capture.hpp"

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

// The acceptance sites' place and day (Hangzhou, 2025-06-01).
geomag::SiteField hangzhou() {
  Site site;
  site.lat_deg = 30.26;
  site.lon_deg = 120.12;
  site.alt_m = 20.0;
  site.date = "2025-06-01";
  return geomag::site_field(geomag::MagneticModel::wmm2025(), site);
}

// The Earth's field in the pipeline's world (ENU, magnetic north), µT.
Vec3 earth(const geomag::SiteField& s) {
  const double f = s.elements.f_nT / 1000.0;
  return Vec3(0.0, f * std::cos(s.inclination), -f * std::sin(s.inclination));
}

// A magnetised mast as the simulator makes it: 12 equal dipoles on its axis up to 3.3 m, µT at p.
Vec3 mast(const Vec3& p, const Vec3& moment_Am2) {
  Vec3 b = Vec3::Zero();
  for (int k = 0; k < 12; ++k) {
    const Vec3 r = p - Vec3(0.0, 0.0, 0.144 + 0.2877 * k);
    const Vec3 u = r.normalized();
    b += 1e-7 * (3.0 * u * u.dot(moment_Am2) - moment_Am2) / std::pow(r.norm(), 3) * 1e6;
  }
  return b;
}

// Twelve photos on an arc 8 m from the mast at 1.5 m height, bearings 66°–84° (site 703's walk).
std::vector<Vec3> walk() {
  std::vector<Vec3> p;
  for (int i = 0; i < 12; ++i) {
    const double bearing = deg2rad(66.0 + 18.0 * i / 11.0);
    p.emplace_back(8.0 * std::sin(bearing), 8.0 * std::cos(bearing), 1.5);
  }
  return p;
}

std::vector<Vec3> with_noise(std::vector<Vec3> b, double sigma_uT, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma_uT);
  for (auto& v : b) v += Vec3(g(rng), g(rng), g(rng));
  return b;
}

TEST(FieldCheck, TheEarthsFieldAloneIsNotADisturbance) {
  const auto site = hangzhou();
  const auto c = check_field(with_noise(std::vector<Vec3>(12, earth(site)), 0.1, 1), site, {});
  EXPECT_FALSE(c.disturbed);
  EXPECT_TRUE(c.warnings.empty());
  EXPECT_EQ(c.heading_sigma_rad, 0.0);
  EXPECT_LT(c.strength_spread_fraction, 0.01);
  EXPECT_LT(rad2deg(c.dip_spread_rad), 0.5);
  ASSERT_EQ(c.strength_uT.size(), 12u);
  EXPECT_NEAR(c.strength_uT[0], site.elements.f_nT / 1000.0, 0.5);
}

// Site 703: the mast turns the compass by 3–5° yet stays within 4 % and 2° of WMM at every photo;
// its field changes along the walk, and that is seen.
TEST(FieldCheck, AMastsFieldChangingAlongTheWalkIsADisturbance) {
  const auto site = hangzhou();
  const Vec3 moment(508.0, 425.0, -392.0);
  std::vector<Vec3> b;
  double worst_turn = 0.0;
  for (const Vec3& p : walk()) {
    b.push_back(earth(site) + mast(p, moment));
    worst_turn = std::max(worst_turn, std::abs(std::atan2(b.back().x(), b.back().y())));
  }
  ASSERT_GT(rad2deg(worst_turn), 3.0);  // the case the WMM test alone missed
  const auto c = check_field(with_noise(b, 0.1, 2), site, {});
  EXPECT_LT(c.worst_strength_fraction, 0.04);
  EXPECT_LT(rad2deg(c.worst_dip_rad), 2.0);
  EXPECT_TRUE(c.disturbed);
  EXPECT_GT(c.strength_spread_fraction, 0.015);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("magnetic disturbance"));
  EXPECT_THAT(c.warnings[0], HasSubstr("varies between them"));
  // The estimate is of the right size (rather low: this mast's field is mostly across B).
  EXPECT_GT(c.heading_sigma_rad, worst_turn / 3);
  EXPECT_LT(c.heading_sigma_rad, 2 * worst_turn);
}

// What no magnetometer sees: the same horizontal turn at every photo, strength and dip unchanged.
TEST(FieldCheck, AUniformTurnOfTheHorizontalFieldIsInvisible) {
  const auto site = hangzhou();
  const Vec3 turned = Eigen::AngleAxisd(deg2rad(5.0), Vec3::UnitZ()) * earth(site);
  const auto c = check_field(with_noise(std::vector<Vec3>(12, turned), 0.1, 3), site, {});
  EXPECT_FALSE(c.disturbed);
}

TEST(FieldCheck, AFieldStrongerThanTheEarthsIsADisturbance) {
  const auto site = hangzhou();
  const auto c = check_field(std::vector<Vec3>(6, 1.06 * earth(site)), site, {});
  EXPECT_TRUE(c.disturbed);
  EXPECT_NEAR(c.worst_strength_fraction, 0.06, 1e-9);
  EXPECT_NEAR(c.strength_spread_fraction, 0.0, 1e-12);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("differs from the WMM's at the site by up to 6.0 % in strength"));
  // 6 % of F along B, none across: σ = 0.06 F / H.
  EXPECT_NEAR(c.heading_sigma_rad, 0.06 / std::cos(site.inclination), 1e-6);
}

TEST(FieldCheck, WithoutASiteThePhotosAreComparedWithEachOther) {
  const auto site = hangzhou();
  std::vector<Vec3> b;
  for (const Vec3& p : walk()) b.push_back(earth(site) + mast(p, Vec3(508.0, 425.0, -392.0)));
  const auto c = check_field(b, std::nullopt, {});
  EXPECT_FALSE(c.wmm_strength_uT.has_value());
  EXPECT_EQ(c.worst_strength_fraction, 0.0);
  EXPECT_TRUE(c.disturbed);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], ::testing::Not(HasSubstr("WMM's at the site by")));
  EXPECT_TRUE(check_field(std::vector<Vec3>(6, earth(site)), std::nullopt, {}).warnings.empty());
}

}  // namespace
}  // namespace antpose::measure
