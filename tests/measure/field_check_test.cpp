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

// From 20 m, a mast's field is the same at every photo. It turns the compass by 3°
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

// The Earth's field plus the residuals of the fields `b` about a linear fit over the positions:
// the same scatter, without the trend.
std::vector<Vec3> earth_with_residuals(const std::vector<Vec3>& b, const std::vector<Vec3>& where,
                                       const geomag::SiteField& site) {
  const auto n = static_cast<Eigen::Index>(b.size());
  Eigen::MatrixXd A(n, 3), y(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    A.row(i) << 1.0, where[k].x(), where[k].y();
    y.row(i) = b[k].transpose();
  }
  const Eigen::MatrixXd r = y - A * A.colPivHouseholderQr().solve(y);
  std::vector<Vec3> out;
  for (Eigen::Index i = 0; i < n; ++i) out.push_back(earth(site) + r.row(i).transpose());
  return out;
}

// Site 1712 as `antpose measure` saw it (its JSON's magnetic_field: each photo's field through
// the board's attitude, and where the photo was taken): a 14.4 m mast 17 m from the walk turned
// the compass by 4.5–5.2°. Its strength changes by 0.9 % along the walk, but the calibration's
// errors (0.12 µT) leave that trend below significance (F 7.9), and the median dip lies 0.8° off
// WMM's, within the 1° limit. The vector turns too: its trend, 1.7 % with F 14, is seen.
TEST(FieldCheck, AFieldVectorChangingWithThePhonesPositionIsADisturbance) {
  const auto site = hangzhou();
  const std::vector<std::pair<Vec3, Vec3>> photos{
      {{-0.013, 35.747, -35.706}, {0.929, 3.045, -0.104}}, {{0.081, 35.663, -35.759}, {1.259, 2.935, -0.095}},
      {{-0.038, 35.684, -35.876}, {1.452, 2.711, -0.121}}, {{0.029, 35.600, -35.842}, {1.615, 2.463, -0.082}},
      {{0.125, 35.663, -35.991}, {1.573, 2.068, -0.047}},  {{0.119, 35.326, -36.042}, {2.002, 2.013, -0.133}},
      {{0.029, 35.376, -35.873}, {2.228, 1.808, -0.053}},  {{0.154, 35.240, -35.897}, {2.179, 1.422, -0.127}},
      {{0.280, 35.073, -35.726}, {2.406, 1.218, -0.139}},  {{0.313, 35.440, -35.820}, {2.450, 0.900, -0.117}},
      {{0.171, 35.110, -35.845}, {2.784, 0.756, -0.057}},  {{0.781, 35.149, -35.856}, {2.593, 0.311, -0.093}}};
  std::vector<Vec3> b, where;
  for (const auto& [field, p] : photos) b.push_back(field), where.push_back(p);
  FieldCheckOptions without_vector;
  without_vector.vector_trend = 1.0;
  without_vector.joint_tolerance = 10.0;
  const auto blind = check_field(b, site, without_vector, where);  // tests 1–4 only
  EXPECT_FALSE(blind.disturbed);
  EXPECT_NEAR(100 * blind.strength_trend_fraction, 0.90, 0.01);
  EXPECT_NEAR(blind.trend_f_statistic, 7.9, 0.1);
  without_vector.joint_tolerance = FieldCheckOptions{}.joint_tolerance;  // tests 1–4 together see it
  EXPECT_TRUE(check_field(b, site, without_vector, where).disturbed);
  const auto c = check_field(b, site, {}, where);
  EXPECT_NEAR(100 * c.vector_trend_fraction, 1.66, 0.01);
  EXPECT_NEAR(c.vector_trend_f_statistic, 14.1, 0.1);
  EXPECT_TRUE(c.disturbed);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("the field vector changing by 1.7 % of its strength along the walk"));
  // The estimate covers the fitted change at least: 1.7 % of F over H.
  EXPECT_GE(c.heading_sigma_rad, c.vector_trend_fraction * c.strength_uT[0] / (earth(site).head<2>().norm() * 1.02));
  ASSERT_EQ(c.field_world_uT.size(), 12u);
  EXPECT_EQ(c.p_world_m.size(), 12u);

  // The Earth's field with the same scatter about it (the linear fit's residuals), no trend: clean.
  const auto fit_residuals = earth_with_residuals(b, where, site);
  const auto clean = check_field(fit_residuals, site, {}, where);
  EXPECT_LT(clean.vector_trend_fraction, 0.01);
  EXPECT_FALSE(clean.disturbed);
}

