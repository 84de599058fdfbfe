// Sensor Logger CSV export → Capture. Units and axes: tszheichoi/awesome-sensor-logger UNITS.md
// and COORDINATES.md (Android: device frame, specific-force sign; iOS: the same axes with the
// acceleration and gravity signs flipped unless "Standardise Units & Frames" was on).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/import.hpp"
#include "antpose/io/import_detail.hpp"
#include "antpose/io/time.hpp"

namespace antpose {
namespace fs = std::filesystem;
using io::detail::rel_name;

namespace {

// One Sensor Logger table: integer ns times and the wanted value columns.
struct Table {
  fs::path file;
  std::vector<std::int64_t> ns;
  std::vector<std::size_t> lines;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> values;  // per column
};

Table read_table(const fs::path& file, const std::vector<std::string>& columns) {
  const auto csv = io::read_csv(file);
  Table t;
  t.file = file;
  t.columns = columns;
  const std::size_t ct = csv.column("time");
  std::vector<std::size_t> cols;
  for (const auto& c : columns) cols.push_back(csv.column(c));
  t.values.assign(columns.size(), {});
  for (auto& v : t.values) v.reserve(csv.rows.size());
  t.ns.reserve(csv.rows.size());
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    t.ns.push_back(io::parse_int64(csv.rows[i][ct], file, csv.lines[i], "time"));
    for (std::size_t k = 0; k < cols.size(); ++k)
      t.values[k].push_back(io::parse_number(csv.rows[i][cols[k]], file, csv.lines[i], columns[k]));
  }
  t.lines = csv.lines;
  return t;
}

double median_norm3(const Table& t) {
  std::vector<double> n(t.ns.size());
  for (std::size_t i = 0; i < n.size(); ++i) n[i] = std::hypot(t.values[0][i], t.values[1][i], t.values[2][i]);
  return median(std::move(n));
}

// Gravity at the accelerometer's time stamps: the same rows when the stamps match (the usual
// case), else linear interpolation inside Gravity's span; outside it there is no honest value.
std::vector<std::vector<double>> gravity_at(const Table& acc, const Table& grav, Diagnostics& diagnostics) {
  if (acc.ns == grav.ns) return grav.values;
  if (grav.ns.size() < 2 || acc.ns.front() < grav.ns.front() || acc.ns.back() > grav.ns.back())
    throw InputError(grav.file, fmt::format("time stamps differ from {} and do not cover its span ({} … {} ns vs {} … {} ns), "
                                            "so gravity cannot be added to the linear acceleration; export with "
                                            "TotalAcceleration enabled or keep Gravity at the same rate",
                                            acc.file.filename().string(), grav.ns.empty() ? 0 : grav.ns.front(),
                                            grav.ns.empty() ? 0 : grav.ns.back(), acc.ns.front(), acc.ns.back()));
  std::vector<std::vector<double>> out(3, std::vector<double>(acc.ns.size()));
  std::size_t j = 0;
  for (std::size_t i = 0; i < acc.ns.size(); ++i) {
    while (j + 2 < grav.ns.size() && grav.ns[j + 1] < acc.ns[i]) ++j;
    const double span = static_cast<double>(grav.ns[j + 1] - grav.ns[j]);
    const double w = span > 0 ? static_cast<double>(acc.ns[i] - grav.ns[j]) / span : 0.0;
    for (int k = 0; k < 3; ++k) out[k][i] = grav.values[k][j] + w * (grav.values[k][j + 1] - grav.values[k][j]);
  }
  std::string how = "the files have different rows";
  if (acc.ns.size() == grav.ns.size()) {
    std::size_t differ = 0;
    std::int64_t worst = 0;
    for (std::size_t i = 0; i < acc.ns.size(); ++i)
      if (acc.ns[i] != grav.ns[i]) {
        ++differ;
        worst = std::max(worst, acc.ns[i] > grav.ns[i] ? acc.ns[i] - grav.ns[i] : grav.ns[i] - acc.ns[i]);
      }
    how = fmt::format("{} of {} time stamps differ, by up to {} ns", differ, acc.ns.size(), worst);
  }
  diagnostics.warn(grav.file, 0, fmt::format("time stamps do not match {} ({}): gravity interpolated linearly at the "
                                             "accelerometer's time stamps",
                                             acc.file.filename().string(), how));
  return out;
}

std::map<std::string, std::string> read_metadata(const fs::path& file) {
  std::map<std::string, std::string> m;
  const auto csv = io::read_csv(file);
  if (csv.rows.empty()) return m;
  for (std::size_t j = 0; j < csv.header.size(); ++j) m[csv.header[j]] = csv.rows.front()[j];
  return m;
}

}  // namespace

