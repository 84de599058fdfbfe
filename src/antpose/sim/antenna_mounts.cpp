#include "antpose/sim/antenna_mounts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace antpose::sim {

namespace {

std::array<Vec3, 8> corners(const OrientedBox& b) {
  std::array<Vec3, 8> out;
  for (int i = 0; i < 8; ++i)
    out[static_cast<std::size_t>(i)] = b.centre + b.axes * Vec3((i & 1 ? 1 : -1) * b.half.x(),
                                                                (i & 2 ? 1 : -1) * b.half.y(),
                                                                (i & 4 ? 1 : -1) * b.half.z());
  return out;
}

double cross2(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Horizontal distance from the vertical axis through `axis_xy` to the box (0 inside its
// outline): the distance to the convex hull (Andrew's monotone chain) of its projected corners.
double distance_to_vertical_axis(const OrientedBox& box, const Vec2& axis_xy) {
  std::vector<Vec2> pts;
  for (const Vec3& c : corners(box)) pts.emplace_back(c.x(), c.y());
  std::sort(pts.begin(), pts.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  std::vector<Vec2> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross2(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);  // counter-clockwise, the first point not repeated
  bool inside = true;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Vec2 &a = hull[i], &b = hull[(i + 1) % hull.size()];
    inside = inside && cross2(a, b, axis_xy) >= 0;
    const Vec2 ab = b - a;
    const double t = std::clamp((axis_xy - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
    best = std::min(best, (a + t * ab - axis_xy).norm());
  }
  return inside ? 0.0 : best;
}

}  // namespace

bool boxes_intersect(const OrientedBox& a, const OrientedBox& b, double clearance_m) {
  const auto placed = [](const OrientedBox& box) {
    return antpose::OrientedBox{isometry(box.axes, box.centre), 2 * box.half};
  };
  return boxes_overlap(placed(a), placed(b), clearance_m);
}

OrientedBox panel_box(const SimAntenna& a) {
  const model::PanelSpec& s = a.spec;
  const double e = a.finish.end_cap_height_m > 0.0 ? a.finish.end_cap_thickness_m : 0.0;
  const double back = -s.depth_m / 2 - (s.bracket ? s.bracket_depth_m : e), front = s.depth_m / 2 + e;
  OrientedBox box;
  box.axes = a.R_world_antenna;
  box.centre = a.p_world_antenna + a.R_world_antenna * Vec3(0.0, 0.5 * (back + front), 0.0);
  box.half = Vec3(s.width_m / 2 + e, 0.5 * (front - back), s.height_m / 2);
  return box;
}

OrientedBox strut_box(const Strut& s) {
  const Vec3 along = s.b - s.a;
  const Vec3 x = along.normalized();
  const Vec3 y = (std::abs(x.z()) < 0.9 ? x.cross(Vec3::UnitZ()) : x.cross(Vec3::UnitX())).normalized();
  OrientedBox box;
  box.axes << x, y, x.cross(y);
  box.centre = 0.5 * (s.a + s.b);
  box.half = Vec3(0.5 * along.norm(), s.radius_m, s.radius_m);
  return box;
}

OrientedBox arm_box(const Arm& arm) {
  return {arm.centre, arm.R_world_arm, Vec3(arm.length_m / 2, 0.025, 0.025)};
}

void mount_sectors(AntennaLayout& L, const std::vector<double>& arm_m, const std::vector<double>& z_m) {
  for (std::size_t k = 0; k < L.antennas.size(); ++k) {
    SimAntenna& a = L.antennas[k];
    a.mount_xy = Vec2::Zero();
    a.mount_radius_m = L.mast_radius_m;
    a.arm_m = arm_m.at(k);
    a.p_world_antenna = centre_on_mount(a, a.mount_xy, a.mount_radius_m, a.arm_m, z_m.at(k));
  }
  L.arrangement = Arrangement::kSectors;
  L.frame.clear();
}

bool mount_side_by_side(AntennaLayout& L, const FrameSpec& f, const std::vector<double>& arm_m) {
  const Vec3 out = heading(f.facing), right = out.cross(Vec3::UnitZ());
  const double bar_distance = L.mast_radius_m + f.standoff_m + f.bar_radius_m;
  const double pipe_distance = bar_distance + f.bar_radius_m + f.pipe_radius_m;
  L.arrangement = Arrangement::kSideBySide;
  L.frame.clear();
  double shared_lo = -std::numeric_limits<double>::infinity(), shared_hi = -shared_lo;
  std::vector<Strut> pipes;
  for (std::size_t k = 0; k < L.antennas.size(); ++k) {
    SimAntenna& a = L.antennas[k];
    const Vec3 pipe = pipe_distance * out + f.offsets_m.at(k) * right;
    a.mount_xy = Vec2(pipe.x(), pipe.y());
    a.mount_radius_m = f.pipe_radius_m;
    a.arm_m = arm_m.at(k);
    a.p_world_antenna = centre_on_mount(a, a.mount_xy, a.mount_radius_m, a.arm_m, f.z_m);
    const auto arms = antenna_arms(a);
    const double lo = std::min(arms[0].axis_point.z(), arms[1].axis_point.z()) - 0.1,
                 hi = std::max(arms[0].axis_point.z(), arms[1].axis_point.z()) + 0.1;
    shared_lo = std::max(shared_lo, lo), shared_hi = std::min(shared_hi, hi);
    pipes.push_back({fmt::format("frame-pipe-{}", k + 1), pipe + Vec3(0.0, 0.0, lo), pipe + Vec3(0.0, 0.0, hi),
                     f.pipe_radius_m});
  }
  if (shared_hi - shared_lo < 0.1) return false;
  const auto [o_min, o_max] = std::minmax_element(f.offsets_m.begin(), f.offsets_m.end());
  for (const auto& [name, fraction] : {std::pair{"low", 0.2}, std::pair{"high", 0.8}}) {
    const Vec3 z(0.0, 0.0, shared_lo + fraction * (shared_hi - shared_lo));
    L.frame.push_back({fmt::format("frame-bar-{}", name), bar_distance * out + (*o_min - 0.15) * right + z,
                       bar_distance * out + (*o_max + 0.15) * right + z, f.bar_radius_m});
    L.frame.push_back({fmt::format("frame-standoff-{}", name), z, bar_distance * out + z, f.bar_radius_m});
  }
  L.frame.insert(L.frame.end(), pipes.begin(), pipes.end());
  return true;
}

bool layout_collides(const AntennaLayout& L, double clearance_m, double min_z) {
  std::vector<OrientedBox> panels;
  for (const SimAntenna& a : L.antennas) panels.push_back(panel_box(a));
  for (std::size_t k = 0; k < panels.size(); ++k) {
    for (const Vec3& c : corners(panels[k]))
      if (c.z() < min_z) return true;
    if (distance_to_vertical_axis(panels[k], Vec2::Zero()) < L.mast_radius_m + clearance_m) return true;
    for (std::size_t j = k + 1; j < panels.size(); ++j)
      if (boxes_intersect(panels[k], panels[j], clearance_m)) return true;
    for (const Strut& s : L.frame)
      if (boxes_intersect(panels[k], strut_box(s), clearance_m)) return true;
    for (std::size_t j = 0; j < L.antennas.size(); ++j)
      if (j != k)
        for (const Arm& arm : antenna_arms(L.antennas[j]))
          if (boxes_intersect(panels[k], arm_box(arm), clearance_m)) return true;
  }
  return false;
}

}  // namespace antpose::sim
