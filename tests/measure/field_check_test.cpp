#include "antpose/measure/field_check.hpp"

#include <cmath>
#include <numbers>
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

// Each photo's field seen through a track whose tilt is off by up to `tilt_deg` (walking): turned
// about a random horizontal axis.
std::vector<Vec3> with_tilt_errors(std::vector<Vec3> b, double tilt_deg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(-deg2rad(tilt_deg), deg2rad(tilt_deg)), axis(0.0, 2 * std::numbers::pi);
  for (auto& v : b) {
    const double a = axis(rng);
    v = Eigen::AngleAxisd(angle(rng), Vec3(std::cos(a), std::sin(a), 0.0)) * v;
  }
  return b;
}

// Site 1612: from 20 m the mast's field is the same at every photo. It turns the compass by 3°
// and steepens the dip by 1.6°; with the walk's tilt errors every photo stays within 2° of WMM's
// dip and the photos agree, but their median dip does not agree with WMM's.
TEST(FieldCheck, AFieldTurnedAlikeAtEveryPhotoIsSeenInTheMedianDip) {
  const auto site = hangzhou();
  const Vec3 b0 = earth(site);
  const Vec3 east = Vec3::UnitX(), dip_direction = Vec3(0.0, std::sin(site.inclination), std::cos(site.inclination));
  const double h = b0.head<2>().norm(), f = b0.norm();
  const Vec3 b = b0 + h * std::tan(deg2rad(3.0)) * east - f * deg2rad(1.6) * dip_direction;
  const auto photos = with_noise(with_tilt_errors(std::vector<Vec3>(12, b), 0.35, 4), 0.1, 5);
  const auto c = check_field(photos, site, {});
  EXPECT_LT(rad2deg(c.worst_dip_rad), 2.0);
  EXPECT_LT(c.strength_spread_fraction, 0.015);
  EXPECT_LT(rad2deg(c.dip_spread_rad), 2.5);
  EXPECT_NEAR(rad2deg(c.median_dip_offset_rad), 1.6, 0.3);
  EXPECT_TRUE(c.disturbed);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("(median dip +1."));
  // Only the dip's part is seen: σ ≈ F · 1.6° / H, about half the turn's size again.
  EXPECT_GT(rad2deg(c.heading_sigma_rad), 2.0);

  // The same walk's tilt errors on the Earth's field alone raise no warning.
  const auto clean = check_field(with_noise(with_tilt_errors(std::vector<Vec3>(12, b0), 0.35, 4), 0.1, 5), site, {});
  EXPECT_FALSE(clean.disturbed);
  EXPECT_LT(std::abs(rad2deg(clean.median_dip_offset_rad)), 0.3);
}

// Site 1306: an 18 m mast magnetised as the simulator makes it (12 dipoles up its axis, induced
// along the Earth's field plus a horizontal remanent part), scaled to turn the compass by 4.5° at
// a walk on an arc 3 m round a board 14 m away. The turn is nearly the same at every photo,
// strength and dip stay near WMM's and spread little; only the strength's fall-off towards the
// mast is seen, as a trend over where the photos were taken.
TEST(FieldCheck, AStrengthChangingWithThePhonesPositionIsADisturbance) {
  const auto site = hangzhou();
  const Vec3 b0 = earth(site);
  auto tall_mast = [](const Vec3& p, const Vec3& moment_Am2) {
    Vec3 b = Vec3::Zero();
    for (int k = 0; k < 12; ++k) {
      const Vec3 r = p - Vec3(0.0, 0.0, 18.0 * (k + 0.5) / 12.0);
      const Vec3 u = r.normalized();
      b += 1e-7 * (3.0 * u * u.dot(moment_Am2) - moment_Am2) / std::pow(r.norm(), 3) * 1e6;
    }
    return b;
  };
  const double bearing = deg2rad(120.0);
  const Vec3 board(14.0 * std::sin(bearing), 14.0 * std::cos(bearing), 1.2);
  std::vector<Vec3> where;
  for (int i = 0; i < 12; ++i) {
    const double phi = bearing + deg2rad(-35.0 + 70.0 * i / 11.0);
    where.push_back(board - 3.0 * Vec3(std::sin(phi), std::cos(phi), -0.02 * (i % 3)));
  }
  const Vec3 direction = (b0.normalized() - Vec3::UnitY()).normalized();
  const Vec3 unit = tall_mast(where[6], direction);
  const double h = b0.head<2>().norm(), t = std::tan(deg2rad(4.5));
  const Vec3 moment = direction * (t * h / (unit.x() - t * unit.y()));  // (h ŷ + s unit) turned by 4.5°
  std::vector<Vec3> b;
  double least_turn = 90.0;
  for (const Vec3& p : where) {
    b.push_back(b0 + tall_mast(p, moment));
    least_turn = std::min(least_turn, std::abs(rad2deg(std::atan2(b.back().x(), b.back().y()))));
  }
  ASSERT_GT(least_turn, 3.5);
  const auto photos = with_noise(with_tilt_errors(b, 0.35, 6), 0.08, 7);  // 25 samples of 0.4 µT noise
  const auto blind = check_field(photos, site, {});                       // tests 1–3 only
  EXPECT_FALSE(blind.disturbed) << blind.worst_strength_fraction << " " << rad2deg(blind.worst_dip_rad) << " "
                                << blind.strength_spread_fraction << " " << rad2deg(blind.median_dip_offset_rad);
  const auto c = check_field(photos, site, {}, where);
  EXPECT_GT(c.strength_trend_fraction, 0.005);
  EXPECT_GT(c.trend_f_statistic, 10.0);
  EXPECT_TRUE(c.disturbed);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("% along the walk"));

  // Without the mast the same walk shows no trend.
  const auto clean =
      check_field(with_noise(with_tilt_errors(std::vector<Vec3>(12, b0), 0.35, 6), 0.08, 7), site, {}, where);
  EXPECT_FALSE(clean.disturbed);
  EXPECT_LT(clean.strength_trend_fraction, 0.005);

  // A walk along a line fits one slope; the positions' count must match the fields'.
  std::vector<Vec3> line;
  for (int i = 0; i < 12; ++i) line.emplace_back(0.0, 12.0 + 0.4 * i, 1.2);
  EXPECT_GT(check_field(photos, site, {}, line).trend_f_statistic, 0.0);
  EXPECT_THROW(check_field(photos, site, {}, std::vector<Vec3>(3, Vec3::Zero())), std::invalid_argument);
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
