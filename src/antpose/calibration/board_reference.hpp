// board_reference.csv of a joint-calibration capture (../shared/notes/capture-format.md §1): the
// board's attitude in each placement measured with a level and a compass (thesis §5.4.3), one
// angle per line:
//   placement,axis,ref,angle_deg
//   hor_0_90,X,N,0        axis X, Y or Z of the board frame (x along the columns, y along the
//   hor_0_90,Z,G,0        rows, z = x × y into the board)
// ref G: angle between the axis and straight down, [0, 180]° (thesis gra());
// ref N: clockwise angle from magnetic north of the axis's horizontal projection, [0, 360)°
//        (thesis nor()).
// The shots of a placement carry its name in the `placement` column of shots.csv.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "antpose/io/capture.hpp"

namespace antpose::calibration {

enum class BoardAxis { kX = 0, kY = 1, kZ = 2 };
enum class AngleReference { kGravity, kNorth };  // G, N

char to_char(BoardAxis axis);
char to_char(AngleReference ref);

struct BoardReferenceLine {
  std::string placement;
  BoardAxis axis = BoardAxis::kZ;
  AngleReference ref = AngleReference::kGravity;
  double angle = 0.0;     // rad: G in [0, π], N in [0, 2π)
  std::size_t line = 0;   // 1-based line in `file` (0: built in memory)
};

struct BoardReference {
  std::filesystem::path file;
  std::vector<BoardReferenceLine> lines;

  /// Placement names in order of first appearance.
  std::vector<std::string> placements() const;
  /// The lines of one placement, in file order.
  std::vector<BoardReferenceLine> lines_of(const std::string& placement) const;
};

/// Reads board_reference.csv (plain or .gz). InputError naming the file and line for: a missing
/// column, an empty placement, an axis other than X|Y|Z, a ref other than G|N, an angle that is
/// not a number or outside [0, 180] (G) / [0, 360) (N), and a line that repeats the placement,
/// axis and ref of an earlier line (naming that line). A file without lines is an error.
BoardReference read_board_reference(const std::filesystem::path& file);

/// The `placement` value of every shot of `capture`, in shot order. InputError naming shots.csv
/// when the capture has no `placement` column or a shot's value is empty (with its line).
std::vector<std::string> shot_placements(const Capture& capture);

/// Checks the reference against the placements the shots name: InputError naming the reference
/// file and the line of the placement's first appearance when a placement has no shot. Shots of
/// placements without reference lines are allowed (they still serve the reference-free method).
void check_board_reference(const BoardReference& reference, const std::vector<std::string>& shot_placements);

}  // namespace antpose::calibration
