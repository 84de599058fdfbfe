// phyphox CSV export → Capture.
//
// phyphox writes each sensor as "Time (s)","X (<unit>)",... with the unit in the header. On iOS
// it converts CoreMotion's accelerometer (in g, pointing opposite to Android) with a factor of
// −9.81 (phyphox-ios ExperimentSensorInput.swift, kG = -9.81), so its "Accelerometer" is the
// specific force including gravity in the Android sign convention, as on Android; gyroscope is
// rad/s and magnetometer µT on both platforms.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/import.hpp"
#include "antpose/io/import_detail.hpp"
#include "antpose/io/time.hpp"

namespace antpose {
namespace fs = std::filesystem;
using io::detail::lower;

namespace {

// "X (m/s^2)" → {"X", "m/s^2"}; a header without a parenthesised unit gives an empty unit.
std::pair<std::string, std::string> split_header(const std::string& h) {
  const auto open = h.rfind('(');
  const auto close = h.rfind(')');
  if (open == std::string::npos || close == std::string::npos || close < open) return {h, ""};
  std::string name = h.substr(0, open);
  while (!name.empty() && name.back() == ' ') name.pop_back();
  return {name, h.substr(open + 1, close - open - 1)};
}

enum class Quantity { kAcceleration, kAngularRate, kMagneticField, kPressure };

struct UnitFactor {
  Quantity quantity;
  double to_si;  // to the capture's unit: m/s^2, rad/s, µT, Pa
};

std::optional<UnitFactor> unit_factor(const std::string& unit) {
  static const std::map<std::string, UnitFactor> units = {
      {"m/s^2", {Quantity::kAcceleration, 1.0}},   {"m/s²", {Quantity::kAcceleration, 1.0}},
      {"g", {Quantity::kAcceleration, 9.80665}},   {"rad/s", {Quantity::kAngularRate, 1.0}},
      {"°/s", {Quantity::kAngularRate, std::numbers::pi / 180.0}},
      {"deg/s", {Quantity::kAngularRate, std::numbers::pi / 180.0}},
      {"µT", {Quantity::kMagneticField, 1.0}},     {"μT", {Quantity::kMagneticField, 1.0}},  // micro sign and Greek mu
      {"uT", {Quantity::kMagneticField, 1.0}},     {"nT", {Quantity::kMagneticField, 1e-3}},
      {"mT", {Quantity::kMagneticField, 1e3}},     {"hPa", {Quantity::kPressure, 100.0}},
      {"mbar", {Quantity::kPressure, 100.0}},      {"Pa", {Quantity::kPressure, 1.0}},
      {"kPa", {Quantity::kPressure, 1000.0}},
  };
  const auto it = units.find(unit);
  if (it == units.end()) return std::nullopt;
  return it->second;
}

constexpr const char* kKnownUnits = "m/s^2, g, rad/s, deg/s, µT, nT, mT, hPa, mbar, Pa, kPa";

struct Mapping {
  const char* file;
  const char* stream;
  Quantity quantity;
};

// The multi-sensor export's files that the capture keeps, by name.
constexpr Mapping kMappings[] = {
    {"Accelerometer.csv", "accelerometer", Quantity::kAcceleration},
    {"Gyroscope.csv", "gyroscope", Quantity::kAngularRate},
    {"Magnetometer.csv", "magnetometer", Quantity::kMagneticField},
    {"Linear Accelerometer.csv", "linear_acceleration", Quantity::kAcceleration},
    {"Gravity.csv", "gravity", Quantity::kAcceleration},
    {"Barometer.csv", "pressure", Quantity::kPressure},
};

Stream read_phyphox_stream(const fs::path& file, const Mapping& map, const fs::path& folder) {
  const auto csv = io::read_csv(file);
  if (csv.header.empty()) throw InputError(file, 1, "empty header, expected \"Time (s)\",...");
  const auto [tname, tunit] = split_header(csv.header[0]);
  if (lower(tname) != "time" || (tunit != "s" && tunit != "ms"))
    throw InputError(file, 1, fmt::format("first column is '{}', expected \"Time (s)\"", csv.header[0]));
  const double t_scale = tunit == "ms" ? 1e-3 : 1.0;
  std::vector<std::string> columns;
  std::vector<double> factors;
  for (std::size_t j = 1; j < csv.header.size(); ++j) {
    const auto [name, unit] = split_header(csv.header[j]);
    const auto f = unit_factor(unit);
    if (!f)
      throw InputError(file, 1, fmt::format("column '{}': unknown unit '{}'; expected one of {}", csv.header[j], unit, kKnownUnits));
    if (f->quantity != map.quantity)
      throw InputError(file, 1, fmt::format("column '{}': unit '{}' does not fit {} ({})", csv.header[j], unit,
                                            io::detail::rel_name(file, folder), map.stream));
    std::string col = lower(name);
    if (map.quantity == Quantity::kPressure) col = "p";  // phyphox labels its single pressure column "X"
    columns.push_back(col);
    factors.push_back(f->to_si);
  }
  if (map.quantity != Quantity::kPressure && (columns.size() < 3 || columns[0] != "x" || columns[1] != "y" || columns[2] != "z"))
    throw InputError(file, 1, fmt::format("columns are {}, expected \"Time (s)\",\"X (unit)\",\"Y (unit)\",\"Z (unit)\"",
                                          fmt::join(csv.header, ",")));
  Stream s;
  s.name = map.stream;
  s.columns = columns;
  s.source_file = file;
  s.source_lines = csv.lines;
  s.t.resize(csv.rows.size());
  s.values.resize(static_cast<Eigen::Index>(csv.rows.size()), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    s.t[i] = io::parse_number(csv.rows[i][0], file, csv.lines[i], csv.header[0]) * t_scale;
    for (std::size_t k = 0; k < columns.size(); ++k)
      s.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) =
          io::parse_number(csv.rows[i][k + 1], file, csv.lines[i], csv.header[k + 1]) * factors[k];
  }
  return s;
}

}  // namespace

