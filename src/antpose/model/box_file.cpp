#include "antpose/model/box_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose::model {
namespace fs = std::filesystem;

namespace {

// Corners are picked by hand on a scan (thesis fig. 6.4), so a real box file is a box only to
// within the picking error: a few millimetres on edges of 0.1–2 m. 2° and 2 % accept that and
// still catch a typo, a swapped pair of labels or corners of two different boxes.
constexpr double kAngleToleranceDeg = 2.0;
constexpr double kLengthTolerance = 0.02;
// Shorter than any part of an antenna: two corners this close are the same point typed twice.
constexpr double kMinEdgeM = 1e-3;

constexpr char kLabels[] = "ABCDEFGH";
enum Corner { A, B, C, D, E, F, G, H };

struct Edge {
  int from, to;
};

// The four parallel edges along x_a, y_a and z_a, each pointing along its axis.
constexpr Edge kEdges[3][4] = {
    {{A, B}, {D, C}, {E, F}, {H, G}}, {{A, D}, {B, C}, {E, H}, {F, G}}, {{E, A}, {F, B}, {G, C}, {H, D}}};
constexpr const char* kAxisNames[3] = {"x_a (width)", "y_a (depth)", "z_a (height)"};

using Corners = std::array<Vec3, 8>;
using Lines = std::array<std::size_t, 8>;

std::string edge_name(Edge e) { return {kLabels[e.from], kLabels[e.to]}; }

Vec3 vec(const Corners& c, Edge e) { return c[e.to] - c[e.from]; }

// " (lines 3 and 7)" for the corners of an edge, empty without line numbers.
std::string lines_of(const Lines& lines, std::initializer_list<int> corners) {
  std::vector<std::size_t> found;
  for (int k : corners)
    if (lines[k] > 0) found.push_back(lines[k]);
  if (found.size() != corners.size()) return "";
  if (found.size() == 2) return fmt::format(" (lines {} and {})", found[0], found[1]);
  return fmt::format(" (lines {})", fmt::join(found, ", "));
}

void check_not_degenerate(const Corners& c, const Lines& lines, const fs::path& file) {
  for (const auto& group : kEdges)
    for (const Edge e : group) {
      const double len = vec(c, e).norm();
      if (len < kMinEdgeM)
        throw InputError(file, fmt::format("edge {} is {:.3g} m long: corners {} and {}{} (nearly) coincide; the "
                                           "edges of a box must be at least {:g} m",
                                           edge_name(e), len, kLabels[e.from], kLabels[e.to],
                                           lines_of(lines, {e.from, e.to}), kMinEdgeM));
    }
}

void check_parallel(const Corners& c, const Lines& lines, const fs::path& file, int axis) {
  const Edge ref = kEdges[axis][0];
  for (int k = 1; k < 4; ++k) {
    const Edge e = kEdges[axis][k];
    const double angle = rad2deg(angle_between(vec(c, ref), vec(c, e)));
    if (angle > 180.0 - kAngleToleranceDeg)
      throw InputError(file, fmt::format("edge {} runs opposite to {} (both should point along {}): either {} and {}{} "
                                         "or {} and {}{} seem swapped",
                                         edge_name(e), edge_name(ref), kAxisNames[axis], kLabels[ref.from],
                                         kLabels[ref.to], lines_of(lines, {ref.from, ref.to}), kLabels[e.from],
                                         kLabels[e.to], lines_of(lines, {e.from, e.to})));
    if (angle > kAngleToleranceDeg)
      throw InputError(file, fmt::format("not a box: edges {} and {} should be parallel (along {}) but are {:.2f}° "
                                         "apart (tolerance {:g}°); check corners {} and {}{}",
                                         edge_name(ref), edge_name(e), kAxisNames[axis], angle, kAngleToleranceDeg,
                                         kLabels[e.from], kLabels[e.to], lines_of(lines, {e.from, e.to})));
  }
}

double relative_spread(const std::vector<double>& len) {
  const auto [lo, hi] = std::ranges::minmax(len);
  return (hi - lo) / hi;
}

// " DC (lines 4 and 3) is the odd one out" when exactly one edge disagrees with the other three.
std::string odd_one_out(const std::vector<double>& len, const Lines& lines, int axis) {
  int odd = -1;
  for (int k = 0; k < 4; ++k) {
    std::vector<double> others = len;
    others.erase(others.begin() + k);
    if (relative_spread(others) > kLengthTolerance) continue;
    if (odd >= 0) return "";
    odd = k;
  }
  if (odd < 0) return "";
  const Edge e = kEdges[axis][odd];
  return fmt::format("; {}{} is the odd one out", edge_name(e), lines_of(lines, {e.from, e.to}));
}

void check_equal_lengths(const Corners& c, const Lines& lines, const fs::path& file, int axis) {
  std::vector<double> len;
  for (const Edge e : kEdges[axis]) len.push_back(vec(c, e).norm());
  const double spread = relative_spread(len);
  if (spread <= kLengthTolerance) return;
  throw InputError(file, fmt::format("not a box: the four edges along {} should be equal but are {} = {:.4g} m, {} = "
                                     "{:.4g} m, {} = {:.4g} m, {} = {:.4g} m ({:.1f} % apart, tolerance {:g} %){}",
                                     kAxisNames[axis], edge_name(kEdges[axis][0]), len[0], edge_name(kEdges[axis][1]),
                                     len[1], edge_name(kEdges[axis][2]), len[2], edge_name(kEdges[axis][3]), len[3],
                                     100 * spread, 100 * kLengthTolerance, odd_one_out(len, lines, axis)));
}

void check_perpendicular_at_a(const Corners& c, const Lines& lines, const fs::path& file) {
  constexpr std::pair<int, int> kPairs[] = {{B, D}, {B, E}, {D, E}};
  for (const auto& [p, q] : kPairs) {
    const double angle = rad2deg(angle_between(c[p] - c[A], c[q] - c[A]));
    if (std::abs(angle - 90.0) > kAngleToleranceDeg)
      throw InputError(file, fmt::format("not a box: edges A{} and A{} should be perpendicular but meet at {:.2f}° "
                                         "(tolerance {:g}°); check corners A, {} and {}{}",
                                         kLabels[p], kLabels[q], angle, kAngleToleranceDeg, kLabels[p], kLabels[q],
                                         lines_of(lines, {A, p, q})));
  }
}

// The box's mean edge vector along each antenna axis (columns x, y, z).
Mat3 mean_edges(const Corners& c) {
  Mat3 M;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 sum = Vec3::Zero();
    for (const Edge e : kEdges[axis]) sum += vec(c, e);
    M.col(axis) = sum / 4.0;
  }
  return M;
}

