#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/geomag/wmm.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(WmmCli, PrintsElementsWithUnitsAndModel) {
  // Report table row: 2025.0, 0 km, 80N 0E.
  const auto r = test::run_cli("wmm --lat 80 --lon 0 --date 2025-01-01");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("WMM-2025"));
  EXPECT_THAT(r.out, HasSubstr("declination D:         1.28 deg"));
  EXPECT_THAT(r.out, HasSubstr("inclination I:        83.21 deg"));
  EXPECT_THAT(r.out, HasSubstr("horizontal H:        6523.2 nT"));
  EXPECT_THAT(r.out, HasSubstr("total F:            55178.5 nT"));
  EXPECT_THAT(r.out, HasSubstr("down Z:             54791.5 nT"));
  EXPECT_THAT(r.out, HasSubstr("grid variation:        1.28 deg"));
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
}

TEST(WmmCli, NegativeLongitudeHeightAndJson) {
  test::TempDir dir;
  const auto json_path = dir / "wmm.json";
  // Report table row: 2025.0, 100 km, 0N 120E; then the same place given as -240.
  const auto r = test::run_cli("wmm --lat 0 --lon -240 --alt-km 100 --date 2025-01-01 --json '" +
                               json_path.string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(io::read_text(json_path));
  EXPECT_EQ(j["model"]["name"], "WMM-2025");
  EXPECT_TRUE(j["valid_date"].get<bool>());
  EXPECT_NEAR(j["declination_deg"].get<double>(), -0.15, 0.006);
  EXPECT_NEAR(j["inclination_deg"].get<double>(), -15.08, 0.006);
  EXPECT_NEAR(j["f_nT"].get<double>(), 39032.1, 0.06);
  EXPECT_NEAR(j["z_nT"].get<double>(), -10152.1, 0.06);
  EXPECT_NEAR(j["per_year"]["z_nT"].get<double>(), 72.9, 0.06);
  EXPECT_TRUE(j["grid_variation_deg"].is_null());
  EXPECT_THAT(r.out, HasSubstr("grid variation:   not defined"));
}

TEST(WmmCli, OtherCoefficientFile) {
  // WMM2020 table: 2020.0, 28 km, 89N 121W: D -112.41, I 88.46, F 56102.7.
  const auto cof = test::shared_path("data/geomagnetism/wmm2025/wmm2020/WMM.COF");
  const auto r = test::run_cli("wmm --lat 89 --lon=-121 --alt-km 28 --date 2020-01-01 --cof '" + cof.string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("WMM-2020"));
  EXPECT_THAT(r.out, HasSubstr("-112.41 deg"));
  EXPECT_THAT(r.out, HasSubstr("88.46 deg"));
  EXPECT_THAT(r.out, HasSubstr("56102.7 nT"));
}

TEST(WmmCli, DateOutsideValidityWarns) {
  const auto r = test::run_cli("wmm --lat 45 --lon 7 --date 2031-06-01");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: date 2031.414 is outside the validity of WMM-2025 (2025.0 to 2030.0)"));
}

TEST(WmmCli, DefaultDateIsToday) {
  const auto r = test::run_cli("wmm --lat 45 --lon 7");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("date:             " + geomag::today_utc_iso()));
}

TEST(WmmCli, BadArgumentsExitWithStatus2) {
  auto r = test::run_cli("wmm --lat 95 --lon 0 --date 2025-06-01");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("error: --lat 95: latitude must be within [-90, 90] degrees"));

  r = test::run_cli("wmm --lat 10 --lon 0 --date 2025-13-01");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("error: --date: '2025-13-01' is not a valid date: month 13 is outside 1..12"));

  r = test::run_cli("wmm --lat 10 --lon 0 --date 2025-02-30");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("day 30 is outside 1..28"));

  r = test::run_cli("wmm --lat north --lon 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--lat 'north' is not a number"));

  r = test::run_cli("wmm --lat 10 --lon 0 --alt-km 900");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--alt-km 900: height must be within [-1, 850] km"));

  // Finite, but no longitude: the sine of 1e16° is noise and of 1e308° NaN.
  for (const char* lon : {"1e308", "1e16", "-361"}) {
    r = test::run_cli(fmt::format("wmm --lat 10 --lon {}", lon));
    EXPECT_EQ(r.status, 2) << lon;
    EXPECT_THAT(r.err, HasSubstr(fmt::format("--lon {}: longitude must be within [-360, 360] degrees", lon)));
  }
}

TEST(WmmCli, BadCoefficientFileNamesFileAndLine) {
  test::TempDir dir;
  test::write_file(dir / "bad.COF", "    2025.0            WMM-2025        11/13/2024\n  1  0  -29351.8  x  12.0 0.0\n");
  auto r = test::run_cli("wmm --lat 10 --lon 0 --date 2025-06-01 --cof '" + (dir / "bad.COF").string() + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.COF:2: column 'h': 'x' is not a number"));

  r = test::run_cli("wmm --lat 10 --lon 0 --date 2025-06-01 --cof '" + (dir / "missing.COF").string() + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("missing.COF"));
}

}  // namespace
}  // namespace antpose
