#include "antpose/geomag/wmm.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::geomag {
namespace {

using ::testing::HasSubstr;

const MagneticModel& wmm2025() {
  static const MagneticModel model = MagneticModel::wmm2025();
  return model;
}

// One checked column of a NOAA table: CSV name, accessor and tolerance.
struct Column {
  std::string name;
  std::function<std::optional<double>(const GeomagneticElements&)> get;
  double tolerance;
};

std::vector<Column> columns(double nT, double deg, double nT_per_yr, double deg_per_yr) {
  return {
      {"X_nT", [](const auto& e) { return std::optional(e.x_nT); }, nT},
      {"Y_nT", [](const auto& e) { return std::optional(e.y_nT); }, nT},
      {"Z_nT", [](const auto& e) { return std::optional(e.z_nT); }, nT},
      {"H_nT", [](const auto& e) { return std::optional(e.h_nT); }, nT},
      {"F_nT", [](const auto& e) { return std::optional(e.f_nT); }, nT},
      {"D_deg", [](const auto& e) { return std::optional(e.declination_deg); }, deg},
      {"I_deg", [](const auto& e) { return std::optional(e.inclination_deg); }, deg},
      {"Xdot_nT_per_yr", [](const auto& e) { return std::optional(e.x_dot_nT_per_yr); }, nT_per_yr},
      {"Ydot_nT_per_yr", [](const auto& e) { return std::optional(e.y_dot_nT_per_yr); }, nT_per_yr},
      {"Zdot_nT_per_yr", [](const auto& e) { return std::optional(e.z_dot_nT_per_yr); }, nT_per_yr},
      {"Hdot_nT_per_yr", [](const auto& e) { return std::optional(e.h_dot_nT_per_yr); }, nT_per_yr},
      {"Fdot_nT_per_yr", [](const auto& e) { return std::optional(e.f_dot_nT_per_yr); }, nT_per_yr},
      {"Ddot_deg_per_yr", [](const auto& e) { return std::optional(e.declination_dot_deg_per_yr); }, deg_per_yr},
      {"Idot_deg_per_yr", [](const auto& e) { return std::optional(e.inclination_dot_deg_per_yr); }, deg_per_yr},
  };
}

// Checks every row and every listed column of a NOAA table; returns the largest deviation
// per column. `NaN` in the table means "not defined" and must match an empty optional.
std::map<std::string, double> check_table(const MagneticModel& model, const std::string& relative,
                                          const std::vector<Column>& cols, std::size_t expected_rows) {
  const auto csv = io::read_csv(test::shared_path(relative));
  EXPECT_EQ(csv.rows.size(), expected_rows) << relative;
  const auto num = [&](std::size_t row, std::string_view column) {
    return io::parse_number(csv.rows[row][csv.column(column)], csv.file, csv.lines[row], column,
                            io::NonFinite::kAllow);
  };
  std::map<std::string, double> max_dev;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const double year = num(i, "date_yr"), alt = num(i, "height_km");
    const double lat = num(i, "lat_deg"), lon = num(i, "lon_deg");
    const auto e = model.evaluate(lat, lon, alt, year);
    for (const auto& col : cols) {
      const double expected = num(i, col.name);
      const auto got = col.get(e);
      const std::string where = fmt::format("{} line {} ({} km, {}, {}, {}) column {}", relative, csv.lines[i], alt,
                                            lat, lon, year, col.name);
      if (std::isnan(expected)) {
        EXPECT_FALSE(got.has_value()) << where;
        continue;
      }
      EXPECT_TRUE(got.has_value()) << where;
      if (!got) continue;
      EXPECT_NEAR(*got, expected, col.tolerance) << where;
      max_dev[col.name] = std::max(max_dev[col.name], std::abs(*got - expected));
    }
  }
  return max_dev;
}

void report(const std::string& table, const std::map<std::string, double>& dev) {
  for (const char* c : {"D_deg", "I_deg", "F_nT", "X_nT", "Y_nT", "Z_nT", "H_nT"})
    if (dev.count(c)) std::printf("[ max dev  ] %s %s = %.3g\n", table.c_str(), c, dev.at(c));
}

