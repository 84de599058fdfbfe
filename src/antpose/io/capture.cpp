#include "antpose/io/capture.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/file_access.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/time.hpp"
#include "antpose/io/units.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormatName = "antpose-capture";
const std::set<std::string> kKinds = {"imu-log", "contact", "imu-calibration", "camera-calibration",
                                      "joint-calibration", "antenna"};
const std::set<std::string> kSensorFrames = {"android", "other"};
const std::set<std::string> kTruthWorlds = {"enu-true", "enu-magnetic", "unaligned"};

std::string stream_stem(const fs::path& file) {
  std::string name = file.filename().string();
  for (const char* suffix : {".csv.gz", ".csv"})
    if (name.ends_with(suffix)) return name.substr(0, name.size() - std::string_view(suffix).size());
  return {};
}

// --- capture.yaml -------------------------------------------------------------------------

template <typename T>
T yaml_as(const YAML::Node& node, const fs::path& file, std::string_view key, std::string_view expected) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw InputError(file, io::line_of(node),
                     fmt::format("'{}' is '{}', expected {}", key, node.IsScalar() ? node.Scalar() : "(not a scalar)", expected));
  }
}

std::string yaml_choice(const YAML::Node& node, const fs::path& file, std::string_view key, const std::set<std::string>& allowed) {
  const auto value = yaml_as<std::string>(node, file, key, "a name");
  if (!allowed.contains(value))
    throw InputError(file, io::line_of(node), fmt::format("{} '{}' is unknown; expected one of {}", key, value, fmt::join(allowed, ", ")));
  return value;
}

bool is_iso_date(std::string_view s) {
  if (s.size() != 10 || s[4] != '-' || s[7] != '-') return false;
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 8, 9})
    if (s[i] < '0' || s[i] > '9') return false;
  const int month = (s[5] - '0') * 10 + (s[6] - '0');
  const int day = (s[8] - '0') * 10 + (s[9] - '0');
  return month >= 1 && month <= 12 && day >= 1 && day <= 31;
}

Site parse_site(const YAML::Node& node, const fs::path& file) {
  if (!node.IsMap()) throw InputError(file, io::line_of(node), "'site' must be a map with lat_deg, lon_deg, alt_m, date");
  Site site;
  auto number = [&](const char* key, double lo, double hi, bool required, double fallback) {
    if (!node[key]) {
      if (required) throw InputError(file, io::line_of(node), fmt::format("site: '{}' is missing", key));
      return fallback;
    }
    const double v = yaml_as<double>(node[key], file, fmt::format("site.{}", key), "a number");
    if (!std::isfinite(v) || v < lo || v > hi)
      throw InputError(file, io::line_of(node[key]), fmt::format("site.{} = {} is out of range, expected [{}, {}]", key, v, lo, hi));
    return v;
  };
  site.lat_deg = number("lat_deg", -90.0, 90.0, true, 0.0);
  site.lon_deg = number("lon_deg", -180.0, 360.0, true, 0.0);
  site.alt_m = number("alt_m", -1000.0, 100000.0, false, 0.0);
  if (site.lon_deg > 180.0) site.lon_deg -= 360.0;
  if (node["date"]) {
    site.date = yaml_as<std::string>(node["date"], file, "site.date", "a date YYYY-MM-DD");
    if (!is_iso_date(site.date))
      throw InputError(file, io::line_of(node["date"]), fmt::format("site.date '{}' is not a date, expected YYYY-MM-DD", site.date));
  }
  return site;
}

