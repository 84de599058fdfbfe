#include "antpose/model/mesh.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose::model {
namespace fs = std::filesystem;

namespace {

// An antenna (with its brackets) is tens of centimetres to a few metres long. Outside these
// bounds the file is in another unit or holds more than the antenna (e.g. a whole mast scan).
constexpr double kMaxExtentM = 10.0;
constexpr double kMinExtentM = 0.05;

std::optional<long long> parse_int(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

std::vector<std::string_view> split_whitespace(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Splits text into lines ('\n', with a trailing '\r' removed); calls f(line, 1-based number).
// f returns false to stop; the offset just past the stopping line is returned.
template <class F>
std::size_t for_each_line(std::string_view text, F&& f) {
  std::size_t pos = 0, number = 0;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    std::string_view line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    if (!f(line, ++number)) break;
  }
  return pos;
}

void add_polygon(Mesh& mesh, const std::vector<std::uint32_t>& polygon) {
  for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
    mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// ---------------------------------------------------------------------------------------------
// OBJ

std::uint32_t obj_index(std::string_view token, std::size_t vertex_count, const fs::path& file, std::size_t line) {
  const std::string_view first = token.substr(0, token.find('/'));
  const auto k = parse_int(first);
  if (!k) throw InputError(file, line, fmt::format("bad vertex index '{}' in face, expected an integer", token));
  const auto n = static_cast<long long>(vertex_count);
  if (*k == 0) throw InputError(file, line, "vertex index 0 in face: OBJ indices start at 1 (or are negative)");
  // Negative indices count back from the last vertex read so far (-1 is the latest).
  const long long i = *k > 0 ? *k - 1 : n + *k;
  if (i < 0 || i >= n)
    throw InputError(file, line,
                     fmt::format("vertex index {} out of range: {} vertices defined before this face", *k, n));
  return static_cast<std::uint32_t>(i);
}

Vec3 obj_vertex(const std::vector<std::string_view>& tokens, const fs::path& file, std::size_t line) {
  if (tokens.size() < 4)
    throw InputError(file, line, fmt::format("vertex has {} coordinates, expected 3 (v x y z)", tokens.size() - 1));
  Vec3 v;
  for (int k = 0; k < 3; ++k) {
    const auto x = io::parse_finite(tokens[k + 1]);
    if (!x)
      throw InputError(file, line, fmt::format("bad number '{}' in vertex, expected a finite number", tokens[k + 1]));
    v[k] = *x;
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// PLY

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };
enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
  std::size_t line = 0;  // of its header line
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  // byte offset of the data
  std::size_t body_line = 0;    // line number of the data's first line (ascii)
};

std::optional<PlyType> ply_type(std::string_view s) {
  static constexpr std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [name, type] : kNames)
    if (name == s) return type;
  return std::nullopt;
}

bool is_integer(PlyType t) { return t != PlyType::kFloat32 && t != PlyType::kFloat64; }

std::size_t type_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

PlyType header_type(std::string_view s, const fs::path& file, std::size_t line) {
  if (const auto t = ply_type(s)) return *t;
  throw InputError(file, line,
                   fmt::format("unknown property type '{}', expected char, uchar, short, ushort, int, uint, float, "
                               "double (or int8 ... float64)",
                               s));
}

PlyProperty parse_property(const std::vector<std::string_view>& t, const fs::path& file, std::size_t line) {
  PlyProperty p;
  if (t.size() == 5 && t[1] == "list") {
    p.is_list = true;
    p.count_type = header_type(t[2], file, line);
    p.type = header_type(t[3], file, line);
    p.name = std::string(t[4]);
    if (!is_integer(p.count_type))
      throw InputError(file, line, fmt::format("list count type '{}' must be an integer type", t[2]));
  } else if (t.size() == 3) {
    p.type = header_type(t[1], file, line);
    p.name = std::string(t[2]);
  } else {
    throw InputError(file, line, "bad property line, expected 'property TYPE NAME' or 'property list COUNT ITEM NAME'");
  }
  return p;
}

PlyFormat parse_format(const std::vector<std::string_view>& t, const fs::path& file, std::size_t line) {
  if (t.size() >= 2 && t[1] == "ascii") return PlyFormat::kAscii;
  if (t.size() >= 2 && t[1] == "binary_little_endian") return PlyFormat::kBinaryLittleEndian;
  if (t.size() >= 2 && t[1] == "binary_big_endian") return PlyFormat::kBinaryBigEndian;
  throw InputError(file, line,
                   fmt::format("unknown PLY format '{}', expected ascii, binary_little_endian or binary_big_endian",
                               t.size() >= 2 ? t[1] : std::string_view()));
}

void parse_header_line(const std::vector<std::string_view>& t, PlyHeader& h, const fs::path& file, std::size_t line) {
  if (t[0] == "format") {
    h.format = parse_format(t, file, line);
  } else if (t[0] == "element") {
    const auto n = t.size() == 3 ? parse_int(t[2]) : std::nullopt;
    if (!n || *n < 0) throw InputError(file, line, "bad element line, expected 'element NAME COUNT' with COUNT ≥ 0");
    h.elements.push_back(PlyElement{std::string(t[1]), static_cast<std::size_t>(*n), {}, line});
  } else if (t[0] == "property") {
    if (h.elements.empty()) throw InputError(file, line, "property before any element");
    h.elements.back().properties.push_back(parse_property(t, file, line));
  } else if (t[0] != "comment" && t[0] != "obj_info") {
    throw InputError(file, line,
                     fmt::format("unknown header keyword '{}', expected format, element, property, comment, "
                                 "obj_info or end_header",
                                 t[0]));
  }
}

PlyHeader parse_ply_header(std::string_view data, const fs::path& file) {
  PlyHeader h;
  bool ended = false, has_format = false;
  std::size_t last = 0;
  h.body_offset = for_each_line(data, [&](std::string_view line, std::size_t number) {
    last = number;
    if (number == 1) {
      if (line != "ply")
        throw InputError(file, 1,
                         fmt::format("not a PLY file: the first line is '{}', expected 'ply'", line.substr(0, 40)));
      return true;
    }
    const auto t = split_whitespace(line);
    if (t.empty()) return true;
    if (t[0] == "end_header") {
      ended = true;
      return false;  // the data starts after this line
    }
    if (t[0] == "format") has_format = true;
    parse_header_line(t, h, file, number);
    return true;
  });
  if (!ended) throw InputError(file, last, "PLY header has no end_header line");
  if (!has_format) throw InputError(file, last, "PLY header has no format line");
  h.body_line = last + 1;
  return h;
}

// What a PLY element means to the mesh reader.
struct ElementRole {
  bool is_vertex = false, is_face = false;
  std::array<int, 3> xyz = {-1, -1, -1};  // property indices of x, y, z (vertex)
  int indices = -1;                       // property index of the index list (face)
};

ElementRole element_role(const PlyElement& e, const fs::path& file) {
  ElementRole r;
  r.is_vertex = e.name == "vertex";
  r.is_face = e.name == "face";
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const PlyProperty& p = e.properties[i];
    const int k = static_cast<int>(i);
    if (r.is_vertex && !p.is_list) {
      if (p.name == "x") r.xyz[0] = k;
      if (p.name == "y") r.xyz[1] = k;
      if (p.name == "z") r.xyz[2] = k;
    }
    if (r.is_face && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      if (!p.is_list || !is_integer(p.type))
        throw InputError(file, e.line, fmt::format("face property '{}' must be a list of integers", p.name));
      r.indices = k;
    }
  }
  if (r.is_vertex && std::ranges::find(r.xyz, -1) != r.xyz.end())
    throw InputError(file, e.line, "vertex element lacks an x, y or z property");
  if (r.is_face && r.indices < 0)
    throw InputError(file, e.line, "face element has no list property 'vertex_indices' (or 'vertex_index')");
  return r;
}

// Reads the values of an ASCII body: one element instance per line, blank lines skipped.
class AsciiCursor {
 public:
  AsciiCursor(std::string_view body, std::size_t first_line, const fs::path& file)
      : body_(body), line_(first_line - 1), file_(file) {}

