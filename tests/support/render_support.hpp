// Scenes rendered by the simulator for tests: hand-held camera poses and the board's pose in them.
#pragma once

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::test {

inline Iso3 iso(const Mat3& R, const Vec3& t) {
  Iso3 T = Iso3::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

/// A camera at `from` looking along `forward` (world) with its x axis level, as an upright photo,
/// then rolled by `roll_rad` about the optical axis, as hand-held.
inline sim::CameraPose level_camera(const Vec3& from, const Vec3& forward, double roll_rad = 0.0) {
  sim::CameraPose pose;
  const Vec3 z = forward.normalized(), x = z.cross(Vec3::UnitZ()).normalized(), y = z.cross(x);
  pose.R_world_camera.col(0) = x, pose.R_world_camera.col(1) = y, pose.R_world_camera.col(2) = z;
  pose.R_world_camera = pose.R_world_camera * rot_z(roll_rad);
  pose.p_world_camera = from;
  return pose;
}

/// T_camera_board of a camera at `pose` for a board at T_world_board.
inline Iso3 camera_from_board(const sim::CameraPose& pose, const Iso3& T_world_board) {
  return iso(pose.R_world_camera, pose.p_world_camera).inverse() * T_world_board;
}

}  // namespace antpose::test