void check_right_handed(const Mat3& edges, const fs::path& file) {
  if (edges.col(0).cross(edges.col(1)).dot(edges.col(2)) > 0) return;
  // A consistent mirror is one pair of opposite faces exchanged. Which one cannot be told from
  // the box alone; a panel is wider than deep, so depth > width hints at B/D exchanged.
  const bool width_depth_swapped = edges.col(1).norm() > edges.col(0).norm();
  const std::string likely =
      width_depth_swapped
          ? "AD is longer than AB, so B and D (and F and H) seem swapped: AB should run across the wide back plate"
          : "probably left and right are swapped (A↔B, D↔C, E↔F, H↔G) or front and back (A↔D, B↔C, E↔H, F↔G)";
  throw InputError(file, fmt::format("the corners form a mirrored box: AB × AD points along AE (down the panel), "
                                     "but the antenna frame needs x_a × y_a = z_a, i.e. along EA (up); {}. Seen "
                                     "from behind the antenna with its top up, B must be right of A, D in front of "
                                     "A (towards the radome) and E below A",
                                     likely));
}


int corner_index(const std::string& label, const fs::path& file, std::size_t line) {
  if (label.size() == 1) {
    const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(label[0])));
    if (u >= 'A' && u <= 'H') return u - 'A';
  }
  throw InputError(file, line, fmt::format("unknown corner label '{}', expected one of A B C D E F G H", label));
}