void parse_metadata(Capture& c, const fs::path& file) {
  try {
    c.metadata = YAML::Load(io::read_text(file));
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.is_null() ? 0 : static_cast<std::size_t>(e.mark.line) + 1, "not valid YAML: " + e.msg);
  }
  const YAML::Node& m = c.metadata;
  if (!m.IsMap()) throw InputError(file, "expected a YAML map with 'format: antpose-capture'");
  if (!m["format"]) throw InputError(file, "no 'format' key: not an antpose capture (expected 'format: antpose-capture')");
  const auto format = yaml_as<std::string>(m["format"], file, "format", kFormatName);
  if (format != kFormatName)
    throw InputError(file, io::line_of(m["format"]), fmt::format("unknown format '{}', expected '{}'", format, kFormatName));
  if (!m["version"]) throw InputError(file, "no 'version' key (expected 'version: 1')");
  const int version = yaml_as<int>(m["version"], file, "version", "an integer");
  if (version < 1 || version > Capture::kFormatVersion)
    throw InputError(file, io::line_of(m["version"]),
                     fmt::format("format version {} is not supported; this antpose reads versions 1 to {}", version,
                                 Capture::kFormatVersion));
  if (m["kind"]) c.kind = yaml_choice(m["kind"], file, "kind", kKinds);
  if (m["time_origin"] && !m["time_origin"].IsNull()) {
    c.time_origin = yaml_as<std::string>(m["time_origin"], file, "time_origin", "an ISO-8601 UTC instant");
    if (!io::parse_utc_iso8601(*c.time_origin))
      throw InputError(file, io::line_of(m["time_origin"]),
                       fmt::format("time_origin '{}' is not an ISO-8601 UTC instant, expected e.g. 2014-01-04T11:34:44.114Z",
                                   *c.time_origin));
  }
  if (const auto d = m["device"]; d && d.IsMap()) {
    if (d["model"]) c.device_model = yaml_as<std::string>(d["model"], file, "device.model", "text");
    if (d["id"]) c.device_id = yaml_as<std::string>(d["id"], file, "device.id", "text");
  }
  if (m["sensor_frame"]) c.sensor_frame = yaml_choice(m["sensor_frame"], file, "sensor_frame", kSensorFrames);
  if (m["site"] && !m["site"].IsNull()) c.site = parse_site(m["site"], file);
  if (const auto truth = m["truth"]; truth && truth.IsMap() && truth["world"])
    c.truth_world = yaml_choice(truth["world"], file, "truth.world", kTruthWorlds);
}

// --- tables -------------------------------------------------------------------------------

// The x, y, z columns of a device-frame vector stream, found by name in whatever order the header
// gives them (capture-format.md: columns are named, extras allowed); empty for other streams.
std::vector<std::size_t> vector_columns(const io::CsvText& csv, std::string_view name) {
  if (name != streams::kAccelerometer && name != streams::kGyroscope && name != streams::kMagnetometer) return {};
  std::vector<std::size_t> out;
  for (const char* axis : {"x", "y", "z"}) {
    const auto j = csv.find_column(axis);
    if (j < 0)
      throw InputError(csv.file, 1,
                       fmt::format("no column '{}': the {} stream has the columns {} (expected t,x,y,z; "
                                   "extra columns are allowed)",
                                   axis, name, fmt::join(csv.header, ",")));
    out.push_back(static_cast<std::size_t>(j));
  }
  return out;
}

Stream parse_stream(const io::CsvText& csv, std::string name, io::NonFinite non_finite) {
  const std::size_t t_col = csv.column("t");
  Stream s;
  s.name = std::move(name);
  s.gzip = io::is_gzip_name(csv.file);
  s.source_file = csv.file;
  s.source_lines = csv.lines;
  std::vector<std::size_t> value_cols = vector_columns(csv, s.name);
  for (std::size_t j = 0; j < csv.header.size(); ++j)
    if (j != t_col && std::find(value_cols.begin(), value_cols.end(), j) == value_cols.end()) value_cols.push_back(j);
  for (std::size_t j : value_cols) s.columns.push_back(csv.header[j]);
  s.t.resize(csv.rows.size());
  s.values.resize(static_cast<Eigen::Index>(csv.rows.size()), static_cast<Eigen::Index>(value_cols.size()));
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& row = csv.rows[i];
    s.t[i] = io::parse_number(row[t_col], csv.file, csv.lines[i], "t");
    for (std::size_t k = 0; k < value_cols.size(); ++k)
      s.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) =
          io::parse_number(row[value_cols[k]], csv.file, csv.lines[i], csv.header[value_cols[k]], non_finite);
  }
  return s;
}