// --- NOAA tables -------------------------------------------------------------------------

TEST(WmmTables, Wmm2025ReportTableAllTwelveRows) {
  auto cols = columns(0.06, 0.006, 0.06, 0.006);
  cols.push_back({"GV_deg", [](const auto& e) { return e.grid_variation_deg; }, 0.006});
  const auto dev = check_table(wmm2025(), "data/geomagnetism/wmm2025/test-values.csv", cols, 12);
  EXPECT_EQ(dev.size(), cols.size());  // every column was compared at least once
  report("WMM2025 12-row", dev);
}

TEST(WmmTables, Wmm2025HighPrecisionTableAllHundredRows) {
  // nT printed to 1e-6; the table's X/H/F differ from the report's equations by up to 7.2e-4 nT
  // (see the data README), hence 1e-3 nT. D and I are printed to 0.01 deg.
  const auto cols = columns(1e-3, 0.006, 1e-5, 1e-5);
  const auto dev = check_table(wmm2025(), "data/geomagnetism/wmm2025/test-values-100.csv", cols, 100);
  EXPECT_EQ(dev.size(), cols.size());
  EXPECT_LT(dev.at("Y_nT"), 1e-5);  // Y matches to the printed digit
  report("WMM2025 100-row", dev);
}

TEST(WmmTables, Wmm2020TableAllHundredRowsWithItsOwnCoefficients) {
  const auto model = MagneticModel::from_file(test::shared_path("data/geomagnetism/wmm2025/wmm2020/WMM.COF"));
  EXPECT_EQ(model.name(), "WMM-2020");
  EXPECT_DOUBLE_EQ(model.epoch(), 2020.0);
  // Printed to 0.1 nT, 0.01 deg, and every rate (deg/yr included) to 0.1.
  const auto cols = columns(0.06, 0.006, 0.06, 0.06);
  const auto dev = check_table(model, "data/geomagnetism/wmm2025/wmm2020/test-values-100.csv", cols, 100);
  EXPECT_EQ(dev.size(), cols.size());
  report("WMM2020 100-row", dev);
}

TEST(WmmModel, BuiltInEqualsSharedCoefficientFile) {
  const auto file = MagneticModel::from_file(test::shared_path("data/geomagnetism/wmm2025/WMM.COF"));
  const auto& built_in = wmm2025();
  EXPECT_EQ(built_in.name(), "WMM-2025");
  EXPECT_EQ(built_in.release_date(), "11/13/2024");
  EXPECT_DOUBLE_EQ(built_in.epoch(), 2025.0);
  EXPECT_DOUBLE_EQ(built_in.valid_until(), 2030.0);
  EXPECT_EQ(built_in.max_degree(), 12);
  EXPECT_DOUBLE_EQ(built_in.coefficient(1, 0).g, -29351.8);
  EXPECT_DOUBLE_EQ(built_in.coefficient(1, 1).h, 4545.4);
  EXPECT_DOUBLE_EQ(built_in.coefficient(12, 12).h_dot, -0.1);
  EXPECT_THROW(built_in.coefficient(13, 0), std::out_of_range);
  for (int n = 1; n <= 12; ++n)
    for (int m = 0; m <= n; ++m) {
      EXPECT_EQ(built_in.coefficient(n, m).g, file.coefficient(n, m).g);
      EXPECT_EQ(built_in.coefficient(n, m).h_dot, file.coefficient(n, m).h_dot);
    }
}

// --- Poles -------------------------------------------------------------------------------

// At the poles (x = sin φ' = ±1) the Legendre terms are closed-form, with s_n = sqrt(n(n+1)/2):
// P_n^0 = x^n; P_n^1 / cos φ' → x^(n+1) s_n (the singular Y' term); dP_n^1/dφ' → −x^n s_n; all
// other terms of X', Y', Z' vanish. This checks the pole independently of the recursion.
struct PoleField {
  double x, y, z;
};

