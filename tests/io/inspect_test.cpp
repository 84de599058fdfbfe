#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "antpose/io/inspect.hpp"

namespace antpose {
namespace {

using ::testing::HasSubstr;

TEST(Inspect, StreamStatisticsRateJitterGapsShots) {
  Capture c;
  c.kind = "contact";
  c.device_model = "Pixel";
  c.time_origin = "2024-01-01T00:00:00Z";
  // 100 Hz for 1 s, a 0.5 s gap, 100 Hz again; x alternates ±1 around 2.
  std::vector<double> t;
  std::vector<Vec3> v;
  for (int i = 0; i < 100; ++i) t.push_back(i * 0.01);
  for (int i = 0; i < 100; ++i) t.push_back(1.49 + i * 0.01);
  for (std::size_t i = 0; i < t.size(); ++i) v.emplace_back(2.0 + (i % 2 ? 1.0 : -1.0), 0.0, 9.8);
  c.streams.emplace("accelerometer", Stream::vector3("accelerometer", t, v));
  c.shots.push_back(Shot{0, 0.5, "images/a.jpg", std::nullopt, {}, {}});
  c.shots.push_back(Shot{1, 3.0, "images/b.jpg", std::nullopt, {}, {}});

  const CaptureSummary s = summarize(c);
  ASSERT_EQ(s.streams.size(), 1u);
  const StreamSummary& a = s.streams[0];
  EXPECT_EQ(a.samples, 200u);
  EXPECT_NEAR(a.duration_s, 2.48, 1e-12);
  EXPECT_NEAR(a.mean_rate_hz, 199 / 2.48, 1e-9);
  EXPECT_NEAR(a.median_interval_s, 0.01, 1e-12);
  EXPECT_EQ(a.gaps, 1u);
  EXPECT_NEAR(a.largest_gap_s, 0.5, 1e-12);
  // Intervals: 198 of 0.01 s and one of 0.5 s → std = sqrt(p(1−p))·0.49 with p = 1/199.
  EXPECT_NEAR(a.interval_std_s, 0.49 * std::sqrt((1.0 / 199) * (198.0 / 199)), 1e-12);
  ASSERT_EQ(a.columns.size(), 3u);
  EXPECT_NEAR(a.columns[0].mean, 2.0, 1e-12);
  EXPECT_NEAR(a.columns[0].std, 1.0, 1e-12);
  EXPECT_EQ(a.columns[0].min, 1.0);
  EXPECT_EQ(a.columns[0].max, 3.0);
  EXPECT_EQ(s.shots.count, 2u);
  EXPECT_EQ(s.shots.outside_sensor_span, 1u);
  EXPECT_FALSE(s.has_truth);

  const std::string text = format_summary(s);
  EXPECT_THAT(text, HasSubstr("kind:         contact"));
  EXPECT_THAT(text, HasSubstr("accelerometer: 200 samples"));
  EXPECT_THAT(text, HasSubstr("gaps: 1 (largest interval 0.500 s)"));
  EXPECT_THAT(text, HasSubstr("2 (0.500 … 3.000 s), 1 outside the sensor span"));
  const auto j = to_json(s);
  EXPECT_EQ(j["streams"][0]["samples"], 200);
  EXPECT_EQ(j["shots"]["outside_sensor_span"], 1);
  EXPECT_EQ(j["device"]["model"], "Pixel");
}

}  // namespace
}  // namespace antpose
