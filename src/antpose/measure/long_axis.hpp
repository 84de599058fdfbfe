// The panel's long axis from its two measurements: the outline's and the points'.
//
// Seen from below, a panel's outline barely changes as its axis tilts along the line of sight,
// and the mast's and the clamps' edges beside it may slide it there by degrees; across the line
// of sight the axis is the outline's direction in every photo, and sharp. The reconstructed
// points fix the axis in 3-D, but from 20–30 m their depths scatter and the region's clutter
// leans on them, across the line of sight as much as along it: on site 4710-1 the outline's
// axis was 3.64° off along the line of sight and 0.02° across it, the points' 1.35° and 1.33°.
// Where the two disagree by more than a gate, the axis kept is the outline's tilted along the
// line of sight onto the points' (the components of a 2-D rotation; the points' component across
// is dropped); within the gate the outline's stands (from the ground the points' axis was
// 1.1–2.0° off where the outline's was right within 0.2°: development sites 710-1, 712-2, 802).
#pragma once

#include "antpose/geometry/rotation.hpp"

namespace antpose::measure {

struct KeptAxis {
  Vec3 axis = Vec3::UnitZ();  // unit, board frame (or any frame the inputs share)
  bool from_points = false;   // beyond the gate: the tilt along the line of sight is the points'
  double disagreement_rad = 0;  // between the outline's axis and the points'
  double along_rad = 0;         // the turn from the outline's axis to the kept one
  /// Unit rotation axes (zero within the gate): turning the outline's axis about `about` by
  /// along_rad gives the kept one (a tilt along the line of sight); turning it about `sideways`
  /// tilts it across the line of sight.
  Vec3 about = Vec3::Zero(), sideways = Vec3::Zero();
};

/// `axis_outline`, `axis_points` unit and pointing the same way; `line_of_sight` from the cameras
/// to the panel (any length, not along the axis).
KeptAxis keep_axis(const Vec3& axis_outline, const Vec3& axis_points, const Vec3& line_of_sight, double gate_rad);

}  // namespace antpose::measure
