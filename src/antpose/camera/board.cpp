#include "antpose/camera/board.hpp"

#include <array>
#include <utility>

#include <fmt/core.h>
#include <opencv2/aruco.hpp>

#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose::camera {
namespace fs = std::filesystem;

namespace {

struct TypeName {
  BoardType type;
  const char* name;
};
constexpr std::array<TypeName, 4> kTypes{{{BoardType::kChessboard, "chessboard"},
                                          {BoardType::kCircles, "circles"},
                                          {BoardType::kAsymmetricCircles, "asymmetric-circles"},
                                          {BoardType::kCharuco, "charuco"}}};

struct DictName {
  const char* name;
  int id;
};
constexpr std::array<DictName, 21> kDictionaries{{
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},       {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},     {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},       {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},     {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},       {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},     {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},       {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},     {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
    {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
    {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
    {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
    {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11},
}};

}  // namespace

std::string to_string(BoardType type) {
  for (const auto& t : kTypes)
    if (t.type == type) return t.name;
  return "unknown";
}

int aruco_dictionary_id(const std::string& name) {
  for (const auto& d : kDictionaries)
    if (name == d.name) return d.id;
  return -1;
}

int BoardSpec::point_count() const {
  return type == BoardType::kCharuco ? (cols - 1) * (rows - 1) : cols * rows;
}

std::vector<Vec3> BoardSpec::object_points() const {
  std::vector<Vec3> p;
  p.reserve(static_cast<std::size_t>(std::max(point_count(), 0)));
  switch (type) {
    case BoardType::kChessboard:
    case BoardType::kCircles:
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) p.emplace_back(c * square_m, r * square_m, 0.0);
      break;
    case BoardType::kAsymmetricCircles:
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) p.emplace_back((2 * c + r % 2) * square_m, r * square_m, 0.0);
      break;
    case BoardType::kCharuco:
      for (int r = 0; r < rows - 1; ++r)
        for (int c = 0; c < cols - 1; ++c) p.emplace_back((c + 1) * square_m, (r + 1) * square_m, 0.0);
      break;
  }
  return p;
}

std::pair<Vec3, Vec3> BoardSpec::extent() const {
  const double s = square_m;
  switch (type) {
    case BoardType::kChessboard:  // one outer square around the inner corners
      return {Vec3(-s, -s, 0.0), Vec3(cols * s, rows * s, 0.0)};
    case BoardType::kCircles:  // circles of diameter ≈ s/2 around the centres
      return {Vec3(-0.5 * s, -0.5 * s, 0.0), Vec3((cols - 0.5) * s, (rows - 0.5) * s, 0.0)};
    case BoardType::kAsymmetricCircles:
      return {Vec3(-0.5 * s, -0.5 * s, 0.0), Vec3((2 * cols - 0.5) * s, (rows - 0.5) * s, 0.0)};
    case BoardType::kCharuco:
      return {Vec3::Zero(), Vec3(cols * s, rows * s, 0.0)};
  }
  return {Vec3::Zero(), Vec3::Zero()};
}

BoardSpec parse_board(const std::string& text, const fs::path& file) {
  const YAML::Node d = io::load_yaml(text, file);
  if (!d.IsMap()) throw InputError(file, "expected a YAML map with type, cols, rows and square_m (a board description)");
  BoardSpec b;
  const YAML::Node type = io::yaml_required(d, "type", file, "type");
  const std::string name = io::yaml_string(type, file, "type");
  bool known = false;
  for (const auto& t : kTypes)
    if (name == t.name) b.type = t.type, known = true;
  if (!known)
    throw InputError(file, io::line_of(type),
                     fmt::format("type is '{}', expected chessboard, circles, asymmetric-circles or charuco", name));
  const int min_count = b.type == BoardType::kCharuco ? 3 : 2;
  auto count = [&](const char* key) {
    const YAML::Node n = io::yaml_required(d, key, file, key);
    const long long v = io::yaml_integer(n, file, key);
    if (v < min_count || v > 1000)
      throw InputError(file, io::line_of(n), fmt::format("{} is {}, expected an integer from {} to 1000", key, v, min_count));
    return static_cast<int>(v);
  };
  b.cols = count("cols");
  b.rows = count("rows");
  const YAML::Node sq = io::yaml_required(d, "square_m", file, "square_m");
  b.square_m = io::yaml_number(sq, file, "square_m");
  if (!(b.square_m > 0.0 && b.square_m < 10.0))
    throw InputError(file, io::line_of(sq), fmt::format("square_m is {} m, expected a side between 0 and 10 m", b.square_m));
  if (b.type == BoardType::kCharuco) {
    const YAML::Node mk = io::yaml_required(d, "marker_m", file, "marker_m (charuco)");
    b.marker_m = io::yaml_number(mk, file, "marker_m");
    if (!(b.marker_m > 0.0 && b.marker_m < b.square_m))
      throw InputError(file, io::line_of(mk),
                       fmt::format("marker_m is {} m, expected a marker side between 0 and square_m = {} m", b.marker_m,
                                   b.square_m));
    const YAML::Node dict = io::yaml_required(d, "dictionary", file, "dictionary (charuco)");
    b.dictionary = io::yaml_string(dict, file, "dictionary");
    if (aruco_dictionary_id(b.dictionary) < 0) {
      std::string names;
      for (const auto& x : kDictionaries) names += std::string(names.empty() ? "" : ", ") + x.name;
      throw InputError(file, io::line_of(dict),
                       fmt::format("dictionary '{}' is not an OpenCV ArUco dictionary; expected one of {}", b.dictionary,
                                   names));
    }
    // A ChArUco board has a marker in every other square, each of them distinct: a board with
    // more markers than its dictionary holds cannot exist (and its detection would search for
    // minutes per photo).
    const int markers = b.cols * b.rows / 2;
    const int available = cv::aruco::getPredefinedDictionary(aruco_dictionary_id(b.dictionary))->bytesList.rows;
    if (markers > available)
      throw InputError(
          file, io::line_of(dict),
          fmt::format("a {}×{} ChArUco board has {} markers but the dictionary {} holds {}: check cols and "
                      "rows, or the dictionary",
                      b.cols, b.rows, markers, b.dictionary, available));
  }
  return b;
}

BoardSpec read_board(const fs::path& file) { return parse_board(io::read_text(file), file); }

std::string format_board(const BoardSpec& b) {
  std::string s = fmt::format("type: {}\ncols: {}\nrows: {}\nsquare_m: {}\n", to_string(b.type), b.cols, b.rows,
                              io::format_number(b.square_m));
  if (b.type == BoardType::kCharuco)
    s += fmt::format("marker_m: {}\ndictionary: {}\n", io::format_number(b.marker_m), b.dictionary);
  return s;
}

}  // namespace antpose::camera