  void begin(const PlyElement& e, std::size_t index) {
    tokens_.clear();
    next_ = 0;
    while (tokens_.empty()) {
      if (pos_ >= body_.size())
        fail_at(line_, fmt::format("file ends after {} of {} '{}' lines", index, e.count, e.name));
      const std::size_t nl = body_.find('\n', pos_);
      const std::size_t end = nl == std::string_view::npos ? body_.size() : nl;
      tokens_ = split_whitespace(body_.substr(pos_, end - pos_));
      pos_ = nl == std::string_view::npos ? body_.size() : nl + 1;
      ++line_;
    }
    element_ = &e;
  }

  double value(PlyType type) {
    if (next_ >= tokens_.size())
      fail(fmt::format("too few values for a '{}' (the header declares more properties)", element_->name));
    const std::string_view s = tokens_[next_++];
    if (is_integer(type)) {
      if (const auto v = parse_int(s)) return static_cast<double>(*v);
      fail(fmt::format("bad number '{}', expected an integer", s));
    }
    if (const auto v = io::parse_finite(s)) return *v;
    fail(fmt::format("bad number '{}', expected a finite number", s));
  }

  void end() {
    if (next_ != tokens_.size())
      fail(fmt::format("{} values for a '{}', the header declares {}", tokens_.size(), element_->name, next_));
  }