std::string stream_csv(const Stream& s) {
  std::string out = "t";
  for (const auto& c : s.columns) out += "," + c;
  out += '\n';
  for (std::size_t i = 0; i < s.size(); ++i) {
    out += io::format_number(s.t[i]);
    for (Eigen::Index k = 0; k < s.values.cols(); ++k) {
      out += ',';
      out += io::format_number(s.values(static_cast<Eigen::Index>(i), k));
    }
    out += '\n';
  }
  return out;
}

void read_shots(Capture& c, const fs::path& folder) {
  const fs::path file = folder / "shots.csv";
  const auto csv = io::read_csv(file);
  c.shots_file = file;
  const std::size_t ci = csv.column("index"), ct = csv.column("t"), cimg = csv.column("image");
  const auto cexp = csv.find_column("exposure_s");
  std::vector<std::size_t> extra;
  for (std::size_t j = 0; j < csv.header.size(); ++j)
    if (j != ci && j != ct && j != cimg && static_cast<std::ptrdiff_t>(j) != cexp) {
      extra.push_back(j);
      c.shot_extra_columns.push_back(csv.header[j]);
    }
  std::map<fs::path, std::size_t> listed;  // image → its line
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& row = csv.rows[i];
    const std::size_t line = csv.lines[i];
    Shot shot;
    const double index = io::parse_number(row[ci], file, line, "index");
    if (index != std::floor(index) || index < 0)
      throw InputError(file, line, fmt::format("column 'index': '{}' is not a non-negative integer", row[ci]));
    shot.index = static_cast<int>(index);
    shot.source_line = line;
    shot.t = io::parse_number(row[ct], file, line, "t");
    shot.image = row[cimg];
    const fs::path image = io::path_inside(folder, shot.image, {file, line, "image"});
    // One row per photo: a photo listed twice would weigh twice in a calibration and pass for a
    // second viewpoint in a measurement.
    const auto [first, fresh] = listed.emplace(fs::path(shot.image).lexically_normal(), line);
    if (!fresh)
      throw InputError(file, line,
                       fmt::format("image '{}' is listed again (first on line {}); each photo is one row", shot.image,
                                   first->second));
    if (const io::FileKind kind = io::file_kind(image); kind != io::FileKind::kRegular)
      throw InputError(file, line,
                       kind == io::FileKind::kMissing
                           ? fmt::format("image '{}' not found in {}", shot.image, folder.string())
                           : fmt::format("image '{}' is {}, expected a photo file", shot.image, io::describe(kind)));
    if (cexp >= 0 && !row[static_cast<std::size_t>(cexp)].empty())
      shot.exposure_s = io::parse_number(row[static_cast<std::size_t>(cexp)], file, line, "exposure_s");
    for (std::size_t j : extra) shot.extra.push_back(row[j]);
    c.shots.push_back(std::move(shot));
  }
}

std::string shots_csv(const Capture& c) {
  const bool with_exposure = std::any_of(c.shots.begin(), c.shots.end(), [](const Shot& s) { return s.exposure_s.has_value(); });
  std::vector<std::string> header = {"index", "t", "image"};
  if (with_exposure) header.push_back("exposure_s");
  header.insert(header.end(), c.shot_extra_columns.begin(), c.shot_extra_columns.end());
  std::string out = io::join_csv_line(header) + '\n';
  for (const auto& s : c.shots) {
    std::vector<std::string> row = {std::to_string(s.index), io::format_number(s.t), s.image};
    if (with_exposure) row.push_back(s.exposure_s ? io::format_number(*s.exposure_s) : "");
    row.insert(row.end(), s.extra.begin(), s.extra.end());
    out += io::join_csv_line(row) + '\n';
  }
  return out;
}