PoleField closed_form_pole(const MagneticModel& model, bool north, double lon_deg, double alt_km, bool rates) {
  const double f = 1.0 / kWgs84InverseFlattening;
  const double r = kWgs84SemiMajorKm * (1.0 - f) + alt_km;
  const double lam = deg2rad(lon_deg);
  PoleField out{0, 0, 0};
  for (int n = 1; n <= model.max_degree(); ++n) {
    const double pw = std::pow(kWmmReferenceRadiusKm / r, n + 2);
    const double s_n = std::sqrt(n * (n + 1) / 2.0);
    const double sign_n = north ? 1.0 : (n % 2 == 0 ? 1.0 : -1.0);  // (±1)^n
    const auto& c0 = model.coefficient(n, 0);
    const auto& c1 = model.coefficient(n, 1);
    const double g0 = rates ? c0.g_dot : c0.g;
    const double g1 = rates ? c1.g_dot : c1.g;
    const double h1 = rates ? c1.h_dot : c1.h;
    out.z += -(n + 1) * pw * g0 * sign_n;
    out.y += pw * (g1 * std::sin(lam) - h1 * std::cos(lam)) * s_n * (north ? 1.0 : -sign_n);
    out.x += pw * (g1 * std::cos(lam) + h1 * std::sin(lam)) * s_n * sign_n;
  }
  return out;
}

TEST(WmmPoles, FieldAtGeographicPolesMatchesClosedFormLimit) {
  const auto& model = wmm2025();
  for (const bool north : {true, false})
    for (const double lon : {0.0, 37.0, 120.0, -100.0}) {
      SCOPED_TRACE(fmt::format("{} pole, lon {}", north ? "north" : "south", lon));
      const auto e = model.evaluate(north ? 90.0 : -90.0, lon, 5.0, model.epoch());
      const auto expect = closed_form_pole(model, north, lon, 5.0, false);
      const auto expect_dot = closed_form_pole(model, north, lon, 5.0, true);
      ASSERT_TRUE(std::isfinite(e.y_nT) && std::isfinite(e.declination_deg));
      EXPECT_NEAR(e.x_nT, expect.x, 1e-6);
      EXPECT_NEAR(e.y_nT, expect.y, 1e-6);
      EXPECT_NEAR(e.z_nT, expect.z, 1e-6);
      EXPECT_NEAR(e.x_dot_nT_per_yr, expect_dot.x, 1e-8);
      EXPECT_NEAR(e.y_dot_nT_per_yr, expect_dot.y, 1e-8);
      EXPECT_NEAR(e.z_dot_nT_per_yr, expect_dot.z, 1e-8);
    }
}

TEST(WmmPoles, PoleIsContinuousAndGridVariationIndependentOfLongitude) {
  const auto& model = wmm2025();
  for (const double pole : {90.0, -90.0}) {
    std::optional<double> gv0, h0;
    for (const double lon : {0.0, 45.0, 160.0, -75.0}) {
      const auto at = model.evaluate(pole, lon, 0.0, 2027.0);
      const auto near = model.evaluate(pole - std::copysign(1e-7, pole), lon, 0.0, 2027.0);
      EXPECT_NEAR(at.x_nT, near.x_nT, 1e-3);
      EXPECT_NEAR(at.y_nT, near.y_nT, 1e-3);
      EXPECT_NEAR(at.z_nT, near.z_nT, 1e-3);
      // On the pole only the meridian that defines "north" changes with the longitude: the
      // horizontal field, and the declination relative to grid north, stay the same.
      ASSERT_TRUE(at.grid_variation_deg);
      if (!gv0) gv0 = at.grid_variation_deg, h0 = at.h_nT;
      EXPECT_NEAR(*at.grid_variation_deg, *gv0, 1e-9) << pole << " " << lon;
      EXPECT_NEAR(at.h_nT, *h0, 1e-8);
    }
  }
}

