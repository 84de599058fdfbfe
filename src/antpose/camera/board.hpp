// Calibration boards (board.yaml of the capture-format note) and their points in the board frame.
//
// Board frame: x along the columns, y along the rows, z = x × y (into the board for a board
// seen from the front, as OpenCV defines it), metres. Origin and point order per type, as
// OpenCV's detectors return them:
//   chessboard          cols × rows inner corners; origin at the first inner corner,
//                       point (c, r) = (c s, r s, 0), index r·cols + c;
//   circles             cols × rows circle centres, (c s, r s, 0);
//   asymmetric-circles  cols per row, rows rows, ((2c + r mod 2) s, r s, 0) (OpenCV's layout,
//                       s = the spacing of the circle grid's diagonal neighbours' columns);
//   charuco             cols × rows squares; (cols−1)(rows−1) inner corners with id
//                       r·(cols−1) + c at ((c + 1) s, (r + 1) s, 0), origin at the board's outer
//                       corner (cv::aruco::CharucoBoard::chessboardCorners).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "antpose/geometry/rotation.hpp"

namespace antpose::camera {

enum class BoardType { kChessboard, kCircles, kAsymmetricCircles, kCharuco };

struct BoardSpec {
  BoardType type = BoardType::kChessboard;
  int cols = 0, rows = 0;
  double square_m = 0.0;       // square side or circle spacing
  double marker_m = 0.0;       // charuco only
  std::string dictionary;      // charuco only, OpenCV name, e.g. DICT_6X6_250

  /// Points in the board frame, in detector order (see file comment).
  std::vector<Vec3> object_points() const;
  /// Number of points a complete detection returns.
  int point_count() const;
  /// Extent of the printed pattern in the board frame (min and max corner of the area covered
  /// by squares / circles, z = 0), e.g. for rendering and for the "partly out of view" check.
  std::pair<Vec3, Vec3> extent() const;
};

std::string to_string(BoardType type);

/// Reads board.yaml. InputError naming the file and line for an unknown type, a missing or
/// non-positive size, a marker not smaller than the square, or an unknown ArUco dictionary.
BoardSpec read_board(const std::filesystem::path& file);
BoardSpec parse_board(const std::string& yaml_text, const std::filesystem::path& file);
/// YAML text of a board (the inverse of parse_board).
std::string format_board(const BoardSpec& board);

/// OpenCV's predefined dictionary id (cv::aruco::PREDEFINED_DICTIONARY_NAME) for a name such as
/// "DICT_6X6_250"; −1 when unknown.
int aruco_dictionary_id(const std::string& name);

}  // namespace antpose::camera