  [[noreturn]] void fail(const std::string& message) const { fail_at(line_, message); }

 private:
  [[noreturn]] void fail_at(std::size_t line, const std::string& message) const {
    throw InputError(file_, line, message);
  }

  std::string_view body_;
  std::size_t pos_ = 0, line_;
  const fs::path& file_;
  std::vector<std::string_view> tokens_;
  std::size_t next_ = 0;
  const PlyElement* element_ = nullptr;
};

// Reads the values of a binary body, swapping bytes when the file's byte order is not the host's.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view body, std::size_t offset, bool big_endian, const fs::path& file)
      : body_(body), pos_(offset), swap_(big_endian != (std::endian::native == std::endian::big)), file_(file) {}

  void begin(const PlyElement& e, std::size_t index) { element_ = &e, index_ = index; }
  void end() {}

  double value(PlyType type) {
    const std::size_t n = type_size(type);
    if (body_.size() - pos_ < n)
      fail(fmt::format("truncated binary data: the file ends at byte {} inside a value", body_.size()));
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, n);
    pos_ += n;
    if (swap_) std::reverse(b, b + n);
    return decode(type, b);
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(file_, fmt::format("{} ('{}' {} of {})", message, element_->name, index_ + 1, element_->count));
  }

 private:
  template <class T>
  static double as(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  }

  static double decode(PlyType type, const unsigned char* b) {
    switch (type) {
      case PlyType::kInt8:
        return as<std::int8_t>(b);
      case PlyType::kUint8:
        return as<std::uint8_t>(b);
      case PlyType::kInt16:
        return as<std::int16_t>(b);
      case PlyType::kUint16:
        return as<std::uint16_t>(b);
      case PlyType::kInt32:
        return as<std::int32_t>(b);
      case PlyType::kUint32:
        return as<std::uint32_t>(b);
      case PlyType::kFloat32:
        return as<float>(b);
      case PlyType::kFloat64:
        return as<double>(b);
    }
    return 0;
  }

  std::string_view body_;
  std::size_t pos_;
  bool swap_;
  const fs::path& file_;
  const PlyElement* element_ = nullptr;
  std::size_t index_ = 0;
};

template <class Cursor>
void read_list(const PlyProperty& p, Cursor& c, std::vector<std::uint32_t>* indices, std::size_t vertex_count) {
  const double n = c.value(p.count_type);
  if (n < 0) c.fail(fmt::format("negative list length {}", n));
  if (indices) {
    if (n < 3) c.fail(fmt::format("face with {} vertices, expected at least 3", n));
    indices->clear();
  }
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    const double v = c.value(p.type);
    if (!indices) continue;
    if (v < 0 || v >= static_cast<double>(vertex_count))
      c.fail(fmt::format("vertex index {} out of range: the file has {} vertices", v, vertex_count));
    indices->push_back(static_cast<std::uint32_t>(v));
  }
}

template <class Cursor>
void read_element(const PlyElement& e, const ElementRole& role, Cursor& c, Mesh& mesh, std::size_t vertex_count,
                  std::size_t body_size) {
  if (role.is_vertex) mesh.vertices.reserve(std::min(e.count, body_size));
  std::vector<std::uint32_t> polygon;
  for (std::size_t i = 0; i < e.count; ++i) {
    c.begin(e, i);
    Vec3 v = Vec3::Zero();
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      const bool is_indices = role.is_face && static_cast<int>(k) == role.indices;
      if (p.is_list) {
        read_list(p, c, is_indices ? &polygon : nullptr, vertex_count);
        continue;
      }
      const double x = c.value(p.type);
      for (int a = 0; a < 3; ++a)
        if (role.is_vertex && role.xyz[a] == static_cast<int>(k)) v[a] = x;
    }
    c.end();
    if (role.is_vertex) {
      if (!v.allFinite()) c.fail("vertex coordinate is not a finite number");
      mesh.vertices.push_back(v);
    }
    if (role.is_face) add_polygon(mesh, polygon);
  }
}

