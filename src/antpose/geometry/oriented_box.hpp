// A box placed in space (an antenna's, a neighbour's, a simulated mount's) and whether two of
// them meet.
#pragma once

#include <optional>

#include "antpose/geometry/point_cloud.hpp"

namespace antpose {

/// A box centred at T_frame_box's origin, its edges along that frame's axes.
struct OrientedBox {
  Iso3 T_frame_box = Iso3::Identity();
  Vec3 size_m = Vec3::Zero();  // edge lengths along the box's x, y, z
};

/// Whether the two boxes (in one frame) meet, or come within `gap_m` of each other along every
/// candidate separating axis: the 3 + 3 face normals and the 9 edge cross products (Gottschalk,
/// Lin & Manocha, "OBBTree", SIGGRAPH 1996).
bool boxes_overlap(const OrientedBox& a, const OrientedBox& b, double gap_m = 0.0);

/// The shortest distance between the box (solid) and the segment from `a` to `b` (one frame); 0
/// where they meet. The distance from a convex set is convex along a line, so a golden-section
/// search over the segment finds its minimum.
double box_segment_distance(const OrientedBox& box, const Vec3& a, const Vec3& b);

/// The box shrunk by `by_m` on every face; nullopt where nothing is left of it.
std::optional<OrientedBox> shrunk(const OrientedBox& box, double by_m);

}  // namespace antpose
