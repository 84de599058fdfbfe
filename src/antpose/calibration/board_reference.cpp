#include "antpose/calibration/board_reference.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"

namespace antpose::calibration {

char to_char(BoardAxis axis) { return "XYZ"[static_cast<int>(axis)]; }
char to_char(AngleReference ref) { return ref == AngleReference::kGravity ? 'G' : 'N'; }

std::vector<std::string> BoardReference::placements() const {
  std::vector<std::string> out;
  for (const auto& l : lines)
    if (std::find(out.begin(), out.end(), l.placement) == out.end()) out.push_back(l.placement);
  return out;
}

std::vector<BoardReferenceLine> BoardReference::lines_of(const std::string& placement) const {
  std::vector<BoardReferenceLine> out;
  for (const auto& l : lines)
    if (l.placement == placement) out.push_back(l);
  return out;
}

BoardReference read_board_reference(const std::filesystem::path& file) {
  const io::CsvText csv = io::read_csv(file);
  const std::size_t cp = csv.column("placement"), ca = csv.column("axis"), cr = csv.column("ref"),
                    cv = csv.column("angle_deg");
  BoardReference out;
  out.file = file;
  std::map<std::tuple<std::string, BoardAxis, AngleReference>, std::size_t> seen;  // → line
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const auto& row = csv.rows[i];
    const std::size_t line = csv.lines[i];
    BoardReferenceLine l;
    l.line = line;
    l.placement = row[cp];
    if (l.placement.empty()) throw InputError(file, line, "column 'placement' is empty, expected the name of a placement");
    const std::string& axis = row[ca];
    if (axis == "X" || axis == "x") l.axis = BoardAxis::kX;
    else if (axis == "Y" || axis == "y") l.axis = BoardAxis::kY;
    else if (axis == "Z" || axis == "z") l.axis = BoardAxis::kZ;
    else throw InputError(file, line, fmt::format("column 'axis': '{}' is not a board axis, expected X, Y or Z", axis));
    const std::string& ref = row[cr];
    if (ref == "G" || ref == "g") l.ref = AngleReference::kGravity;
    else if (ref == "N" || ref == "n") l.ref = AngleReference::kNorth;
    else
      throw InputError(file, line,
                       fmt::format("column 'ref': '{}' is not a reference, expected G (angle from straight down) or N "
                                   "(clockwise from north)",
                                   ref));
    const double deg = io::parse_number(row[cv], file, line, "angle_deg");
    if (l.ref == AngleReference::kGravity && !(deg >= 0.0 && deg <= 180.0))
      throw InputError(file, line, fmt::format("column 'angle_deg': {} is outside [0, 180] (a G angle)", row[cv]));
    if (l.ref == AngleReference::kNorth && !(deg >= 0.0 && deg < 360.0))
      throw InputError(file, line, fmt::format("column 'angle_deg': {} is outside [0, 360) (an N angle)", row[cv]));
    l.angle = deg2rad(deg);
    const auto key = std::make_tuple(l.placement, l.axis, l.ref);
    if (const auto it = seen.find(key); it != seen.end())
      throw InputError(file, line,
                       fmt::format("placement '{}', axis {}, ref {} repeats line {}; give each angle once",
                                   l.placement, to_char(l.axis), to_char(l.ref), it->second));
    seen.emplace(key, line);
    out.lines.push_back(std::move(l));
  }
  if (out.lines.empty()) throw InputError(file, "no reference lines (expected placement,axis,ref,angle_deg rows)");
  return out;
}

std::vector<std::string> shot_placements(const Capture& capture) {
  const auto& cols = capture.shot_extra_columns;
  const auto it = std::find(cols.begin(), cols.end(), "placement");
  if (it == cols.end())
    throw InputError(capture.shots_file,
                     "no 'placement' column: a joint calibration needs the board placement of every shot");
  const auto j = static_cast<std::size_t>(it - cols.begin());
  std::vector<std::string> out;
  out.reserve(capture.shots.size());
  for (const auto& shot : capture.shots) {
    const std::string value = j < shot.extra.size() ? shot.extra[j] : std::string();
    if (value.empty())
      throw InputError(capture.shots_file, shot.source_line,
                       fmt::format("shot {} ('{}'): column 'placement' is empty, expected the name of a placement",
                                   shot.index, shot.image));
    out.push_back(value);
  }
  return out;
}

void check_board_reference(const BoardReference& reference, const std::vector<std::string>& shot_placements) {
  const std::set<std::string> shot_set(shot_placements.begin(), shot_placements.end());
  for (const auto& l : reference.lines)
    if (!shot_set.count(l.placement)) {
      std::string have;
      for (const auto& p : shot_set) have += (have.empty() ? "" : ", ") + p;
      throw InputError(reference.file, l.line,
                       fmt::format("placement '{}' has no shot (shots.csv names: {})", l.placement,
                                   have.empty() ? "none" : have));
    }
}

}  // namespace antpose::calibration
