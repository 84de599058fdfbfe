// How the panels of a wide antenna site hang on the mast, and the check that a drawn layout is
// physically possible.
//
//   sectors       each panel on its own pair of horizontal arms clamped to the mast (the usual
//                 three-sector site);
//   side-by-side  the panels on vertical pipes clamped to two horizontal bars, the bars held out
//                 from the mast by stand-offs: neighbours a few decimetres apart, looking the same
//                 way, which overlap in most photos.
//
// Intersections are found with the separating-axis test on oriented boxes (Gottschalk, Lin &
// Manocha, "OBBTree", SIGGRAPH 1996): a panel's box includes its brackets and end caps; the mast
// is a vertical cylinder, tested against a box's horizontal outline.
#pragma once

#include <vector>

#include "antpose/geometry/oriented_box.hpp"
#include "antpose/sim/antenna_scene.hpp"

namespace antpose::sim {

/// A box: centre, axes (columns, orthonormal) and half sizes along them, world frame.
struct OrientedBox {
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
  Vec3 half = Vec3::Zero();
};

/// Whether two boxes overlap or come closer than `clearance_m` along every one of the 15 candidate
/// separating axes (antpose::boxes_overlap).
bool boxes_intersect(const OrientedBox& a, const OrientedBox& b, double clearance_m);

/// The box of a rendered panel: its box, the brackets behind it and the end caps' rim.
OrientedBox panel_box(const SimAntenna& antenna);
/// The box around a strut or an arm.
OrientedBox strut_box(const Strut& strut);
OrientedBox arm_box(const Arm& arm);

/// Each antenna (spec and attitude set) on its own arms to the mast: the nearer bracket's arm
/// arm_m[k] beyond the mast's surface, the centre at height z_m[k].
void mount_sectors(AntennaLayout& layout, const std::vector<double>& arm_m, const std::vector<double>& z_m);

/// The frame of a side-by-side arrangement.
struct FrameSpec {
  double facing = 0.0;              // azimuth (rad) of the direction the frame faces, out from the mast
  std::vector<double> offsets_m;    // each pipe along the bars, to the right looking along `facing`
  double standoff_m = 0.3;          // from the mast's surface to the bars
  double pipe_radius_m = 0.03, bar_radius_m = 0.03;
  double z_m = 0.0;                 // the panels' centre height
};

/// The antennas (spec and attitude set) side by side: antenna k on pipe k, the nearer bracket's
/// arm arm_m[k] beyond the pipe's surface; the bars at 1/5 and 4/5 of the height range all pipes
/// share, each pipe running 10 cm past its brackets. Fills layout.frame; false when the pipes
/// share less than 10 cm of height (no room for two bars).
bool mount_side_by_side(AntennaLayout& layout, const FrameSpec& frame, const std::vector<double>& arm_m);

/// Whether a layout is impossible: two panels, or a panel and the mast, a strut or another
/// antenna's arm, closer than `clearance_m`, or a panel's lowest point below `min_z` (the roof
/// or the ground plus a margin).
bool layout_collides(const AntennaLayout& layout, double clearance_m, double min_z);

}  // namespace antpose::sim
