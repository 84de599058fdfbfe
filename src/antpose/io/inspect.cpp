#include "antpose/io/inspect.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"

namespace antpose {

namespace {

StreamSummary summarize_stream(const Stream& s, double gap_factor) {
  StreamSummary out;
  out.name = s.name;
  out.samples = s.size();
  if (s.empty()) return out;
  out.t_first = s.t.front();
  out.t_last = s.t.back();
  out.duration_s = s.duration();
  if (s.size() >= 2 && out.duration_s > 0) {
    out.mean_rate_hz = static_cast<double>(s.size() - 1) / out.duration_s;
    std::vector<double> dt(s.size() - 1);
    for (std::size_t i = 1; i < s.size(); ++i) dt[i - 1] = s.t[i] - s.t[i - 1];
    const double mean = std::accumulate(dt.begin(), dt.end(), 0.0) / static_cast<double>(dt.size());
    double var = 0.0;
    for (double d : dt) var += (d - mean) * (d - mean);
    out.interval_std_s = std::sqrt(var / static_cast<double>(dt.size()));
    out.largest_gap_s = *std::max_element(dt.begin(), dt.end());
    out.median_interval_s = median(dt);
    for (double d : dt)
      if (d > gap_factor * out.median_interval_s && d > 0.05) ++out.gaps;
  }
  for (std::size_t k = 0; k < s.columns.size(); ++k) {
    const auto col = s.values.col(static_cast<Eigen::Index>(k));
    ColumnStats c;
    c.column = s.columns[k];
    c.mean = col.mean();
    c.std = std::sqrt((col.array() - c.mean).square().mean());
    c.min = col.minCoeff();
    c.max = col.maxCoeff();
    out.columns.push_back(c);
  }
  if (s.has_xyz()) {
    std::vector<double> n(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) n[i] = s.xyz(i).norm();
    std::nth_element(n.begin(), n.begin() + static_cast<std::ptrdiff_t>(n.size() / 2), n.end());
    out.median_norm = n[n.size() / 2];
  }
  return out;
}

}  // namespace

CaptureSummary summarize(const Capture& c, double gap_factor) {
  CaptureSummary out;
  if (c.metadata.IsMap() && c.metadata["source"] && c.metadata["source"].IsMap() &&
      c.metadata["source"]["format"].IsScalar())
    out.format = c.metadata["source"]["format"].Scalar();
  out.kind = c.kind;
  out.device_model = c.device_model;
  out.device_id = c.device_id;
  out.sensor_frame = c.sensor_frame;
  out.time_origin = c.time_origin;
  out.site = c.site;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& [name, s] : c.streams) {
    out.streams.push_back(summarize_stream(s, gap_factor));
    if (!s.empty()) {
      lo = std::min(lo, s.t.front());
      hi = std::max(hi, s.t.back());
    }
  }
  out.shots.count = c.shots.size();
  if (!c.shots.empty()) {
    out.shots.t_first = INFINITY;
    out.shots.t_last = -INFINITY;
    for (const auto& shot : c.shots) {
      out.shots.t_first = std::min(out.shots.t_first, shot.t);
      out.shots.t_last = std::max(out.shots.t_last, shot.t);
      if (shot.t < lo || shot.t > hi) ++out.shots.outside_sensor_span;
    }
  }
  out.has_truth = c.truth_orientation.has_value();
  out.truth_world = c.truth_world;
  out.truth_samples = c.truth_orientation ? c.truth_orientation->size() : 0;
  out.other_files = c.other_files.size();
  return out;
}

