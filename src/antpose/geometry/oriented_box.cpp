#include "antpose/geometry/oriented_box.hpp"

#include <algorithm>
#include <cmath>

namespace antpose {

bool boxes_overlap(const OrientedBox& a, const OrientedBox& b, double gap_m) {
  const Vec3 ea = a.size_m / 2, eb = b.size_m / 2;
  // b in a's frame: its axes (columns of R) and its centre (t).
  const Mat3 R = a.T_frame_box.linear().transpose() * b.T_frame_box.linear();
  const Vec3 t = a.T_frame_box.linear().transpose() * (b.T_frame_box.translation() - a.T_frame_box.translation());
  // A small term keeps the cross axes of near-parallel edges (a zero vector) from separating.
  const Mat3 absR = R.cwiseAbs().array() + 1e-9;
  for (int i = 0; i < 3; ++i)
    if (std::abs(t(i)) > ea(i) + eb.dot(absR.row(i)) + gap_m) return false;
  for (int j = 0; j < 3; ++j)
    if (std::abs(t.dot(R.col(j))) > ea.dot(absR.col(j)) + eb(j) + gap_m) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // The axis e_i × R.col(j), unnormalised: its length scales the gap.
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = ea(i1) * absR(i2, j) + ea(i2) * absR(i1, j);
      const double rb = eb(j1) * absR(i, j2) + eb(j2) * absR(i, j1);
      const double length = std::hypot(R(i1, j), R(i2, j));
      if (std::abs(t(i2) * R(i1, j) - t(i1) * R(i2, j)) > ra + rb + gap_m * length) return false;
    }
  return true;
}

double box_segment_distance(const OrientedBox& box, const Vec3& a, const Vec3& b) {
  const Iso3 T_box_frame = box.T_frame_box.inverse();
  const Vec3 half = box.size_m / 2;
  const auto distance = [&](double t) {
    const Vec3 q = T_box_frame * (a + t * (b - a));
    return (q.cwiseAbs() - half).cwiseMax(0.0).norm();
  };
  const double ratio = (std::sqrt(5.0) - 1) / 2;
  double lo = 0.0, hi = 1.0;
  double m1 = hi - ratio * (hi - lo), m2 = lo + ratio * (hi - lo);
  double d1 = distance(m1), d2 = distance(m2);
  for (int i = 0; i < 60; ++i) {  // each step keeps one probe and evaluates one new
    if (d1 <= d2) {
      hi = m2, m2 = m1, d2 = d1;
      m1 = hi - ratio * (hi - lo), d1 = distance(m1);
    } else {
      lo = m1, m1 = m2, d1 = d2;
      m2 = lo + ratio * (hi - lo), d2 = distance(m2);
    }
  }
  return distance((lo + hi) / 2);
}

std::optional<OrientedBox> shrunk(const OrientedBox& box, double by_m) {
  OrientedBox out = box;
  out.size_m.array() -= 2 * by_m;
  if ((out.size_m.array() < 0).any()) return std::nullopt;
  return out;
}

}  // namespace antpose