YAML::Node metadata_yaml(const Capture& c) {
  YAML::Node out;
  out["format"] = kFormatName;
  out["version"] = Capture::kFormatVersion;
  out["kind"] = c.kind;
  if (c.time_origin) out["time_origin"] = *c.time_origin;
  YAML::Node device = c.metadata["device"] && c.metadata["device"].IsMap() ? YAML::Clone(c.metadata["device"]) : YAML::Node();
  if (!c.device_model.empty()) device["model"] = c.device_model;
  if (!c.device_id.empty()) device["id"] = c.device_id;
  if (device.size() > 0) out["device"] = device;
  out["sensor_frame"] = c.sensor_frame;
  if (c.site) {
    YAML::Node site;
    site["lat_deg"] = io::format_number(c.site->lat_deg);
    site["lon_deg"] = io::format_number(c.site->lon_deg);
    site["alt_m"] = io::format_number(c.site->alt_m);
    if (!c.site->date.empty()) site["date"] = c.site->date;
    out["site"] = site;
  }
  if (c.truth_orientation || !c.truth_world.empty()) {
    YAML::Node truth = c.metadata["truth"] && c.metadata["truth"].IsMap() ? YAML::Clone(c.metadata["truth"]) : YAML::Node();
    if (c.truth_orientation)
      truth["orientation"] = c.truth_orientation->gzip ? "truth/orientation.csv.gz" : "truth/orientation.csv";
    else if (truth["orientation"])
      truth.remove("orientation");
    if (!c.truth_world.empty()) truth["world"] = c.truth_world;
    out["truth"] = truth;
  }
  // Keys the writer derives from the Capture fields are not copied from the old metadata: a
  // field cleared in memory (time_origin, site, truth) must not come back from it.
  static const std::set<std::string> kManaged = {"format", "version", "kind", "time_origin", "device",
                                                 "sensor_frame", "site", "truth"};
  if (c.metadata.IsMap())
    for (const auto& kv : c.metadata) {
      if (!kv.first.IsScalar()) continue;  // a key that is no name (a YAML map or list) is not kept
      const std::string& key = kv.first.Scalar();
      if (!kManaged.contains(key) && !out[key]) out[key] = YAML::Clone(kv.second);
    }
  return out;
}

fs::path truth_orientation_file(const fs::path& folder, const YAML::Node& truth) {
  if (truth && truth.IsMap() && truth["orientation"]) {
    const fs::path yaml = folder / "capture.yaml";
    const auto value = yaml_as<std::string>(truth["orientation"], yaml, "truth.orientation", "a path in the capture");
    return io::path_inside(folder, value, {yaml, io::line_of(truth["orientation"]), "truth.orientation"});
  }
  for (const char* name : {"truth/orientation.csv.gz", "truth/orientation.csv"})
    if (fs::exists(folder / name)) return folder / name;
  return {};
}

}  // namespace

bool Stream::has_xyz() const { return columns.size() >= 3 && columns[0] == "x" && columns[1] == "y" && columns[2] == "z"; }

Stream Stream::vector3(std::string name, std::vector<double> t, const std::vector<Vec3>& xyz) {
  Stream s;
  s.name = std::move(name);
  s.columns = {"x", "y", "z"};
  s.values.resize(static_cast<Eigen::Index>(xyz.size()), 3);
  for (std::size_t i = 0; i < xyz.size(); ++i) s.values.row(static_cast<Eigen::Index>(i)) = xyz[i].transpose();
  s.t = std::move(t);
  return s;
}

const Stream* Capture::find(std::string_view name) const {
  const auto it = streams.find(std::string(name));
  return it == streams.end() ? nullptr : &it->second;
}

const Stream& Capture::require(std::string_view name) const {
  if (const Stream* s = find(name)) return *s;
  std::vector<std::string> have;
  for (const auto& [k, v] : streams) have.push_back(k);
  throw InputError(root / "sensors", fmt::format("no {} stream (sensors/{}.csv); the capture has: {}", name, name,
                                                 have.empty() ? std::string("no streams") : fmt::format("{}", fmt::join(have, ", "))));
}

fs::path stream_path(const fs::path& folder, const Stream& stream) {
  return folder / "sensors" / (stream.name + (stream.gzip ? ".csv.gz" : ".csv"));
}

fs::path stream_source(const fs::path& folder, const Stream& stream) {
  return stream.source_file.empty() ? stream_path(folder, stream) : stream.source_file;
}

std::size_t Stream::source_line(std::size_t i) const {
  if (source_lines.size() == t.size() && i < source_lines.size()) return source_lines[i];
  return source_file.empty() ? i + 2 : 0;
}

