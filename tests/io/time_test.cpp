#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/time.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

TEST(UtcIso8601, FormatsNanosecondsAndTruncates) {
  EXPECT_EQ(format_utc_iso8601(1711523595018936600LL), "2024-03-27T07:13:15.018936600Z");
  EXPECT_EQ(format_utc_iso8601(1711523595018936600LL, 3), "2024-03-27T07:13:15.018Z");
  EXPECT_EQ(format_utc_iso8601(0, 0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(format_utc_iso8601(-1, 9), "1969-12-31T23:59:59.999999999Z");
  EXPECT_EQ(format_utc_iso8601(951782400LL * 1000000000LL, 0), "2000-02-29T00:00:00Z");
}

TEST(UtcIso8601, ParsesZonesAndRejectsNonsense) {
  EXPECT_EQ(parse_utc_iso8601("2024-03-27T07:13:15.0189366Z"), 1711523595018936600LL);
  EXPECT_EQ(parse_utc_iso8601("2024-03-27T15:13:15.0189366+08:00"), 1711523595018936600LL);
  EXPECT_EQ(parse_utc_iso8601("2014-01-04T11:34:44.114Z"), 1388835284114000000LL);
  EXPECT_FALSE(parse_utc_iso8601("2014-01-04"));
  EXPECT_FALSE(parse_utc_iso8601("2014-13-04T11:34:44Z"));
  EXPECT_FALSE(parse_utc_iso8601("2014-02-30T11:34:44Z"));
  EXPECT_FALSE(parse_utc_iso8601("2014-01-04T11:34:44"));  // no zone: ambiguous
  EXPECT_FALSE(parse_utc_iso8601("2014-01-04T25:34:44Z"));
  EXPECT_FALSE(parse_utc_iso8601("2014-01-04T11:34:44Zjunk"));
}

TEST(UtcIso8601, DoubleSecondsKeepTheirResolution) {
  // phyphox meta/time.csv START: 1.686142249762457E9 → µs exactly as written.
  EXPECT_EQ(format_utc_iso8601(unix_seconds_to_ns_us(1.686142249762457E9), 6), "2023-06-07T12:50:49.762457Z");
  const double utc = 1.3888352841142452E9;
  const auto origin = unix_seconds_to_ns_us(utc, Rounding::kDown);
  EXPECT_EQ(format_utc_iso8601(origin, 6), "2014-01-04T11:34:44.114245Z");
  const double t = seconds_since(utc, origin);
  EXPECT_GE(t, 0.0);
  EXPECT_LT(t, 1e-6);
  // A difference of two samples equals the difference of their t (exactly here).
  const double later = utc + 0.5;
  EXPECT_EQ(seconds_since(later, origin) - t, later - utc);
}

// int64 nanoseconds hold 1678 to 2262: times beyond are refused, never overflowed.
TEST(UtcIso8601, TimesBeyondWhatNanosecondsHoldAreRefused) {
  EXPECT_FALSE(parse_utc_iso8601("4052-06-01T00:00:00Z"));
  EXPECT_FALSE(parse_utc_iso8601("1600-06-01T00:00:00Z"));
  EXPECT_TRUE(parse_utc_iso8601("2261-12-31T23:59:59Z"));
  EXPECT_THAT(test::input_error([] { checked_unix_seconds(1.38884e25, "sensor_0.xml", 7, "<time>"); }),
              ::testing::HasSubstr("sensor_0.xml:7: <time> 1.38884e+25 is not a UTC time in seconds since 1970"));
  EXPECT_THAT(test::input_error([] { checked_unix_seconds(-1.0, "time.csv", 2, "system time"); }),
              ::testing::HasSubstr("system time -1 is not a UTC time"));
  EXPECT_EQ(checked_unix_seconds(1.6e9, "x", 1, "t"), 1.6e9);
  EXPECT_THROW(unix_seconds_to_ns_us(1e25), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::io
