// Triangle meshes of antenna models: Wavefront OBJ and PLY readers, an ASCII PLY writer, and the
// few measures the model code needs (area, enclosed volume, closedness).
//
// A mesh's vertices are in metres in the frame its owner names (`mesh_antenna`, or the file's own
// "mesh" frame). Triangles index `vertices`; polygons of the files are fan-triangulated
// (v0 v1 v2, v0 v2 v3, ...), which keeps their winding. A triangle's normal follows its winding
// (counter-clockwise seen from the side the normal points to), so the normals of a file are only
// as consistent as its winding.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose::model {

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // may be empty (a point-only PLY)
};

/// The length unit of a model file. Files carry no unit, so it is always stated, never guessed.
enum class Units { kMetres, kMillimetres };

/// Metres per file unit: 1 or 1e-3.
double metres_per_unit(Units units);
/// "m" or "mm".
std::string to_string(Units units);

/// Reads an OBJ (.obj) or PLY (.ply) file, chosen by the extension (case-insensitive; a further
/// ".gz" is allowed, the data is then decompressed), and scales it to metres. Then checks that the
/// result is antenna-sized: a largest bounding-box side above 10 m (e.g. a model in millimetres
/// read as metres: pass `--model-units mm`) or below 0.05 m is an InputError saying what was
/// found. InputError naming the file (and the line for text data) for every malformed input.
Mesh read_mesh(const std::filesystem::path& file, Units units = Units::kMetres);

/// The raw parsers behind read_mesh: coordinates as written, no scaling and no size check.
/// `file` is only used in messages. OBJ: `v` and `f` statements (v, v/vt, v//vn, v/vt/vn forms,
/// negative indices relative to the vertices read so far); every other statement is ignored.
Mesh parse_obj(std::string_view text, const std::filesystem::path& file);
/// PLY: ascii, binary_little_endian or binary_big_endian; `vertex` x, y, z of any numeric type,
/// every other property and element skipped; `face` list `vertex_indices` or `vertex_index`.
Mesh parse_ply(std::string_view data, const std::filesystem::path& file);

/// Largest side of the axis-aligned bounding box, metres; InputError naming `file` when it lies
/// outside [0.05 m, 10 m] (the message names the extent, the units it was read in and the fix).
void check_model_extent(const Mesh& mesh, const std::filesystem::path& file, Units units);

/// ASCII PLY text of a mesh (x y z as double, faces as uchar/int lists) or of a cloud (x y z, and
/// nx ny nz when it has normals). Numbers are written in shortest round-trip form.
std::string format_ply(const Mesh& mesh);
std::string format_ply(const PointCloud& cloud);
/// Writes format_ply atomically (io::write_text_atomic; a ".gz" name is compressed).
void write_ply(const Mesh& mesh, const std::filesystem::path& file);
void write_ply(const PointCloud& cloud, const std::filesystem::path& file);

/// The mesh with every vertex mapped by T (p' = T p); triangles unchanged.
Mesh transformed(const Mesh& mesh, const Iso3& T);
/// Appends `part` to `mesh` (its triangles re-indexed): one mesh of several closed parts.
void append_mesh(Mesh& mesh, const Mesh& part);
/// Axis-aligned bounding box (min, max) of the vertices; both zero for an empty mesh.
std::pair<Vec3, Vec3> bounding_box(const Mesh& mesh);
/// Area of triangle i (m²) and its unit normal by winding (zero for a degenerate triangle).
double triangle_area(const Mesh& mesh, std::size_t i);
Vec3 triangle_normal(const Mesh& mesh, std::size_t i);
/// Total area, m².
double surface_area(const Mesh& mesh);
/// Signed volume enclosed by a closed mesh (divergence theorem, Σ a·(b × c)/6), m³: positive when
/// the winding makes the normals point outwards. Meaningless for an open mesh.
double enclosed_volume(const Mesh& mesh);
/// True when every edge is shared by exactly two triangles that run along it in opposite
/// directions: a closed, consistently wound surface.
bool is_closed(const Mesh& mesh);

}  // namespace antpose::model