template <class Cursor>
Mesh read_ply_body(const PlyHeader& h, Cursor& c, std::size_t body_size, const fs::path& file) {
  std::size_t vertex_count = 0;
  bool has_vertex = false;
  for (const auto& e : h.elements)
    if (e.name == "vertex") vertex_count = e.count, has_vertex = true;
  if (!has_vertex) throw InputError(file, "PLY header declares no 'vertex' element");
  if (vertex_count == 0) throw InputError(file, "no vertices: the PLY 'vertex' element has count 0");
  if (vertex_count > std::numeric_limits<std::uint32_t>::max())
    throw InputError(file, fmt::format("{} vertices, more than the 2^32 a mesh can index", vertex_count));
  Mesh mesh;
  for (const auto& e : h.elements) read_element(e, element_role(e, file), c, mesh, vertex_count, body_size);
  return mesh;
}

// ---------------------------------------------------------------------------------------------

std::string format_extension(const fs::path& file) {
  fs::path name = file.filename();
  if (lower(name.extension().string()) == ".gz") name = name.stem();
  return lower(name.extension().string());
}

std::string ply_header(std::size_t vertices, bool normals, std::size_t faces, bool with_faces) {
  std::string h = "ply\nformat ascii 1.0\ncomment written by antpose; units: metres\n";
  h += fmt::format("element vertex {}\nproperty double x\nproperty double y\nproperty double z\n", vertices);
  if (normals) h += "property double nx\nproperty double ny\nproperty double nz\n";
  if (with_faces) h += fmt::format("element face {}\nproperty list uchar int vertex_indices\n", faces);
  return h + "end_header\n";
}

}  // namespace

double metres_per_unit(Units units) { return units == Units::kMillimetres ? 1e-3 : 1.0; }

std::string to_string(Units units) { return units == Units::kMillimetres ? "mm" : "m"; }

Mesh parse_obj(std::string_view text, const fs::path& file) {
  Mesh mesh;
  std::vector<std::uint32_t> polygon;
  for_each_line(text, [&](std::string_view line, std::size_t number) {
    const auto tokens = split_whitespace(line.substr(0, line.find('#')));
    if (tokens.empty()) return true;
    if (tokens[0] == "v") {
      mesh.vertices.push_back(obj_vertex(tokens, file, number));
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4)
        throw InputError(file, number, fmt::format("face with {} vertices, expected at least 3", tokens.size() - 1));
      polygon.clear();
      for (std::size_t k = 1; k < tokens.size(); ++k)
        polygon.push_back(obj_index(tokens[k], mesh.vertices.size(), file, number));
      add_polygon(mesh, polygon);
    }
    return true;
  });
  if (mesh.vertices.empty()) throw InputError(file, "no vertices: the OBJ file has no 'v' lines");
  return mesh;
}

Mesh parse_ply(std::string_view data, const fs::path& file) {
  const PlyHeader h = parse_ply_header(data, file);
  if (h.format == PlyFormat::kAscii) {
    AsciiCursor c(data.substr(h.body_offset), h.body_line, file);
    return read_ply_body(h, c, data.size() - h.body_offset, file);
  }
  BinaryCursor c(data, h.body_offset, h.format == PlyFormat::kBinaryBigEndian, file);
  return read_ply_body(h, c, data.size() - h.body_offset, file);
}

void check_model_extent(const Mesh& mesh, const fs::path& file, Units units) {
  if (mesh.vertices.empty()) throw InputError(file, "no vertices");
  const auto [lo, hi] = bounding_box(mesh);
  const double extent = (hi - lo).maxCoeff();
  const bool mm = units == Units::kMillimetres;
  if (extent > kMaxExtentM && !mm)
    throw InputError(file, fmt::format("the model is {:.4g} m long (largest side of its bounding box) when read as "
                                       "metres, more than {:g} m: the file is almost surely in millimetres; pass "
                                       "--model-units mm",
                                       extent, kMaxExtentM));
  if (extent > kMaxExtentM)
    throw InputError(file, fmt::format("the model is {:.4g} m long (largest side of its bounding box) even when read "
                                       "as millimetres, more than {:g} m: check its units and that it holds only "
                                       "the antenna",
                                       extent, kMaxExtentM));
  if (extent < kMinExtentM && mm)
    throw InputError(file, fmt::format("the model is only {:.4g} m long (largest side of its bounding box) when read "
                                       "as millimetres, less than {:g} m: the file is probably in metres; drop "
                                       "--model-units mm",
                                       extent, kMinExtentM));
  if (extent < kMinExtentM)
    throw InputError(file, fmt::format("the model is only {:.4g} m long (largest side of its bounding box) when read "
                                       "as metres, less than {:g} m, too small for an antenna: check its units "
                                       "(metres, or millimetres with --model-units mm)",
                                       extent, kMinExtentM));
}

