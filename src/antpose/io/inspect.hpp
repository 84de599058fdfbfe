// Summary statistics of a capture (what `antpose inspect` prints): per stream sample count,
// duration, rate, jitter, gaps and per-column mean/std/min/max; shots and truth presence.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/io/capture.hpp"

namespace antpose {

struct ColumnStats {
  std::string column;
  double mean = 0.0, std = 0.0, min = 0.0, max = 0.0;  // in the stream's unit; std with 1/n
};

struct StreamSummary {
  std::string name;
  std::size_t samples = 0;
  double t_first = 0.0, t_last = 0.0;  // s, capture clock
  double duration_s = 0.0;
  double mean_rate_hz = 0.0;           // (samples − 1) / duration
  double median_interval_s = 0.0;
  double interval_std_s = 0.0;         // rate jitter: standard deviation of the sample intervals
  std::size_t gaps = 0;                // intervals > gap_factor × median and > 0.05 s
  double largest_gap_s = 0.0;          // largest interval (gap or not)
  std::optional<double> median_norm;   // of x, y, z when the stream has them
  std::vector<ColumnStats> columns;
};

struct ShotsSummary {
  std::size_t count = 0;
  double t_first = 0.0, t_last = 0.0;
  std::size_t outside_sensor_span = 0;  // shots before the first or after the last sensor sample
};

struct CaptureSummary {
  std::string format = "native";  // from metadata source.format for imported captures
  std::string kind;
  std::string device_model, device_id;
  std::string sensor_frame;
  std::optional<std::string> time_origin;
  std::optional<Site> site;
  std::vector<StreamSummary> streams;
  ShotsSummary shots;
  bool has_truth = false;
  std::string truth_world;
  std::size_t truth_samples = 0;
  std::size_t other_files = 0;
};

/// Statistics of every stream, the shots and the truth of `capture`.
CaptureSummary summarize(const Capture& capture, double gap_factor = 10.0);

/// Human-readable multi-line text of a summary.
std::string format_summary(const CaptureSummary& summary);

/// The summary as JSON (keys as the struct fields; degrees only in site.*_deg).
nlohmann::json to_json(const CaptureSummary& summary);

}  // namespace antpose
