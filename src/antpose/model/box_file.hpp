// The box file (thesis §6.5, fig. 6.4): the eight corners of a box hand-fitted to a panel, in the
// mesh's own coordinates, which fixes the antenna frame on a scanned mesh.
//
//   # comment               one corner per line, any order, each label exactly once:
//   A x y z                 ABCD is the top face, ABFE lies against the back plate,
//   ...                     E, F, G, H are below A, B, C, D, and D is in front of A (towards the
//   H x y z                 radome). So AB runs along x_a, AD along y_a, EA along z_a.
//
// The rotation is R_antenna_mesh = [AB AD EA]ᵀ (each the mean of the four parallel edges, rows
// normalised, then projected onto SO(3)); the box centre becomes the antenna origin. Corners are
// hand-picked, so the box is checked to within a few degrees and percent (see box_file.cpp), and a
// mirrored labelling is refused rather than silently turned into a rotation.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/model/mesh.hpp"

namespace antpose::model {

struct AntennaBox {
  Iso3 T_antenna_mesh = Iso3::Identity();  // mesh coordinates (metres) → antenna frame
  Vec3 size_m = Vec3::Zero();              // width along x_a, depth along y_a, height along z_a
};

/// Reads a box file whose coordinates are in `units` (those of the mesh it belongs to). InputError
/// naming the file and line for a bad line, an unknown, missing or repeated label, and for corners
/// that are not a box or form a mirrored one (the message says which labels seem swapped).
AntennaBox read_box_file(const std::filesystem::path& file, Units units = Units::kMetres);
AntennaBox parse_box_file(const std::string& text, const std::filesystem::path& file, Units units = Units::kMetres);

/// The box through eight corners given in A..H order (metres); `lines` are their 1-based line
/// numbers, only used in messages (zeros when there is no file). Same checks as read_box_file.
AntennaBox fit_box(const std::array<Vec3, 8>& corners_mesh, const std::filesystem::path& file,
                   const std::array<std::size_t, 8>& lines = {});

/// Corners A..H of a box of `size_m` centred in the antenna frame, mapped into the mesh frame by
/// T_mesh_antenna: A = (−w/2, −d/2, +h/2), B = (+w/2, −d/2, +h/2), D = (−w/2, +d/2, +h/2), ...
std::array<Vec3, 8> box_corners(const Vec3& size_m, const Iso3& T_mesh_antenna = Iso3::Identity());

/// Box file text for corners in A..H order (shortest round-trip numbers).
std::string format_box_file(const std::array<Vec3, 8>& corners_mesh);

}  // namespace antpose::model