TEST(WmmElements, GridVariationOnlyPolewardOf55Degrees) {
  const auto& model = wmm2025();
  EXPECT_FALSE(model.evaluate(54.99, 10, 0, 2026).grid_variation_deg);
  EXPECT_FALSE(model.evaluate(-54.99, 10, 0, 2026).grid_variation_deg);
  const auto n = model.evaluate(55.0, 10, 0, 2026);
  ASSERT_TRUE(n.grid_variation_deg && n.grid_variation_dot_deg_per_yr);
  EXPECT_NEAR(*n.grid_variation_deg, n.declination_deg - 10.0, 1e-12);
  EXPECT_DOUBLE_EQ(*n.grid_variation_dot_deg_per_yr, n.declination_dot_deg_per_yr);
  const auto s = model.evaluate(-70.0, 200.0, 0, 2026);
  ASSERT_TRUE(s.grid_variation_deg);
  const double gv = s.declination_deg + 200.0 - 360.0 * std::round((s.declination_deg + 200.0) / 360.0);
  EXPECT_NEAR(*s.grid_variation_deg, gv, 1e-12);
  EXPECT_GT(*s.grid_variation_deg, -180.0);
  EXPECT_LE(*s.grid_variation_deg, 180.0);
}

TEST(WmmElements, LongitudeIsPeriodic) {
  const auto a = wmm2025().evaluate(-33.0, -120.0, 1.0, 2028.3);
  const auto b = wmm2025().evaluate(-33.0, 240.0, 1.0, 2028.3);
  EXPECT_NEAR(a.x_nT, b.x_nT, 1e-8);
  EXPECT_NEAR(a.y_nT, b.y_nT, 1e-8);
  EXPECT_NEAR(a.z_nT, b.z_nT, 1e-8);
}

// --- Input checks -------------------------------------------------------------------------

std::string invalid_argument_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return {};
}

TEST(WmmElements, RejectsPositionsOutsideTheModel) {
  const auto& m = wmm2025();
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(90.5, 0, 0, 2025.5); }),
              HasSubstr("latitude 90.5 deg is outside [-90, 90]"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(-91, 0, 0, 2025.5); }), HasSubstr("latitude -91"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(10, 0, 851, 2025.5); }),
              HasSubstr("height 851 km is outside the model's range [-1, 850] km"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(10, 0, -1.5, 2025.5); }), HasSubstr("height -1.5 km"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(10, NAN, 0, 2025.5); }), HasSubstr("longitude nan"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(10, 1e16, 0, 2025.5); }),
              HasSubstr("longitude 1e+16 deg is outside [-360, 360]"));
  EXPECT_THAT(invalid_argument_message([&] { m.evaluate(10, 0, 0, INFINITY); }), HasSubstr("decimal year inf"));
  EXPECT_NO_THROW(m.evaluate(10, 0, -1.0, 2025.5));
  EXPECT_NO_THROW(m.evaluate(10, 0, 850.0, 2025.5));
}

TEST(WmmModel, ValidityIsTheFiveYearSpan) {
  const auto& m = wmm2025();
  EXPECT_TRUE(m.valid_for(2025.0));
  EXPECT_TRUE(m.valid_for(2029.999));
  EXPECT_FALSE(m.valid_for(2030.0));
  EXPECT_FALSE(m.valid_for(2024.99));
  EXPECT_FALSE(m.validity_warning(2027.0));
  const auto w = m.validity_warning(2031.25);
  ASSERT_TRUE(w);
  EXPECT_THAT(*w, HasSubstr("date 2031.250 is outside the validity of WMM-2025 (2025.0 to 2030.0)"));
  // Outside the span the model still evaluates (callers warn).
  EXPECT_NO_THROW(m.evaluate(10, 0, 0, 2031.25));
}

TEST(WmmDates, DecimalYearIsDayOfYearBased) {
  EXPECT_DOUBLE_EQ(decimal_year(2025, 1, 1), 2025.0);
  EXPECT_DOUBLE_EQ(decimal_year(2024, 7, 2), 2024.5);  // day 184 of 366
  EXPECT_DOUBLE_EQ(decimal_year(2025, 12, 31), 2025.0 + 364.0 / 365.0);
  EXPECT_DOUBLE_EQ(decimal_year(2024, 3, 1), 2024.0 + 60.0 / 366.0);
  EXPECT_DOUBLE_EQ(decimal_year(2000, 2, 29), 2000.0 + 59.0 / 366.0);
  EXPECT_DOUBLE_EQ(decimal_year_from_iso("2027-07-02"), 2027.0 + 182.0 / 365.0);
}

