#include "antpose/measure/long_axis.hpp"

#include <cmath>

namespace antpose::measure {

KeptAxis keep_axis(const Vec3& axis_outline, const Vec3& axis_points, const Vec3& line_of_sight, double gate_rad) {
  KeptAxis k;
  k.axis = axis_outline;
  k.disagreement_rad = angle_between(axis_outline, axis_points);
  if (k.disagreement_rad <= gate_rad) return k;
  k.from_points = true;
  // u: where the outline's axis goes as it tilts along the line of sight.
  const Vec3 u = (line_of_sight - line_of_sight.dot(axis_outline) * axis_outline).normalized();
  k.along_rad = std::atan2(axis_points.dot(u), axis_points.dot(axis_outline));
  k.axis = std::cos(k.along_rad) * axis_outline + std::sin(k.along_rad) * u;
  k.about = axis_outline.cross(u);
  k.sideways = u;
  return k;
}

}  // namespace antpose::measure
