// A box placed in space (an antenna's, a neighbour's) and whether two of them share volume.
#pragma once

#include "antpose/geometry/point_cloud.hpp"

namespace antpose {

/// A box centred at T_frame_box's origin, its edges along that frame's axes.
struct OrientedBox {
  Iso3 T_frame_box = Iso3::Identity();
  Vec3 size_m = Vec3::Zero();  // edge lengths along the box's x, y, z
};

/// Whether the two boxes (in one frame), each shrunk by `clearance_m` on every face, intersect:
/// whether one passes through the other deeper than the clearance. The separating-axis test over
/// the boxes' 3 + 3 face normals and 9 edge cross products (Gottschalk, Lin & Manocha, "OBBTree",
/// SIGGRAPH 1996).
bool boxes_overlap(const OrientedBox& a, const OrientedBox& b, double clearance_m = 0.0);

}  // namespace antpose
