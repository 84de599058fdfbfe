#include "antpose/sim/capture_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "antpose/sim/capture_simulator.hpp"
#include "antpose/sim/random.hpp"

namespace antpose::sim {

Mat3 rotation_between(const Vec3& a, const Vec3& b) {
  const Vec3 axis = a.cross(b);
  const double s = axis.norm(), c = a.dot(b);
  if (s < 1e-12)
    return c > 0 ? Mat3::Identity()
                 : exp_so3(std::numbers::pi *
                           (std::abs(a.x()) < 0.9 ? a.cross(Vec3::UnitX()) : a.cross(Vec3::UnitY())).normalized());
  return exp_so3(axis / s * std::atan2(s, c));
}

Mat3 look_rotation(const Vec3& forward, const Vec3& down, double roll) {
  const Vec3 z = forward.normalized();
  Vec3 y = down - down.dot(z) * z;
  if (y.norm() < 1e-9) y = (std::abs(z.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(z);
  y.normalize();
  const Vec3 x = y.cross(z);
  Mat3 R;
  R << x, y, z;
  return R * rot_z(roll);
}

Vec3 board_centre(const camera::BoardSpec& board) {
  const auto [lo, hi] = board.extent();
  return 0.5 * (lo + hi);
}

Mat3 board_rotation(const Vec3& n_out, double face_normal_z, const Vec3& x_hint) {
  const Vec3 z = (face_normal_z * n_out).normalized();
  const Vec3 x = (x_hint - x_hint.dot(z) * z).normalized();
  Mat3 R;
  R << x, z.cross(x), z;
  return R;
}

bool board_in_view(const camera::CameraIntrinsics& K, const CameraPose& pose, const camera::BoardSpec& board,
                   const Mat3& R_world_board, const Vec3& p_world_board, double margin_m, double border_px) {
  const auto [lo, hi] = board.extent();
  // Sample the outline densely: with distortion a straight edge bows between its corners.
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      if (i != 0 && i != 8 && j != 0 && j != 8) continue;
      const Vec3 p_board(lo.x() - margin_m + (hi.x() - lo.x() + 2 * margin_m) * i / 8.0,
                         lo.y() - margin_m + (hi.y() - lo.y() + 2 * margin_m) * j / 8.0, 0.0);
      const Vec3 p_camera =
          pose.R_world_camera.transpose() * (p_world_board + R_world_board * p_board - pose.p_world_camera);
      if (p_camera.z() < 0.05) return false;
      // Outside the field of view by a wide margin: the distortion polynomial is meaningless there.
      const double x = p_camera.x() / p_camera.z(), y = p_camera.y() / p_camera.z();
      if (std::abs(x) > 1.5 * K.width / K.fx || std::abs(y) > 1.5 * K.height / K.fy) return false;
      const auto uv = K.project(p_camera);
      if (!uv || uv->x() < border_px || uv->y() < border_px || uv->x() > K.width - 1 - border_px ||
          uv->y() > K.height - 1 - border_px)
        return false;
    }
  return true;
}

std::vector<Vec3> board_points(const camera::BoardSpec& board, const BoardPlacement& pl, double margin_m) {
  const auto [lo, hi] = board.extent();
  std::vector<Vec3> out;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      if (i != 0 && i != 8 && j != 0 && j != 8) continue;
      const Vec3 p(lo.x() - margin_m + (hi.x() - lo.x() + 2 * margin_m) * i / 8.0,
                   lo.y() - margin_m + (hi.y() - lo.y() + 2 * margin_m) * j / 8.0, 0.0);
      out.push_back(pl.p_world_board + pl.R_world_board * p);
    }
  return out;
}

Waypoint device_from_camera(const SimulatedDevice& d, const Mat3& R_world_camera, const Vec3& p_world_camera) {
  const Mat3 R_world_device = R_world_camera * d.R_device_camera.transpose();
  return {R_world_device, p_world_camera - R_world_device * d.p_device_camera};
}

CameraPose camera_pose(const SimulatedDevice& d, const Trajectory& tr, double t) {
  const Mat3 R_wd = tr.R_world_device(t);
  return {R_wd * d.R_device_camera, tr.position_world(t) + R_wd * d.p_device_camera};
}

std::vector<Vec3> antenna_points(const AntennaLayout& layout) {
  std::vector<Vec3> out;
  for (const auto& a : layout.antennas)
    for (const Vec3& v : rendered_panel_mesh(a).vertices) out.push_back(a.p_world_antenna + a.R_world_antenna * v);
  return out;
}

double fit_margin_px(const camera::CameraIntrinsics& K, const CameraPose& pose, const std::vector<Vec3>& points) {
  double margin = std::numeric_limits<double>::infinity();
  for (const Vec3& p : points) {
    const Vec3 pc = pose.R_world_camera.transpose() * (p - pose.p_world_camera);
    if (pc.z() < 0.05) return -1.0;
    if (std::abs(pc.x() / pc.z()) > 1.5 * K.width / K.fx || std::abs(pc.y() / pc.z()) > 1.5 * K.height / K.fy)
      return -1.0;
    const auto uv = K.project(pc);
    if (!uv) return -1.0;
    margin = std::min({margin, uv->x(), uv->y(), K.width - 1 - uv->x(), K.height - 1 - uv->y()});
  }
  return margin;
}

Mat3 aim_camera(const Vec3& c, const std::vector<Vec3>& points, bool portrait, double roll) {
  Vec3 f = Vec3::Zero();
  for (const Vec3& p : points) f += (p - c).normalized();
  Mat3 R = look_rotation(f, -Vec3::UnitZ(), roll + (portrait ? 0.5 * std::numbers::pi : 0.0));
  for (int it = 0; it < 4; ++it) {
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    for (const Vec3& p : points) {
      const Vec3 q = R.transpose() * (p - c);
      if (q.z() <= 1e-3) return R;
      x0 = std::min(x0, q.x() / q.z()), x1 = std::max(x1, q.x() / q.z());
      y0 = std::min(y0, q.y() / q.z()), y1 = std::max(y1, q.y() / q.z());
    }
    R = R * rotation_between(Vec3::UnitZ(), Vec3(0.5 * (x0 + x1), 0.5 * (y0 + y1), 1.0).normalized());
  }
  return R;
}

camera::CameraIntrinsics scaled_intrinsics(const camera::CameraIntrinsics& K, int factor) {
  camera::CameraIntrinsics s = K;
  s.width = K.width / factor, s.height = K.height / factor;
  s.fx = K.fx / factor, s.fy = K.fy / factor;
  // Pixel centres at integers: u_small = (u + 0.5) / factor − 0.5.
  s.cx = (K.cx + 0.5) / factor - 0.5, s.cy = (K.cy + 0.5) / factor - 0.5;
  return s;
}

std::vector<double> visible_fractions(const PhotoRenderer& low, const Scene& scene,
                                      const std::vector<std::size_t>& panel_mesh, const CameraPose& pose) {
  const Lighting lighting;
  cv::Mat ids;
  low.render(scene, pose, lighting, &ids);
  std::vector<double> out;
  for (const std::size_t m : panel_mesh) {
    Scene alone;
    alone.meshes.push_back(scene.meshes[m]);
    cv::Mat alone_ids;
    low.render(alone, pose, lighting, &alone_ids);
    const int id = static_cast<int>(scene.patches.size() + m);
    const double all = cv::countNonZero(alone_ids == 0);
    const double seen = cv::countNonZero(ids == id);
    out.push_back(all > 0 ? seen / all : 0.0);
  }
  return out;
}

std::vector<MeshObject> tripod_meshes(const camera::BoardSpec& board, const BoardPlacement& pl, double ground_z) {
  const auto [lo, hi] = board.extent();
  // The lowest point of the board's outline (one square of margin) is where the head holds it.
  Vec3 bottom = pl.p_world_board + pl.R_world_board * Vec3(0.5 * (lo.x() + hi.x()), lo.y() - board.square_m, 0.0);
  const Vec3 other = pl.p_world_board + pl.R_world_board * Vec3(0.5 * (lo.x() + hi.x()), hi.y() + board.square_m, 0.0);
  if (other.z() < bottom.z()) bottom = other;
  const Vec3 n = pl.R_world_board.col(2);
  const Vec3 head = bottom - Vec3(0.0, 0.0, 0.12) - 0.03 * Vec3(n.x(), n.y(), 0.0).normalized();
  std::vector<MeshObject> out;
  MeshObject post;
  post.name = "tripod-post";
  post.mesh = cylinder_mesh(head, bottom + Vec3(0.0, 0.0, 0.02), 0.015, 12);
  post.albedo = 0.15;
  out.push_back(post);
  for (int k = 0; k < 3; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 3.0 + 0.3;
    const Vec3 foot(head.x() + 0.55 * std::cos(a), head.y() + 0.55 * std::sin(a), ground_z);
    MeshObject leg;
    leg.name = fmt::format("tripod-leg-{}", k + 1);
    leg.mesh = cylinder_mesh(head, foot, 0.012, 10);
    leg.albedo = 0.15;
    out.push_back(leg);
  }
  return out;
}

BoardPlacement tripod_board(const camera::BoardSpec& board, double face_normal_z, const Vec3& centre,
                            const Vec3& facing) {
  BoardPlacement pl;
  pl.name = "tripod";
  const Vec3 n_out = (facing - centre).normalized();
  pl.R_world_board = board_rotation(n_out, face_normal_z, (-n_out).cross(Vec3::UnitZ()));
  pl.p_world_board = centre - pl.R_world_board * board_centre(board);
  return pl;
}

std::optional<ArcViews> fit_arc_views(const ArcWalk& walk, const camera::CameraIntrinsics& K,
                                      const std::vector<Vec3>& points, std::mt19937_64& rng) {
  const double border = 0.04 * K.width;
  const int N = walk.photos;
  for (double span = walk.span_max; span >= walk.span_min; span -= deg2rad(2.0)) {
    std::vector<Vec3> cs;
    bool fine = true;
    for (int k = 0; k < N && fine; ++k) {
      const double psi = walk.azimuth + span * (static_cast<double>(k) / (N - 1) - 0.5);
      const double Dk = walk.distance_m + uniform(rng, -0.3, 0.3),
                   hk = walk.height_m + uniform(rng, -0.05, 0.05);  // sequenced draws
      const Vec3 c = Dk * Vec3(std::sin(psi), std::cos(psi), 0.0) + hk * Vec3::UnitZ();
      const double to_board = (c - walk.board_centre).norm();
      fine = to_board >= 1.5 && to_board <= walk.board_max_m;
      cs.push_back(c);
    }
    if (!fine) continue;
    // Portrait or landscape, whichever leaves more room at the middle of the walk.
    const Vec3& cm = cs[static_cast<std::size_t>(N / 2)];
    ArcViews views;
    double best = -1.0;
    for (const bool p : {true, false}) {
      const double m = fit_margin_px(K, {aim_camera(cm, points, p, 0.0), cm}, points);
      if (m > best) best = m, views.portrait = p;
    }
    fine = best >= border;
    for (int k = 0; k < N && fine; ++k) {
      const Vec3& c = cs[static_cast<std::size_t>(k)];
      const CameraPose pose{aim_camera(c, points, views.portrait, deg2rad(uniform(rng, -4.0, 4.0))), c};
      fine = fit_margin_px(K, pose, points) >= border;
      views.poses.push_back(pose);
    }
    if (fine) return views;
  }
  return std::nullopt;
}

PixelBox projected_box(const camera::CameraIntrinsics& K, const CameraPose& pose, const std::vector<Vec3>& points) {
  PixelBox b;
  b.u0 = std::numeric_limits<double>::infinity(), b.u1 = -b.u0, b.v0 = b.u0, b.v1 = -b.u0;
  for (const Vec3& p : points)
    if (const auto uv = project_world(K, pose, p)) {
      b.u0 = std::min(b.u0, uv->x()), b.u1 = std::max(b.u1, uv->x()), b.v0 = std::min(b.v0, uv->y()),
      b.v1 = std::max(b.v1, uv->y());
    }
  return b;
}

cv::Rect roi_rect(const PixelBox& b, const std::array<double, 4>& margin_fraction, int width, int height) {
  const double larger = std::max(b.u1 - b.u0, b.v1 - b.v0);
  std::array<double, 4> m{};
  for (std::size_t i = 0; i < 4; ++i) m[i] = std::max(8.0, margin_fraction[i] * larger);
  const int x0 = std::max(0, static_cast<int>(std::floor(b.u0 - m[0]))),
            y0 = std::max(0, static_cast<int>(std::floor(b.v0 - m[1])));
  const int x1 = std::min(width, static_cast<int>(std::ceil(b.u1 + m[2])) + 1);
  const int y1 = std::min(height, static_cast<int>(std::ceil(b.v1 + m[3])) + 1);
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace antpose::sim