Mesh read_mesh(const fs::path& file, Units units) {
  const std::string ext = format_extension(file);
  if (ext != ".obj" && ext != ".ply")
    throw InputError(file, fmt::format("unknown mesh format {}, expected a .obj or .ply file (optionally .gz)",
                                       ext.empty() ? "(no extension)" : "'" + ext + "'"));
  const std::string data = io::read_text(file);
  Mesh mesh = ext == ".obj" ? parse_obj(data, file) : parse_ply(data, file);
  const double scale = metres_per_unit(units);
  if (scale != 1.0)
    for (auto& v : mesh.vertices) v *= scale;
  check_model_extent(mesh, file, units);
  return mesh;
}

std::string format_ply(const Mesh& mesh) {
  fmt::memory_buffer out;
  const std::string header = ply_header(mesh.vertices.size(), false, mesh.triangles.size(), true);
  out.append(header.data(), header.data() + header.size());
  for (const auto& v : mesh.vertices) fmt::format_to(std::back_inserter(out), "{} {} {}\n", v.x(), v.y(), v.z());
  for (const auto& t : mesh.triangles) fmt::format_to(std::back_inserter(out), "3 {} {} {}\n", t[0], t[1], t[2]);
  return fmt::to_string(out);
}

std::string format_ply(const PointCloud& cloud) {
  fmt::memory_buffer out;
  const bool normals = cloud.has_normals();
  const std::string header = ply_header(cloud.size(), normals, 0, false);
  out.append(header.data(), header.data() + header.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    fmt::format_to(std::back_inserter(out), "{} {} {}", p.x(), p.y(), p.z());
    if (normals)
      fmt::format_to(std::back_inserter(out), " {} {} {}", cloud.normals[i].x(), cloud.normals[i].y(),
                     cloud.normals[i].z());
    out.push_back('\n');
  }
  return fmt::to_string(out);
}

void write_ply(const Mesh& mesh, const fs::path& file) { io::write_text_atomic(file, format_ply(mesh)); }

void write_ply(const PointCloud& cloud, const fs::path& file) { io::write_text_atomic(file, format_ply(cloud)); }

Mesh transformed(const Mesh& mesh, const Iso3& T) {
  Mesh out;
  out.triangles = mesh.triangles;
  out.vertices.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) out.vertices.push_back(T * v);
  return out;
}

void append_mesh(Mesh& mesh, const Mesh& part) {
  const auto offset = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const auto& t : part.triangles) mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
}

std::pair<Vec3, Vec3> bounding_box(const Mesh& mesh) {
  if (mesh.vertices.empty()) return {Vec3::Zero(), Vec3::Zero()};
  Vec3 lo = mesh.vertices.front(), hi = lo;
  for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return {lo, hi};
}

namespace {
Vec3 area_vector(const Mesh& mesh, std::size_t i) {  // (b − a) × (c − a): twice the area, along the normal
  const auto& t = mesh.triangles[i];
  const Vec3& a = mesh.vertices[t[0]];
  return (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
}
}  // namespace

double triangle_area(const Mesh& mesh, std::size_t i) { return 0.5 * area_vector(mesh, i).norm(); }

Vec3 triangle_normal(const Mesh& mesh, std::size_t i) {
  const Vec3 n = area_vector(mesh, i);
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

double surface_area(const Mesh& mesh) {
  double sum = 0;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) sum += triangle_area(mesh, i);
  return sum;
}

double enclosed_volume(const Mesh& mesh) {
  double sum = 0;
  for (const auto& t : mesh.triangles) sum += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return sum / 6.0;
}

bool is_closed(const Mesh& mesh) {
  // Each directed edge must occur once and its reverse once: then every edge has exactly two
  // triangles, wound consistently.
  const auto key = [](std::uint32_t a, std::uint32_t b) { return (static_cast<std::uint64_t>(a) << 32) | b; };
  std::unordered_map<std::uint64_t, int> directed;
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return false;
    for (int k = 0; k < 3; ++k)
      if (++directed[key(t[k], t[(k + 1) % 3])] > 1) return false;
  }
  for (const auto& [edge, count] : directed) {
    const auto a = static_cast<std::uint32_t>(edge >> 32), b = static_cast<std::uint32_t>(edge);
    if (!directed.contains(key(b, a))) return false;
  }
  return !mesh.triangles.empty();
}

}  // namespace antpose::model
