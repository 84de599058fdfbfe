// The thesis's collection-app project (capture-format.md §2) → Capture.
//
// collection-proj.xml survives only as a partial screenshot, so elements are matched without
// regard to case and unknown ones are ignored. Sensor frames carry UTC seconds as doubles
// (resolution 2.4e-7 s near 1.4e9 s); io::seconds_since keeps that resolution in t.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "antpose/io/csv.hpp"
#include "antpose/io/import.hpp"
#include "antpose/io/file_access.hpp"
#include "antpose/io/import_detail.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/time.hpp"

namespace antpose {
namespace fs = std::filesystem;
using io::detail::lower;

namespace {

// An XML file kept in memory, so element offsets can be turned into line numbers.
struct XmlFile {
  fs::path file;
  std::string text;
  pugi::xml_document doc;
  std::vector<std::size_t> line_starts;

  explicit XmlFile(fs::path path) : file(std::move(path)), text(io::read_text(file)) {
    line_starts.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') line_starts.push_back(i + 1);
    const auto result = doc.load_buffer(text.data(), text.size());
    if (!result) throw InputError(file, line_of(static_cast<std::size_t>(result.offset)), fmt::format("not valid XML: {}", result.description()));
  }
  std::size_t line_of(std::size_t offset) const {
    return static_cast<std::size_t>(std::upper_bound(line_starts.begin(), line_starts.end(), offset) - line_starts.begin());
  }
  std::size_t line(const pugi::xml_node& n) const {
    const auto off = n.offset_debug();
    return off < 0 ? 0 : line_of(static_cast<std::size_t>(off));
  }
};

pugi::xml_node child_ci(const pugi::xml_node& n, std::string_view name) {
  for (auto c : n.children())
    if (c.type() == pugi::node_element && lower(c.name()) == name) return c;
  return {};
}

std::vector<pugi::xml_node> children_ci(const pugi::xml_node& n, std::string_view name) {
  std::vector<pugi::xml_node> out;
  for (auto c : n.children())
    if (c.type() == pugi::node_element && lower(c.name()) == name) out.push_back(c);
  return out;
}

// All elements named `name` below n (any depth), in document order.
std::vector<pugi::xml_node> descendants_ci(const pugi::xml_node& n, std::string_view name) {
  std::vector<pugi::xml_node> out;
  for (auto c : n.children()) {
    if (c.type() != pugi::node_element) continue;
    if (lower(c.name()) == name) out.push_back(c);
    else {
      auto sub = descendants_ci(c, name);
      out.insert(out.end(), sub.begin(), sub.end());
    }
  }
  return out;
}

std::string trimmed_text(const pugi::xml_node& n) {
  std::string s = n.text().get();
  const auto a = s.find_first_not_of(" \t\r\n");
  const auto b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The text of a required child element, or an error naming the element's line.
std::string required_text(const XmlFile& x, const pugi::xml_node& parent, std::string_view child, std::string_view what) {
  const auto n = child_ci(parent, child);
  if (!n) throw InputError(x.file, x.line(parent), fmt::format("<{}> has no <{}> ({})", parent.name(), child, what));
  std::string s = trimmed_text(n);
  if (s.empty()) throw InputError(x.file, x.line(n), fmt::format("<{}> is empty ({})", n.name(), what));
  return s;
}

double required_number(const XmlFile& x, const pugi::xml_node& parent, std::string_view child, std::string_view what) {
  const auto text = required_text(x, parent, child, what);
  return io::parse_number(text, x.file, x.line(child_ci(parent, child)), std::string("<") + std::string(child) + ">");
}

struct Frame {
  double utc;
  Vec3 v;
  std::size_t file;  // index into the list of sensor files
  std::size_t line;
};

struct Channel {
  const char* stream;
  const char* unit;
};

const std::map<std::string, Channel> kChannels = {
    {"a", {"accelerometer", "m/s^2"}}, {"m", {"magnetometer", "µT"}}, {"g", {"gyroscope", "rad/s"}}};

}  // namespace

Capture import_thesis_project(const fs::path& in, Diagnostics& diagnostics, const CaptureReadOptions& options) {
  const fs::path folder = fs::is_regular_file(in) ? in.parent_path() : in;
  const fs::path proj_file = fs::is_regular_file(in) ? in : folder / "collection-proj.xml";
  const XmlFile proj(proj_file);
  const auto root = child_ci(proj.doc, "project");
  if (!root) throw InputError(proj_file, 1, "no <project> element, expected the thesis app's collection-proj.xml");

  Capture c;
  c.root = folder;
  c.kind = "imu-log";
  c.sensor_frame = "android";
  io::detail::SourceRecord src;
  src.format = "thesis-project";
  src.path = folder;
  src.read.push_back("collection-proj.xml");
  if (auto n = child_ci(root, "name")) src.extra["project"]["name"] = trimmed_text(n);
  if (auto n = child_ci(root, "description")) src.extra["project"]["description"] = trimmed_text(n);
  if (auto n = child_ci(root, "createtime"); n && !trimmed_text(n).empty()) {
    const double ct =
        io::checked_unix_seconds(io::parse_number(trimmed_text(n), proj_file, proj.line(n), "<createTime>"), proj_file,
                                 proj.line(n), "<createTime>");
    src.extra["project"]["create_time"] = io::format_utc_iso8601(io::unix_seconds_to_ns_us(ct), 6);
  }

  struct Collection {
    int index;
    double utc;
    std::string picture;
    std::size_t line;
  };
  std::vector<Collection> collections;
  std::vector<fs::path> sensor_files;
  const auto coll_parent = child_ci(root, "collections");
  for (const auto& node : coll_parent ? children_ci(coll_parent, "collection") : children_ci(root, "collection")) {
    const std::size_t line = proj.line(node);
    const double index = required_number(proj, node, "index", "the photo number");
    if (index < 0 || index != std::floor(index))
      throw InputError(proj_file, line, fmt::format("<index> {} is not a non-negative integer", index));
    Collection col{static_cast<int>(index), 0.0, {}, line};
    col.utc = io::checked_unix_seconds(required_number(proj, node, "time", "shot time in UTC seconds since 1970"),
                                       proj_file, line, "<time>");
    if (auto pic = child_ci(node, "picture"); pic && !trimmed_text(pic).empty()) {
      col.picture = trimmed_text(pic);
      if (!fs::is_regular_file(io::path_inside(folder, col.picture, {proj_file, proj.line(pic), "picture"})))
        throw InputError(proj_file, proj.line(pic), fmt::format("picture '{}' not found in {}", col.picture, folder.string()));
    }
    if (auto sen = child_ci(node, "sensor"); sen && !trimmed_text(sen).empty()) {
      const fs::path f = io::path_inside(folder, trimmed_text(sen), {proj_file, proj.line(sen), "sensor"});
      if (!fs::is_regular_file(f))
        throw InputError(proj_file, proj.line(sen), fmt::format("sensor file '{}' not found in {}", trimmed_text(sen), folder.string()));
      if (std::find(sensor_files.begin(), sensor_files.end(), f) == sensor_files.end()) sensor_files.push_back(f);
    }
    collections.push_back(std::move(col));
  }
  if (collections.empty()) throw InputError(proj_file, proj.line(root), "no <collection> entries: the project has no photos or sensor data");

  // Frames per channel, in file order; within a file time must not go backwards.
  std::map<std::string, std::vector<Frame>> frames;
  for (std::size_t fi = 0; fi < sensor_files.size(); ++fi) {
    const XmlFile x(sensor_files[fi]);
    src.read.push_back(sensor_files[fi].filename().string());
    for (const auto& ch : descendants_ci(x.doc, "channel")) {
      const std::string name = lower(required_text(x, ch, "name", "channel a, m or g"));
      if (!kChannels.contains(name)) {
        diagnostics.warn(x.file, x.line(ch), fmt::format("channel '{}' is unknown (expected a, m or g): skipped", name));
        continue;
      }
      auto& out = frames[name];
      double prev = -INFINITY;
      for (const auto& fr : descendants_ci(ch, "frame")) {
        const std::size_t line = x.line(fr);
        const auto value = child_ci(fr, "value");
        if (!value) throw InputError(x.file, line, "<frame> has no <value> with x, y, z");
        Frame f{
            io::checked_unix_seconds(required_number(x, fr, "time", "UTC seconds since 1970"), x.file, line, "<time>"),
            Vec3(required_number(x, value, "x", "a number"), required_number(x, value, "y", "a number"),
                 required_number(x, value, "z", "a number")),
            fi, line};
        if (f.utc < prev)
          throw InputError(x.file, line, fmt::format("frame time {} goes backwards (previous frame of channel {} at {})",
                                                     io::format_number(f.utc), name, io::format_number(prev)));
        prev = f.utc;
        out.push_back(f);
      }
    }
  }

  // Merge overlapping files: a stable sort keeps the earlier file first among equal times.
  std::size_t dropped = 0, disagreeing = 0;
  for (auto& [name, fs_] : frames) {
    std::stable_sort(fs_.begin(), fs_.end(), [](const Frame& a, const Frame& b) { return a.utc < b.utc; });
    std::vector<Frame> merged;
    merged.reserve(fs_.size());
    for (const auto& f : fs_) {
      if (!merged.empty() && merged.back().utc == f.utc) {
        const Frame& kept = merged.back();
        if (kept.v == f.v) {
          ++dropped;
        } else {
          ++disagreeing;
          diagnostics.warn(sensor_files[f.file], f.line,
                           fmt::format("channel {} frame at UTC {} s disagrees with {}:{} at the same time ({} vs {}); kept the "
                                       "frame of {}",
                                       name, io::format_number(f.utc), sensor_files[kept.file].filename().string(), kept.line,
                                       fmt::format("{:.9g},{:.9g},{:.9g}", f.v.x(), f.v.y(), f.v.z()),
                                       fmt::format("{:.9g},{:.9g},{:.9g}", kept.v.x(), kept.v.y(), kept.v.z()),
                                       sensor_files[kept.file].filename().string()));
        }
        continue;
      }
      merged.push_back(f);
    }
    fs_ = std::move(merged);
  }

  // One clock: the earliest sample or shot, to the µs, rounded down.
  double earliest = INFINITY;
  for (const auto& [name, fs_] : frames)
    if (!fs_.empty()) earliest = std::min(earliest, fs_.front().utc);
  for (const auto& col : collections) earliest = std::min(earliest, col.utc);
  const std::int64_t origin = io::unix_seconds_to_ns_us(earliest, io::Rounding::kDown);
  c.time_origin = io::format_utc_iso8601(origin, 6);

  for (const auto& [name, fs_] : frames) {
    if (fs_.empty()) continue;
    std::vector<double> t(fs_.size());
    std::vector<Vec3> v(fs_.size());
    for (std::size_t i = 0; i < fs_.size(); ++i) {
      t[i] = io::seconds_since(fs_[i].utc, origin);
      v[i] = fs_[i].v;
    }
    const Channel& ch = kChannels.at(name);
    Stream s = Stream::vector3(ch.stream, std::move(t), v);
    s.source_file = folder / fmt::format("sensor_*.xml (channel {})", name);
    c.streams.emplace(s.name, std::move(s));
  }
  if (c.streams.empty()) throw InputError(proj_file, "the sensor files hold no frames of channels a, m or g");

  c.shots_file = proj_file;
  for (const auto& col : collections) {
    if (col.picture.empty()) continue;
    Shot shot;
    shot.index = col.index;
    shot.t = io::seconds_since(col.utc, origin);
    shot.image = (fs::path("images") / fs::path(col.picture).filename()).generic_string();
    shot.source = folder / col.picture;
    shot.source_line = col.line;
    c.shots.push_back(std::move(shot));
  }
  std::sort(c.shots.begin(), c.shots.end(), [](const Shot& a, const Shot& b) { return a.index < b.index; });

  src.assumptions.push_back("times: UTC seconds since 1970; t = utc − time_origin (the earliest sample or shot, to the µs)");
  src.assumptions.push_back("channels a, m, g: accelerometer m/s^2 (with gravity), magnetometer µT, gyroscope rad/s (thesis fig. 7.7)");
  src.assumptions.push_back("frame: Android device frame (the app is an Android app)");
  src.assumptions.push_back(fmt::format("overlapping sensor files merged: {} duplicate frames dropped, {} disagreeing frames "
                                        "(first kept)",
                                        dropped, disagreeing));
  c.metadata["source"] = src.to_yaml();
  validate_capture(c, folder, diagnostics, options);
  return c;
}

}  // namespace antpose
