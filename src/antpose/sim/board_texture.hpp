// Textures of the simulated scene: printed calibration boards (all four board.hpp types) and
// procedural surfaces (ground, walls).
//
// A board texture is drawn in the board frame of camera/board.hpp (x along the columns, y along
// the rows, z = x × y into the board, metres) so that a rendered photo's detections correspond
// exactly to BoardSpec::object_points():
//   chessboard          (cols + 1) × (rows + 1) squares around the cols × rows inner corners
//                       (point (c, r) at (c s, r s)); the outer square at (−s, −s) is black;
//   circles             black discs of diameter s/2 at (c s, r s);
//   asymmetric-circles  black discs of diameter s/2 at ((2c + r mod 2) s, r s);
//   charuco             cv::aruco::CharucoBoard::draw, placed so that the corner with id
//                       r (cols − 1) + c lies at ((c + 1) s, (r + 1) s) — the orientation of the
//                       drawing is found by detecting the drawn board (robust to OpenCV's
//                       y-up/y-down board conventions across versions; see face_normal_z).
// Every board has a white margin around BoardSpec::extent() (detectors need a quiet zone).
// Reflectances: ink 0.05, paper 0.85.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

struct BoardTextureOptions {
  int texels_per_square = 128;  // texture resolution: texels per square side / circle spacing
  double margin_squares = 1.0;  // white margin beyond extent(), in squares
};

/// A board's texture and the rectangle it covers in the board frame (extent ± margin), m.
struct BoardTexture {
  std::shared_ptr<const Texture> texture;
  Eigen::Vector2d min_xy = Eigen::Vector2d::Zero(), max_xy = Eigen::Vector2d::Zero();
  /// The printed face looks along face_normal_z · z_board: −1 when z = x × y points into the
  /// board seen from the front (board.hpp; chessboards and circle grids), +1 for a ChArUco
  /// drawing whose corner ids run up the page (OpenCV ≤ 4.6 contrib), where z = x × y points out
  /// of the printed face.
  double face_normal_z = -1.0;
};

/// Draws a board. std::invalid_argument for a board with fewer than 2 points per side, a
/// non-positive size, or an unknown ArUco dictionary; std::runtime_error if the drawn ChArUco
/// board cannot be re-detected (an OpenCV drawing convention this code does not know).
BoardTexture board_texture(const camera::BoardSpec& board, const BoardTextureOptions& options = {});

/// The patch of a board whose frame is at R_world_board, p_world_board (the board frame's origin,
/// world, m): patch frame = board frame.
TexturedPatch board_patch(const BoardTexture& texture, const Mat3& R_world_board, const Vec3& p_world_board,
                          std::string name = "board");

/// A seamless (tileable) procedural texture: band-limited noise in four octaves (Gaussian-
/// filtered white noise, wavelengths from 1/20 of the tile down to a few texels), `texels` ×
/// `texels` (a power of two ≥ 128), covering `tile_m` × `tile_m` and repeating, reflectance
/// `mean` ± `contrast` (1σ), clamped to [0.02, 0.98]. Deterministic for a seed.
std::shared_ptr<const Texture> procedural_texture(std::uint64_t seed, double tile_m, int texels, double mean, double contrast);

/// A room around the origin: the ground z = 0 (grey asphalt-like) and four walls at ±half_size_m
/// (lighter plaster-like), height_m high, each with its own procedural texture.
std::vector<TexturedPatch> room_patches(std::uint64_t seed, double half_size_m = 5.0, double height_m = 3.0);

}  // namespace antpose::sim