Capture import_sensor_logger(const fs::path& folder, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  if (!fs::is_directory(folder)) throw InputError(folder, "not found or not a folder, expected a Sensor Logger export folder");
  Capture c;
  c.root = folder;
  c.kind = "imu-log";
  c.sensor_frame = "android";
  io::detail::SourceRecord src;
  src.format = "sensor-logger";
  src.path = folder;

  std::string platform = "android";
  if (const fs::path meta = folder / "Metadata.csv"; fs::exists(meta)) {
    const auto m = read_metadata(meta);
    auto get = [&](const char* k) { const auto it = m.find(k); return it == m.end() ? std::string() : it->second; };
    c.device_model = get("device name");
    c.device_id = get("device id");
    if (!get("platform").empty()) platform = io::detail::lower(get("platform"));
    for (const char* k : {"platform", "appVersion", "version", "recording time", "recording timezone", "recording epoch time",
                          "sensors", "sampleRateMs"})
      if (!get(k).empty()) src.extra["metadata"][k] = get(k);
    src.read.push_back("Metadata.csv (device, platform, app version)");
  } else {
    diagnostics.warn(folder / "Metadata.csv", 0, "missing: device model and platform unknown; assuming Android conventions");
    src.assumptions.push_back("no Metadata.csv: platform assumed Android");
  }
  if (platform != "android" && platform != "ios")
    throw InputError(folder / "Metadata.csv", 2, fmt::format("platform '{}' is unknown, expected android or ios", platform));
  const bool ios = platform == "ios";

  auto present = [&](const char* name) { return fs::exists(folder / name); };
  const std::vector<std::string> xyz = {"x", "y", "z"};
  std::map<std::string, Table> tables;  // by stream name

  // Accelerometer: specific force for the capture.
  if (present("TotalAcceleration.csv")) {
    tables["accelerometer"] = read_table(folder / "TotalAcceleration.csv", xyz);
    src.read.push_back("TotalAcceleration.csv → accelerometer (acceleration with gravity)");
    if (present("Accelerometer.csv")) {
      tables["linear_acceleration"] = read_table(folder / "Accelerometer.csv", xyz);
      src.read.push_back("Accelerometer.csv → linear_acceleration");
    }
  } else if (present("Accelerometer.csv")) {
    Table acc = read_table(folder / "Accelerometer.csv", xyz);
    if (acc.ns.empty()) throw InputError(acc.file, "no samples: the accelerometer stream is empty (only a header)");
    const double m = median_norm3(acc);
    if (m < 3.0) {
      if (!present("Gravity.csv"))
        throw InputError(acc.file, fmt::format("median |a| = {:.3g} m/s^2: this is linear acceleration (gravity removed) and the "
                                               "export has neither Gravity.csv nor TotalAcceleration.csv to restore the specific force",
                                               m));
      const Table grav = read_table(folder / "Gravity.csv", xyz);
      const auto g = gravity_at(acc, grav, diagnostics);
      tables["linear_acceleration"] = acc;
      for (int k = 0; k < 3; ++k)
        for (std::size_t i = 0; i < acc.ns.size(); ++i) acc.values[k][i] += g[k][i];
      tables["accelerometer"] = std::move(acc);
      src.read.push_back("Accelerometer.csv + Gravity.csv → accelerometer (specific force = Accelerometer + Gravity)");
      src.read.push_back("Accelerometer.csv → linear_acceleration (as exported)");
      src.assumptions.push_back(fmt::format("Accelerometer.csv is linear acceleration (median |a| = {:.3g} m/s^2, Gravity.csv "
                                            "present): gravity added back",
                                            m));
    } else {
      tables["accelerometer"] = std::move(acc);
      src.read.push_back("Accelerometer.csv → accelerometer");
      src.assumptions.push_back(fmt::format("Accelerometer.csv already includes gravity (median |a| = {:.3g} m/s^2)", m));
    }
  }
  if (present("Gravity.csv")) {
    tables["gravity"] = read_table(folder / "Gravity.csv", xyz);
    src.read.push_back("Gravity.csv → gravity");
  }
  if (present("Gyroscope.csv")) {
    tables["gyroscope"] = read_table(folder / "Gyroscope.csv", xyz);
    src.read.push_back("Gyroscope.csv → gyroscope (rad/s)");
  }
  if (present("Magnetometer.csv")) {
    tables["magnetometer"] = read_table(folder / "Magnetometer.csv", xyz);
    src.read.push_back("Magnetometer.csv → magnetometer (µT, calibrated)");
  }
  for (const auto& [file, name] : {std::pair{"AccelerometerUncalibrated.csv", "accelerometer_uncalibrated"},
                                   std::pair{"GyroscopeUncalibrated.csv", "gyroscope_uncalibrated"},
                                   std::pair{"MagnetometerUncalibrated.csv", "magnetometer_uncalibrated"}})
    if (present(file)) {
      tables[name] = read_table(folder / file, xyz);
      src.read.push_back(fmt::format("{} → {}", file, name));
    }
  if (present("Orientation.csv")) {
    tables["rotation_vector"] = read_table(folder / "Orientation.csv", {"qw", "qx", "qy", "qz"});
    src.read.push_back("Orientation.csv → rotation_vector (qw,qx,qy,qz; roll/pitch/yaw dropped, they derive from it)");
    src.assumptions.push_back("rotation_vector is the app's attitude quaternion as exported (Android rotation vector: "
                              "device → magnetic ENU); not used for measurement");
  }
  if (present("Barometer.csv")) {
    Table baro = read_table(folder / "Barometer.csv", {"pressure"});
    for (double& p : baro.values[0]) p *= 100.0;  // mbar = hPa → Pa
    baro.columns = {"p"};
    tables["pressure"] = std::move(baro);
    src.read.push_back("Barometer.csv → pressure (column p in Pa, from hPa)");
  }
  if (!tables.contains("accelerometer") && !tables.contains("gyroscope") && !tables.contains("magnetometer"))
    throw InputError(folder, "no Accelerometer.csv, Gyroscope.csv or Magnetometer.csv: nothing to import from this Sensor Logger export");

  if (ios) {
    for (const char* name : {"accelerometer", "linear_acceleration", "gravity", "accelerometer_uncalibrated"})
      if (auto it = tables.find(name); it != tables.end())
        for (int k = 0; k < 3; ++k)
          for (double& v : it->second.values[k]) v = -v;
    diagnostics.warn(folder / "Metadata.csv", 0,
                     "iOS export: acceleration and gravity negated to the Android sign convention, assuming the app's "
                     "'Standardise Units & Frames' setting was off (its default)");
    src.assumptions.push_back("iOS: acceleration/gravity signs flipped to Android's (Standardise Units & Frames assumed off)");
  }

  // Files looked at but not imported.
  for (const auto& e : fs::directory_iterator(folder)) {
    if (!e.is_regular_file()) continue;
    const std::string f = e.path().filename().string();
    static const std::vector<std::string> used = {"Metadata.csv", "Accelerometer.csv", "TotalAcceleration.csv", "Gravity.csv",
                                                  "Gyroscope.csv", "Magnetometer.csv", "Orientation.csv", "Barometer.csv",
                                                  "AccelerometerUncalibrated.csv", "GyroscopeUncalibrated.csv",
                                                  "MagnetometerUncalibrated.csv"};
    if (std::find(used.begin(), used.end(), f) != used.end()) continue;
    if (e.file_size() == 0) src.skipped.push_back(f + ": empty file");
    else src.skipped.push_back(f + ": not needed for attitude");
  }
  std::sort(src.skipped.begin(), src.skipped.end());
  if (fs::exists(folder / "Location.csv") && fs::file_size(folder / "Location.csv") == 0)
    diagnostics.warn(folder / "Location.csv", 0, "empty (no GPS fix recorded): no site position from this export");

  // One clock: ns since the earliest kept sample; integer differences keep every ns.
  std::optional<std::int64_t> origin;
  for (const auto& [name, t] : tables)
    if (!t.ns.empty()) origin = origin ? std::min(*origin, t.ns.front()) : t.ns.front();
  if (origin) c.time_origin = io::format_utc_iso8601(*origin, 9);
  for (auto& [name, t] : tables) {
    std::vector<double> secs(t.ns.size());
    for (std::size_t i = 0; i < secs.size(); ++i) secs[i] = static_cast<double>(t.ns[i] - *origin) / 1e9;
    Stream s = io::detail::make_stream(name, t.columns, std::move(secs), t.values);
    s.source_file = t.file;
    s.source_lines = t.lines;
    c.streams.emplace(name, std::move(s));
  }
  src.assumptions.push_back("time: integer ns since 1970 (UTC); t = (time − origin)/1e9 with origin the earliest sample; "
                            "seconds_elapsed ignored");
  src.assumptions.push_back("frame: Android device frame (x right, y up the long side, z out of the screen)");
  c.metadata["source"] = src.to_yaml();
  validate_capture(c, folder, diagnostics, options);
  return c;
}

}  // namespace antpose