Capture import_phyphox(const fs::path& folder, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  if (!fs::is_directory(folder)) throw InputError(folder, "not found or not a folder, expected a phyphox export folder");
  Capture c;
  c.root = folder;
  c.kind = "imu-log";
  c.sensor_frame = "android";
  io::detail::SourceRecord src;
  src.format = "phyphox";
  src.path = folder;

  // meta/device.csv: "property","value".
  std::string brand;
  if (const fs::path dev = folder / "meta" / "device.csv"; fs::exists(dev)) {
    const auto csv = io::read_csv(dev);
    const auto cp = csv.column("property"), cv = csv.column("value");
    for (const auto& row : csv.rows) {
      if (row[cv].empty()) continue;
      if (row[cp] == "deviceModel") c.device_model = row[cv];
      if (row[cp] == "deviceBrand") brand = row[cv];
      src.extra["device"][row[cp]] = row[cv];
    }
    src.read.push_back("meta/device.csv (device model, phyphox version)");
  } else {
    diagnostics.warn(dev, 0, "missing: device model unknown");
  }

  // meta/time.csv: the START event ties experiment time to the wall clock.
  const fs::path time_file = folder / "meta" / "time.csv";
  double t_shift = 0.0;
  if (fs::exists(time_file)) {
    const auto csv = io::read_csv(time_file);
    const auto ce = csv.column("event"), cx = csv.column("experiment time"), cs = csv.column("system time");
    std::size_t starts = 0;
    for (std::size_t i = 0; i < csv.rows.size(); ++i) {
      if (csv.rows[i][ce] != "START") continue;
      if (++starts > 1) continue;
      const double exp_t = io::parse_number(csv.rows[i][cx], time_file, csv.lines[i], "experiment time");
      const double sys_t =
          io::checked_unix_seconds(io::parse_number(csv.rows[i][cs], time_file, csv.lines[i], "system time"), time_file,
                                   csv.lines[i], "system time");
      c.time_origin = io::format_utc_iso8601(io::unix_seconds_to_ns_us(sys_t), 6);
      t_shift = -exp_t;
      src.assumptions.push_back(fmt::format("time_origin = START system time {} of meta/time.csv (line {}), to the µs; "
                                            "t = Time (s) − {}",
                                            csv.rows[i][cs], csv.lines[i], csv.rows[i][cx]));
    }
    if (starts == 0)
      diagnostics.warn(time_file, 0, "no START event: the export has no wall-clock time, so time_origin is left out "
                                     "(t is phyphox's experiment time)");
    if (starts > 1)
      diagnostics.warn(time_file, 0, fmt::format("{} START events (paused and resumed): time_origin holds for the first "
                                                 "run only; later runs are offset by the pause lengths",
                                                 starts));
    src.read.push_back("meta/time.csv (START event → time_origin)");
  } else {
    diagnostics.warn(time_file, 0, "missing: the export has no wall-clock time, so time_origin is left out");
  }

  for (const auto& map : kMappings) {
    const fs::path file = folder / map.file;
    if (!fs::exists(file)) continue;
    Stream s = read_phyphox_stream(file, map, folder);
    for (double& t : s.t) t += t_shift;
    src.read.push_back(fmt::format("{} → {} ({} rows)", map.file, map.stream, s.size()));
    c.streams.emplace(s.name, std::move(s));
  }
  if (!c.streams.contains("accelerometer") && !c.streams.contains("gyroscope") && !c.streams.contains("magnetometer"))
    throw InputError(folder, "no Accelerometer.csv, Gyroscope.csv or Magnetometer.csv: nothing to import from this phyphox export");
  if (!c.streams.contains("magnetometer")) src.assumptions.push_back("no Magnetometer.csv in the export: no magnetometer stream");

  for (const auto& e : fs::directory_iterator(folder)) {
    if (!e.is_regular_file()) continue;
    const std::string f = e.path().filename().string();
    const bool used = std::any_of(std::begin(kMappings), std::end(kMappings), [&](const Mapping& m) { return f == m.file; });
    if (!used) src.skipped.push_back(f + ": not needed for attitude");
  }
  std::sort(src.skipped.begin(), src.skipped.end());
  src.assumptions.push_back(
      fmt::format("accelerometer includes gravity, Android sign convention (phyphox{} converts with −9.81 m/s^2 per g)",
                  brand == "Apple" ? " on iOS" : ""));
  src.assumptions.push_back("frame: Android device frame (x right, y up the long side, z out of the screen)");
  src.assumptions.push_back("units from the column headers, converted to m/s^2, rad/s, µT, Pa");
  c.metadata["source"] = src.to_yaml();
  validate_capture(c, folder, diagnostics, options);
  return c;
}

}  // namespace antpose