TEST(WmmDates, InvalidDatesAreRejectedWithTheReason) {
  const auto msg = [](std::string_view d) { return invalid_argument_message([&] { decimal_year_from_iso(d); }); };
  EXPECT_THAT(msg("2025-02-30"), HasSubstr("'2025-02-30' is not a valid date: day 30 is outside 1..28 for 2025-02"));
  EXPECT_THAT(msg("2025-02-29"), HasSubstr("day 29 is outside 1..28"));
  EXPECT_THAT(msg("1900-02-29"), HasSubstr("day 29 is outside 1..28"));
  EXPECT_THAT(msg("2025-13-01"), HasSubstr("'2025-13-01' is not a valid date: month 13 is outside 1..12"));
  EXPECT_THAT(msg("2025-00-10"), HasSubstr("month 0 is outside 1..12"));
  EXPECT_THAT(msg("2025-04-31"), HasSubstr("day 31 is outside 1..30"));
  EXPECT_THAT(msg("0000-01-01"), HasSubstr("year 0 is outside 1..9999"));
  for (const char* bad : {"2025/01/01", "25-01-01", "2025-1-01", "", "2025-01-01T00:00", "2025-0a-01"})
    EXPECT_THAT(msg(bad), HasSubstr("wrong format (expected YYYY-MM-DD)")) << bad;
  EXPECT_NO_THROW(decimal_year_from_iso("2024-02-29"));
}

TEST(WmmDates, TodayIsAValidIsoDate) {
  const auto today = today_utc_iso();
  EXPECT_EQ(today.size(), 10u);
  EXPECT_GT(decimal_year_from_iso(today), 2024.0);
}

// --- Conversions for the rest of antpose -----------------------------------------------

TEST(WmmEnu, FieldInEnuMicroTesla) {
  // Report table row: 2025.0, 0 km, 80N 0E: X 6521.6, Y 145.9, Z 54791.5 nT.
  const auto e = wmm2025().evaluate(80.0, 0.0, 0.0, 2025.0);
  const Vec3 b = field_enu_uT(e);
  EXPECT_NEAR(b.x(), 0.1459, 1e-4);   // east
  EXPECT_NEAR(b.y(), 6.5216, 1e-4);   // north
  EXPECT_NEAR(b.z(), -54.7915, 1e-4);  // up: the field points down in the north
  EXPECT_NEAR(b.norm(), e.f_nT / 1000.0, 1e-12);
  EXPECT_NEAR(rad2deg(std::atan2(b.x(), b.y())), e.declination_deg, 1e-12);
  EXPECT_NEAR(rad2deg(std::atan2(-b.z(), b.head<2>().norm())), e.inclination_deg, 1e-12);
}

TEST(WmmEnu, SiteFieldUsesMetresAndIsoDate) {
  Site site;
  site.lat_deg = -80.0;
  site.lon_deg = 240.0;
  site.alt_m = 100000.0;
  site.date = "2025-01-01";
  const auto f = site_field(wmm2025(), site);
  // Report table: 2025.0, 100 km, 80S 240E: D 68.21, I -72.19, F 52035.0.
  EXPECT_NEAR(rad2deg(f.declination), 68.21, 0.006);
  EXPECT_NEAR(rad2deg(f.inclination), -72.19, 0.006);
  EXPECT_NEAR(f.field_enu_uT.norm(), 52.0350, 6e-5);
  EXPECT_GT(f.field_enu_uT.z(), 0.0);  // southern hemisphere: field points up
  EXPECT_DOUBLE_EQ(f.decimal_year, 2025.0);
  EXPECT_FALSE(f.validity_warning);

  site.date = "2032-03-01";
  const auto late = site_field(wmm2025(), site);
  ASSERT_TRUE(late.validity_warning);
  EXPECT_THAT(*late.validity_warning, HasSubstr("outside the validity of WMM-2025"));

  site.date = "2025-02-30";
  EXPECT_THAT(invalid_argument_message([&] { site_field(wmm2025(), site); }), HasSubstr("'2025-02-30'"));
  site.date.clear();
  EXPECT_THAT(invalid_argument_message([&] { site_field(wmm2025(), site); }), HasSubstr("site has no date"));
}