void require_android_frame(const Capture& capture, std::string_view what) {
  if (capture.sensor_frame == "android") return;
  throw InputError(capture.root / "capture.yaml",
                   fmt::format("sensor_frame '{}': {} needs the streams in Android's device frame (x right, y up the "
                               "long side, z out of the screen); a body frame that only the truth relates to the "
                               "phone cannot give an antenna's attitude",
                               capture.sensor_frame, what));
}

fs::path capture_file(const fs::path& folder, std::string_view name) {
  return io::path_inside(folder, name, {folder, 0, "file"});
}

Capture read_capture(const fs::path& folder, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  if (!fs::exists(folder)) throw InputError(folder, "capture folder not found");
  if (!fs::is_directory(folder)) throw InputError(folder, "is a file, expected a capture folder (with capture.yaml)");
  const fs::path yaml = folder / "capture.yaml";
  if (!fs::exists(yaml)) throw InputError(yaml, "missing: not an antpose capture folder (use 'antpose convert' to import phone-logger exports)");
  Capture c;
  c.root = folder;
  parse_metadata(c, yaml);

  std::set<fs::path> known = {"capture.yaml", "shots.csv"};
  if (fs::is_directory(folder / "sensors")) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(folder / "sensors"))
      if (!e.is_directory() && !stream_stem(e.path()).empty()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::string name = stream_stem(f);
      if (c.streams.contains(name))
        throw InputError(f, fmt::format("stream '{}' is stored twice (both .csv and .csv.gz); keep one", name));
      const fs::path rel = f.lexically_relative(folder);  // fs::relative would follow the links
      io::path_inside(folder, rel.string(), {folder / "sensors", 0, "stream"});
      c.streams.emplace(name, parse_stream(io::read_csv(f), name, io::NonFinite::kReject));
      known.insert(rel);
    }
  }
  if (fs::exists(folder / "shots.csv")) read_shots(c, folder);
  for (const auto& s : c.shots) known.insert(fs::path(s.image).lexically_normal());

  if (const fs::path truth = truth_orientation_file(folder, c.metadata["truth"]); !truth.empty()) {
    auto table = parse_stream(io::read_csv(truth), "truth/orientation", io::NonFinite::kAllow);
    for (const char* col : {"qw", "qx", "qy", "qz"})
      if (std::find(table.columns.begin(), table.columns.end(), col) == table.columns.end())
        throw InputError(truth, 1, fmt::format("missing column '{}' (expected t,qw,qx,qy,qz[,valid,moving])", col));
    c.truth_orientation = std::move(table);
    known.insert(fs::relative(truth, folder));
  }
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), folder);
    const bool hidden = std::any_of(rel.begin(), rel.end(), [](const fs::path& part) { return part.string().starts_with("."); });
    if (!known.contains(rel) && !hidden) c.other_files.push_back(rel);
  }
  std::sort(c.other_files.begin(), c.other_files.end());
  validate_capture(c, folder, diagnostics, options);
  return c;
}