void require_all_corners(const Lines& lines, const fs::path& file) {
  std::vector<char> missing;
  for (int k = 0; k < 8; ++k)
    if (lines[k] == 0) missing.push_back(kLabels[k]);
  if (!missing.empty())
    throw InputError(file, fmt::format("missing corner{} {}: a box file needs each of A B C D E F G H exactly once",
                                       missing.size() > 1 ? "s" : "", fmt::join(missing, ", ")));
}

}  // namespace

AntennaBox fit_box(const Corners& corners, const fs::path& file, const Lines& lines) {
  check_not_degenerate(corners, lines, file);
  for (int axis = 0; axis < 3; ++axis) check_parallel(corners, lines, file, axis);
  for (int axis = 0; axis < 3; ++axis) check_equal_lengths(corners, lines, file, axis);
  check_perpendicular_at_a(corners, lines, file);
  const Mat3 edges = mean_edges(corners);
  check_right_handed(edges, file);

  Mat3 rows;
  for (int axis = 0; axis < 3; ++axis) rows.row(axis) = edges.col(axis).normalized().transpose();
  Vec3 centre = Vec3::Zero();
  for (const auto& p : corners) centre += p / 8.0;
  AntennaBox box;
  box.T_antenna_mesh.linear() = nearest_rotation(rows);
  box.T_antenna_mesh.translation() = -(box.T_antenna_mesh.linear() * centre);
  box.size_m = edges.colwise().norm().transpose();
  return box;
}

AntennaBox parse_box_file(const std::string& text, const fs::path& file, Units units) {
  Corners corners;
  Lines lines{};
  std::istringstream in(text);
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::istringstream tokens(line.substr(0, line.find('#')));
    std::vector<std::string> t{std::istream_iterator<std::string>(tokens), std::istream_iterator<std::string>()};
    if (t.empty()) continue;
    if (t.size() != 4)
      throw InputError(file, number,
                       fmt::format("{} fields, expected 'LABEL x y z' (e.g. 'A 0.1 -0.2 0.65')", t.size()));
    const int k = corner_index(t[0], file, number);
    if (lines[k] != 0)
      throw InputError(file, number, fmt::format("corner {} given twice (first on line {})", kLabels[k], lines[k]));
    for (int a = 0; a < 3; ++a) {
      const auto v = io::parse_finite(t[a + 1]);
      if (!v) throw InputError(file, number, fmt::format("bad number '{}' for corner {}", t[a + 1], kLabels[k]));
      corners[k][a] = *v * metres_per_unit(units);
    }
    lines[k] = number;
  }
  require_all_corners(lines, file);
  return fit_box(corners, file, lines);
}

AntennaBox read_box_file(const fs::path& file, Units units) { return parse_box_file(io::read_text(file), file, units); }

std::array<Vec3, 8> box_corners(const Vec3& size_m, const Iso3& T_mesh_antenna) {
  const Vec3 h = size_m / 2;
  // Signs of (x, y, z) per corner: A back-left-top, B back-right-top, C front-right-top, ...
  constexpr int kSigns[8][3] = {{-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1},
                                {-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}};
  std::array<Vec3, 8> out;
  for (int k = 0; k < 8; ++k)
    out[k] = T_mesh_antenna * Vec3(kSigns[k][0] * h.x(), kSigns[k][1] * h.y(), kSigns[k][2] * h.z());
  return out;
}

std::string format_box_file(const std::array<Vec3, 8>& corners_mesh) {
  std::string out = "# antenna box: ABCD top face, ABFE against the back plate, E..H below A..D\n";
  for (int k = 0; k < 8; ++k)
    out += fmt::format("{} {} {} {}\n", kLabels[k], corners_mesh[k].x(), corners_mesh[k].y(), corners_mesh[k].z());
  return out;
}

}  // namespace antpose::model