std::string format_summary(const CaptureSummary& s) {
  std::string out;
  auto line = [&](std::string text) { out += text + '\n'; };
  line(fmt::format("format:       {}", s.format));
  line(fmt::format("kind:         {}", s.kind));
  line(fmt::format("device:       {}{}", s.device_model.empty() ? "(unknown)" : s.device_model,
                   s.device_id.empty() ? "" : fmt::format(" (id {})", s.device_id)));
  line(fmt::format("sensor frame: {}", s.sensor_frame));
  line(fmt::format("time origin:  {}", s.time_origin ? *s.time_origin : "(none: no wall-clock time)"));
  if (s.site)
    line(fmt::format("site:         lat {:.6f}°, lon {:.6f}°, alt {:.1f} m{}", s.site->lat_deg, s.site->lon_deg, s.site->alt_m,
                     s.site->date.empty() ? "" : ", date " + s.site->date));
  else
    line("site:         (none)");
  line(fmt::format("streams:      {}", s.streams.size()));
  for (const auto& st : s.streams) {
    line(fmt::format("  {}: {} samples, {:.3f} … {:.3f} s ({:.3f} s), {:.2f} Hz mean, interval median {:.4f} s, jitter (std) {:.4f} s",
                     st.name, st.samples, st.t_first, st.t_last, st.duration_s, st.mean_rate_hz, st.median_interval_s,
                     st.interval_std_s));
    line(fmt::format("    gaps: {} (largest interval {:.3f} s){}", st.gaps, st.largest_gap_s,
                     st.median_norm ? fmt::format(", median |xyz| {:.4g}", *st.median_norm) : ""));
    for (const auto& c : st.columns)
      line(fmt::format("    {:>8}: mean {:>12.5g}  std {:>11.5g}  min {:>12.5g}  max {:>12.5g}", c.column, c.mean, c.std, c.min, c.max));
  }
  if (s.shots.count == 0)
    line("shots:        none");
  else
    line(fmt::format("shots:        {} ({:.3f} … {:.3f} s), {} outside the sensor span", s.shots.count, s.shots.t_first,
                     s.shots.t_last, s.shots.outside_sensor_span));
  line(s.has_truth ? fmt::format("truth:        orientation, {} samples, world {}", s.truth_samples,
                                 s.truth_world.empty() ? "(unspecified)" : s.truth_world)
                   : std::string("truth:        none"));
  if (s.other_files) line(fmt::format("other files:  {}", s.other_files));
  return out;
}

nlohmann::json to_json(const CaptureSummary& s) {
  nlohmann::json j;
  j["format"] = s.format;
  j["kind"] = s.kind;
  j["device"] = {{"model", s.device_model}, {"id", s.device_id}};
  j["sensor_frame"] = s.sensor_frame;
  j["time_origin"] = s.time_origin ? nlohmann::json(*s.time_origin) : nlohmann::json(nullptr);
  if (s.site)
    j["site"] = {{"lat_deg", s.site->lat_deg}, {"lon_deg", s.site->lon_deg}, {"alt_m", s.site->alt_m}, {"date", s.site->date}};
  else
    j["site"] = nullptr;
  j["streams"] = nlohmann::json::array();
  for (const auto& st : s.streams) {
    nlohmann::json js = {{"name", st.name},
                         {"samples", st.samples},
                         {"t_first_s", st.t_first},
                         {"t_last_s", st.t_last},
                         {"duration_s", st.duration_s},
                         {"mean_rate_hz", st.mean_rate_hz},
                         {"median_interval_s", st.median_interval_s},
                         {"interval_std_s", st.interval_std_s},
                         {"gaps", st.gaps},
                         {"largest_gap_s", st.largest_gap_s}};
    // The statistics below are in the stream's unit (null where the format fixes none).
    const std::string_view unit = streams::unit_of(st.name);
    js["unit"] = unit.empty() ? nlohmann::json(nullptr) : nlohmann::json(std::string(unit));
    if (st.median_norm) js["median_norm"] = *st.median_norm;
    for (const auto& c : st.columns)
      js["columns"][c.column] = {{"mean", c.mean}, {"std", c.std}, {"min", c.min}, {"max", c.max}};
    j["streams"].push_back(js);
  }
  j["shots"] = {{"count", s.shots.count},
                {"t_first_s", s.shots.t_first},
                {"t_last_s", s.shots.t_last},
                {"outside_sensor_span", s.shots.outside_sensor_span}};
  j["truth"] = {{"present", s.has_truth}, {"world", s.truth_world}, {"samples", s.truth_samples}};
  j["other_files"] = s.other_files;
  return j;
}

}  // namespace antpose