void validate_capture(Capture& c, const fs::path& folder, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  double span_lo = INFINITY, span_hi = -INFINITY;
  for (auto& [name, s] : c.streams) {
    const fs::path file = stream_source(folder, s);
    if (s.empty()) throw InputError(file, fmt::format("no samples: the {} stream is empty (only a header)", name));
    if (static_cast<std::size_t>(s.values.rows()) != s.size() || static_cast<std::size_t>(s.values.cols()) != s.columns.size())
      throw Error(fmt::format("{}: stream '{}' has {} times but a {}×{} value table for {} columns (a bug in the code that built it)",
                              file.string(), name, s.size(), s.values.rows(), s.values.cols(), s.columns.size()));
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!std::isfinite(s.t[i]))
        throw InputError(file, s.source_line(i), fmt::format("t = {} is not a finite time", io::format_number(s.t[i])));
      for (std::size_t k = 0; k < s.columns.size(); ++k) {
        const double v = s.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k));
        if (!std::isfinite(v))
          throw InputError(file, s.source_line(i),
                           fmt::format("column '{}': {} is not a finite number (NaN/Inf not allowed in a sensor stream)",
                                       s.columns[k], io::format_number(v)));
      }
      if (i == 0) continue;
      if (s.t[i] < s.t[i - 1])
        throw InputError(file, s.source_line(i),
                         fmt::format("t = {} goes backwards (previous row has t = {}); rows must be in increasing time",
                                     io::format_number(s.t[i]), io::format_number(s.t[i - 1])));
      if (s.t[i] == s.t[i - 1])
        throw InputError(file, s.source_line(i), fmt::format("t = {} repeats the previous row's time; rows must be in increasing time",
                                                             io::format_number(s.t[i])));
    }
    if (s.size() >= 3) {
      std::vector<double> dt(s.size() - 1);
      for (std::size_t i = 1; i < s.size(); ++i) dt[i - 1] = s.t[i] - s.t[i - 1];
      const double median = antpose::median(dt);
      std::size_t reported = 0;
      for (std::size_t i = 0; i < dt.size(); ++i)
        if (dt[i] > options.gap_factor * median && dt[i] > 0.05) {
          if (++reported <= 3)
            diagnostics.warn(file, s.source_line(i + 1),
                             fmt::format("gap of {:.3f} s in the stream before t = {} (median interval {:.4f} s)", dt[i],
                                         io::format_number(s.t[i + 1]), median));
        }
      if (reported > 3) diagnostics.warn(file, 0, fmt::format("{} gaps in all (only the first 3 are listed)", reported));
    }
    span_lo = std::min(span_lo, s.t.front());
    span_hi = std::max(span_hi, s.t.back());
  }
  io::check_units(c, folder, diagnostics, options.repair_units);
  const fs::path shots_file = c.shots_file.empty() ? folder / "shots.csv" : c.shots_file;
  for (std::size_t i = 0; i < c.shots.size(); ++i) {
    const auto& shot = c.shots[i];
    const std::size_t line = shot.source_line != 0 ? shot.source_line : (c.shots_file.empty() ? i + 2 : 0);
    if (!std::isfinite(shot.t)) throw InputError(shots_file, line, fmt::format("shot {} has no finite time", shot.index));
    if (!c.streams.empty() && (shot.t < span_lo || shot.t > span_hi))
      diagnostics.warn(shots_file, line,
                       fmt::format("shot {} at t = {} s lies outside the sensor data ({:.3f} … {:.3f} s): no orientation for it",
                                   shot.index, io::format_number(shot.t), span_lo, span_hi));
  }
}

void write_capture(const Capture& c, const fs::path& folder, const CaptureWriteOptions& options) {
  io::write_folder_atomic(folder, options.overwrite, [&](const fs::path& tmp) {
    io::write_text_atomic(tmp / "capture.yaml", io::yaml_document(metadata_yaml(c)));
    for (const auto& [name, s] : c.streams) io::write_text_atomic(stream_path(tmp, s), stream_csv(s));
    if (!c.shots.empty()) {
      io::write_text_atomic(tmp / "shots.csv", shots_csv(c));
      for (const auto& s : c.shots) {
        const fs::path from = s.source.empty() ? c.root / s.image : s.source;
        fs::create_directories((tmp / s.image).parent_path());
        fs::copy_file(from, tmp / s.image, fs::copy_options::overwrite_existing);
      }
    }
    if (c.truth_orientation) {
      Stream truth = *c.truth_orientation;
      truth.name = "orientation";
      io::write_text_atomic(tmp / "truth" / (truth.gzip ? "orientation.csv.gz" : "orientation.csv"), stream_csv(truth));
    }
    for (const auto& rel : c.other_files) {
      fs::create_directories((tmp / rel).parent_path());
      fs::copy_file(c.root / rel, tmp / rel, fs::copy_options::overwrite_existing);
    }
    for (const auto& [rel, text] : c.generated_files) {
      if (rel.is_absolute() || rel.lexically_normal().string().starts_with(".."))
        throw Error(fmt::format("generated file '{}' must be a path inside the capture", rel.string()));
      io::write_text_atomic(tmp / rel, text);
    }
  });
}

}  // namespace antpose