// --- Coefficient file errors ------------------------------------------------------------

std::vector<std::string> cof_lines() {
  const std::string text = io::read_text(test::shared_path("data/geomagnetism/wmm2025/WMM.COF"));
  std::vector<std::string> lines;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const auto end = text.find('\n', pos);
    lines.push_back(text.substr(pos, end - pos));
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return lines;
}

std::string join(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

std::string cof_error(const std::string& text) {
  try {
    MagneticModel::from_cof_text(text, "bad.COF");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

TEST(WmmCof, ParsesTheUnmodifiedFileAndCrlf) {
  auto lines = cof_lines();
  ASSERT_EQ(lines.size(), 93u);  // header, 90 coefficients, two lines of 9s
  EXPECT_NO_THROW(MagneticModel::from_cof_text(join(lines), "ok.COF"));
  std::string crlf;
  for (const auto& l : lines) crlf += l + "\r\n";
  const auto m = MagneticModel::from_cof_text(crlf, "crlf.COF");
  EXPECT_EQ(m.release_date(), "11/13/2024");
  EXPECT_DOUBLE_EQ(m.coefficient(12, 12).g, -0.7);
}

TEST(WmmCof, MalformedNumberNamesFileAndLine) {
  auto lines = cof_lines();
  lines[2] = "  1  1   -1410.8    45x5.4        9.7      -21.5";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:3: column 'h': '45x5.4' is not a number"));
  lines = cof_lines();
  lines[4] = "  2  1.5   -1410.8    4545.4        9.7      -21.5";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:5: column 'm': '1.5' is not an integer"));
}

TEST(WmmCof, WrongDegreeOrOrderNamesTheExpectedOne) {
  auto lines = cof_lines();
  lines.erase(lines.begin() + 2);  // drop n=1 m=1
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:3: unexpected degree/order n=2 m=0: expected n=1 m=1"));
}

TEST(WmmCof, MissingLinesAreReported) {
  auto lines = cof_lines();
  lines.erase(lines.begin() + 90);  // drop n=12 m=12, keep the closing 9s
  EXPECT_THAT(cof_error(join(lines)),
              HasSubstr("bad.COF:91: coefficients end inside degree 12: missing lines from n=12 m=12"));
  lines = cof_lines();
  lines.resize(50);  // truncated file, no closing line
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:50: missing lines: the file ends after n=9 m=4"));
  EXPECT_THAT(cof_error(join({lines[0], std::string(48, '9')})), HasSubstr("bad.COF:2: no coefficient lines"));
}

TEST(WmmCof, BadHeaderAndFieldCountAndNonZeroH0) {
  auto lines = cof_lines();
  lines[0] = "WMM-2025 2025.0 11/13/2024";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:1: column 'epoch': 'WMM-2025' is not a number"));
  lines[0] = "2025.0";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:1: bad header '2025.0'"));
  lines = cof_lines();
  lines[3] = "  2  0   -2556.6       0.0       -11.6";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:4: 5 fields, expected 6"));
  lines = cof_lines();
  lines[3] = "  2  0   -2556.6       1.0       -11.6        0.0";
  EXPECT_THAT(cof_error(join(lines)), HasSubstr("bad.COF:4: h and hdot must be 0 for m=0 (n=2)"));
  EXPECT_THAT(cof_error("\n\n"), HasSubstr("bad.COF: empty coefficient file"));
}

TEST(WmmCof, MissingFileIsAnInputErrorNamingIt) {
  test::TempDir dir;
  try {
    MagneticModel::from_file(dir / "nope.COF");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("nope.COF"));
  }
}

}  // namespace
}  // namespace antpose::geomag