// A simulated site as `antpose measure` saw it: a magnetised mast turned the compass by 3.45° at
// every photo. Each test alone stays within its limit (at 0.4–0.85 of it): the strength 2 % below
// WMM's, the median dip 0.64° steep, the vector's change along the walk 1.24 % with F 6.8. Each
// sees another part of the one perturbation; together they are beyond what the Earth's field
// with its noise gives.
TEST(FieldCheck, TestsNearTheirLimitsTogetherAreADisturbance) {
  const auto site = hangzhou();
  const std::vector<std::pair<Vec3, Vec3>> photos{
      {{0.181, 32.506, -34.965}, {-1.339, -2.212, -0.148}},  {{0.295, 32.630, -34.995}, {-1.734, -2.183, -0.204}},
      {{-0.014, 32.870, -35.007}, {-1.551, -1.854, -0.161}}, {{0.020, 32.629, -34.968}, {-1.708, -1.699, -0.182}},
      {{0.009, 32.941, -34.871}, {-1.781, -1.502, -0.140}},  {{0.000, 32.823, -34.752}, {-2.024, -1.381, -0.226}},
      {{0.106, 32.754, -34.889}, {-2.142, -1.200, -0.163}},  {{-0.053, 32.743, -34.953}, {-2.087, -0.950, -0.139}},
      {{-0.033, 33.010, -35.122}, {-2.425, -0.854, -0.194}}, {{-0.182, 32.875, -35.046}, {-2.198, -0.544, -0.185}},
      {{-0.279, 33.009, -34.956}, {-2.152, -0.307, -0.158}}, {{-0.219, 32.873, -35.047}, {-2.219, -0.111, -0.217}}};
  std::vector<Vec3> b, where;
  for (const auto& [field, p] : photos) b.push_back(field), where.push_back(p);
  FieldCheckOptions single;
  single.joint_tolerance = 10.0;
  EXPECT_FALSE(check_field(b, site, single, where).disturbed);
  const auto c = check_field(b, site, {}, where);
  for (const double r : c.test_ratios) {
    EXPECT_GT(r, 0.3);
    EXPECT_LT(r, 1.0);
  }
  EXPECT_NEAR(c.joint_ratio, 1.4, 0.1);
  EXPECT_TRUE(c.disturbed);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_THAT(c.warnings[0], HasSubstr("every test is within its limit, but together they are not"));
  // The σ from what is seen (the strength's 2 % off WMM's, over H) is of the turn's size.
  EXPECT_GT(rad2deg(c.heading_sigma_rad), 3.45 / 2);
  EXPECT_LT(rad2deg(c.heading_sigma_rad), 2 * 3.45);

  // The Earth's field with the same scatter about the fit over the walk: clean.
  const auto clean = check_field(earth_with_residuals(b, where, site), site, {}, where);
  EXPECT_LT(clean.joint_ratio, 1.0);
  EXPECT_FALSE(clean.disturbed);
  EXPECT_EQ(clean.heading_sigma_rad, 0.0);
}

TEST(FieldCheck, OptionsSayWhatIsWrongWithThem) {
  FieldCheckOptions o;
  EXPECT_TRUE(o.Check().ok());
  o.joint_tolerance = 0.0;
  o.dip_spread = std::nan("");
  const auto p = o.Check();
  ASSERT_EQ(p.list().size(), 2u);
  EXPECT_THAT(p.message(), HasSubstr("joint_tolerance: positive"));
  EXPECT_THAT(p.message(), HasSubstr("dip_spread: positive"));
  EXPECT_THROW(check_field({earth(hangzhou())}, std::nullopt, o), std::invalid_argument);
}

// The field at a photo comes through the photo's own attitude (from the board), the track only
// carrying the samples around it to the photo's instant: a track whose heading and tilt are off
// by degrees does not move the field, a turn of the phone during the window is undone.
TEST(FieldCheck, TheFieldAtAPhotoTakesThePhotosAttitudeFromTheBoard) {
  const auto site = hangzhou();
  const Vec3 b_world = earth(site);
  // The phone turns about its z axis at 20°/s; the track has it right but for a constant error.
  const auto R_world_device = [](double t) {
    return Mat3(Eigen::AngleAxisd(deg2rad(30.0), Vec3::UnitX()) * Eigen::AngleAxisd(deg2rad(20.0 * t), Vec3::UnitZ()));
  };
  const Mat3 track_error =
      (Eigen::AngleAxisd(deg2rad(4.0), Vec3::UnitZ()) * Eigen::AngleAxisd(deg2rad(1.5), Vec3::UnitX()))
          .toRotationMatrix();
  orientation::ImuData data;
  orientation::OrientationTrack track;
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.01 * i;
    track.push_back(t, Quat(track_error * R_world_device(t)));
    if (i % 2 == 0) {
      data.magnetometer.t.push_back(t);
      data.magnetometer.v.push_back(R_world_device(t).transpose() * b_world);
    }
  }
  const std::vector<double> t_photos{1.0, 2.0, 3.9, 5.0};
  std::vector<Mat3> attitudes;
  for (const double t : t_photos) attitudes.push_back(R_world_device(t));
  const auto fields = field_at_photos(data, track, t_photos, attitudes, 0.25);
  ASSERT_EQ(fields.size(), 4u);
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(fields[k].has_value()) << k;
    EXPECT_LT((*fields[k] - b_world).norm(), 1e-6) << k;  // window cut at the track's end for k = 2
  }
  EXPECT_FALSE(fields[3].has_value());  // outside the track
  EXPECT_THROW(field_at_photos(data, track, t_photos, {attitudes[0]}, 0.25), std::invalid_argument);
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
