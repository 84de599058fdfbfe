// Antenna models in the canonical antenna frame (docs/antenna-models.md, notes/antenna-model.md):
// origin at the centre of the panel's box, y_a the boresight (outward normal of the radome), z_a
// up the long axis, x_a = y_a × z_a; metres.
//
// A model comes from a mesh file placed by its box file, from a mesh declared to be in the antenna
// frame already, or from a parametric panel. A mesh alone does not fix the frame: its shape gives
// the long axis (up to sign) but never which face is the radome, and guessing would turn into a
// confident 180° azimuth error. So a mesh without a box file is refused unless declared canonical.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/model/box_file.hpp"
#include "antpose/model/mesh.hpp"

namespace antpose::model {

struct PanelSpec;

struct AntennaModel {
  std::string name;
  Mesh mesh_antenna;                       // vertices in the antenna frame, metres
  Vec3 size_m = Vec3::Zero();              // the box: width along x_a, depth along y_a, height along z_a
  Iso3 T_antenna_mesh = Iso3::Identity();  // file coordinates (in metres) → antenna frame; identity for built-ins
  /// A parametric panel's spec (built-ins and datasheet boxes): its edge rounding and brackets are
  /// a guess, which the registration may refit; none for a mesh from a file.
  std::shared_ptr<const PanelSpec> panel;
};

/// Loads a model from a mesh file (read_mesh: OBJ or PLY in `units`, size-checked) that has
/// triangles. With `box_file` (same units and coordinates as the mesh) the mesh is moved into
/// the antenna frame by its T_antenna_mesh and size_m is the box's. Without one, `assume_canonical`
/// takes the mesh as already in the antenna frame and only moves its bounding-box centre to the
/// origin (size_m = bounding box); otherwise InputError asking for a box file, with the mesh's
/// principal-axis extents as a hint. InputError too when the box does not fit the mesh (e.g. the
/// two in different units). The name is the mesh file's stem.
AntennaModel load_antenna_model(const std::filesystem::path& mesh_file,
                                const std::optional<std::filesystem::path>& box_file, Units units = Units::kMetres,
                                bool assume_canonical = false);

/// A rough box from the principal axes of the mesh's surface (area-weighted; the vertices when it
/// has no triangles): z = the axis of largest spread, y = the smallest (a panel's depth),
/// x = y × z, centre and size from the vertices' extent along these axes. Signs are whatever the
/// eigen solver returns, so the box is known only up to a half-turn about any of its axes: never
/// an antenna frame, only a hint (e.g. in messages). std::invalid_argument for an empty mesh.
AntennaBox principal_axes_box(const Mesh& mesh);

/// A parametric panel: a box of width × depth × height with rounded vertical edges and, optionally,
/// two bracket blocks on the back plate.
struct PanelSpec {
  double width_m = 0.30, depth_m = 0.16, height_m = 1.31;
  double edge_radius_m = 0.02;  // rounded vertical edges; 0 for sharp ones
  bool bracket = true;          // two blocks on the back plate
  double bracket_width_m = 0.10, bracket_depth_m = 0.06, bracket_height_m = 0.12;  // along x_a, −y_a, z_a
  /// The brackets' centres lie this fraction of the height from each end (1/4: at 1/4 and 3/4 of
  /// the height).
  double bracket_end_fraction = 0.25;
  int arc_segments = 6;  // flat facets per rounded edge
  /// End caps: mouldings at both ends, end_cap_height_m long and flush with them, standing out of
  /// the radome's section all round by end_cap_rim_m (their corners rounded by the edge radius plus
  /// the rim). Height 0: none. A datasheet box leaves them out: it gives the radome's section.
  double end_cap_height_m = 0.0, end_cap_rim_m = 0.0;
};

/// The closed, outward-wound triangle mesh of a panel in the antenna frame: box centre at the
/// origin, radome at +y, top at +z; the rounded edges are inscribed polygons (vertices on the
/// arcs). The brackets protrude from the back plate (−y) outside the box, so size_m is the box
/// (width, depth, height) without them, like a box fitted by hand to a scan. Two equal brackets
/// at the same distance from each end keep the panel symmetric under a half-turn about y_a
/// (up/down is told by gravity, not by shape) and break the front/back symmetry.
/// std::invalid_argument for a non-positive size, a radius not below half the smaller of width
/// and depth, fewer than 1 arc segment, or a bracket that is not narrower than the flat part of
/// the back plate, whose end fraction is not in (0, 1/2), or that does not fit between its end
/// and the other bracket (for brackets at 1/4 and 3/4: not shorter than height/2).
AntennaModel parametric_panel(const PanelSpec& spec);

/// The end caps of PanelSpec (two closed meshes, bottom then top; none for height 0), as
/// parametric_panel adds them to the panel's mesh where they stand out of its section.
std::vector<Mesh> end_cap_meshes(const PanelSpec& spec);

/// The box the model's own outline stays within (antenna frame, centred): its box, grown across
/// by the end caps' rim. Outside it lie attachments (brackets), whose outline misleads
/// (registration/silhouette.hpp, SilhouetteOptions::outline_box_m).
Vec3 outline_box(const AntennaModel& model);

/// Built-in panels by name: "thesis-1310x159x80" (the thesis's scanned panel) and any datasheet
/// box "panel-<h>x<w>x<d>", height × width × depth in whole millimetres (h 300..4000, w 100..800,
/// d 50..400, d ≤ w), such as "panel-1310x300x160" and "panel-2000x300x150". Other PanelSpec fields
/// at their defaults, except that the brackets of a narrow panel are narrowed to leave 2 cm of the
/// back plate's flat part beside them. InputError naming the expected form and the ranges for
/// any other name.
AntennaModel builtin_panel(const std::string& name);
/// Whether builtin_panel accepts the name.
bool is_builtin_panel(const std::string& name);
/// The named built-ins (a few of the datasheet boxes builtin_panel accepts).
std::vector<std::string> builtin_panel_names();

}  // namespace antpose::model
