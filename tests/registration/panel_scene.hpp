// A small rendered scene for the registration's tests: one parametric panel on a pole with two
// arms, over textured ground, photographed from several directions (defaults: a rooftop, a
// 1.31 m panel seen from 5.5 m at 1.5 m height, 7 views spanning 30°, 1280 × 960, noise, no JPEG).
#pragma once

#include <numbers>
#include <vector>

#include "antpose/model/antenna_model.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/registration/silhouette.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/photo_simulator.hpp"
#include "support/render_support.hpp"

namespace antpose::registration::fixture {

using test::iso;

struct SyntheticScene {
  camera::CameraIntrinsics intrinsics;
  model::Mesh mesh_antenna;
  Iso3 T_board_antenna;
  std::vector<SilhouetteView> views;
  reconstruction::Mast mast;  // the pole, board frame
};

// Where the antenna stands and how it is photographed. The defaults are a rooftop: a 1.31 m
// panel on a thin pole with two arms, over textured ground, seen from 5.5 m at 1.5 m height from
// 7 directions spanning 30°, rendered at 1280 × 960 with noise and JPEG-free 8-bit output.
struct SceneSpec {
  model::PanelSpec panel{};
  double distance_m = 5.5, below_m = 1.3;  // the cameras from the antenna, horizontally and below it
  double antenna_height_m = 2.8;
  double mast_radius_m = 0.057, mast_behind_m = 0.35;
  double mast_base_m = 0.0;  // world height of the pole's foot (a roof)
  double focal_px = 1050;
  std::vector<double> view_offsets_deg{-15.0, -10.0, -5.0, 0.0, 5.0, 10.0, 15.0};
  bool look_away = false;  // the cameras turned away from the antenna
  /// Where not empty, rendered in place of the panel (antenna frame): a panel other than the model.
  model::Mesh rendered{};
};

// The board frame is an arbitrary rigid frame (T_world_board), as in a real capture.
inline SyntheticScene make_scene(const SceneSpec& spec = {}) {
  SyntheticScene s;
  auto& K = s.intrinsics;
  K.width = 1280, K.height = 960, K.fx = K.fy = spec.focal_px, K.cx = 643.2, K.cy = 478.9;
  K.distortion = {0.08, -0.2, 0.0002, -0.0003, 0.1};

  const auto panel = model::parametric_panel(spec.panel);
  s.mesh_antenna = panel.mesh_antenna;
  const double az = deg2rad(37), tilt = deg2rad(6), roll = deg2rad(1.5);
  const Mat3 R_world_antenna = rot_z(-az) * rot_x(-tilt) * rot_y(roll);
  const Vec3 p_world_antenna(0.2, -0.1, spec.antenna_height_m);
  const Vec3 boresight = R_world_antenna * Vec3::UnitY();
  const Vec3 back = -Vec3(boresight.x(), boresight.y(), 0).normalized();
  const Vec3 mast = p_world_antenna + spec.mast_behind_m * back;

  sim::Scene scene;
  sim::MeshObject antenna;
  antenna.name = "antenna";
  antenna.mesh = spec.rendered.vertices.empty() ? panel.mesh_antenna : spec.rendered;
  antenna.corner_normals = sim::smooth_corner_normals(antenna.mesh, deg2rad(30));
  antenna.R_world_object = R_world_antenna;
  antenna.p_world_object = p_world_antenna;
  antenna.albedo = 0.72;
  scene.meshes.push_back(antenna);
  sim::MeshObject pole;
  pole.name = "pole";
  pole.mesh = sim::cylinder_mesh(Vec3(mast.x(), mast.y(), spec.mast_base_m), Vec3(mast.x(), mast.y(), spec.antenna_height_m + 1.4),
                                 spec.mast_radius_m, 24);
  pole.albedo = 0.45;
  scene.meshes.push_back(pole);
  for (double dz : {-0.33, 0.33}) {  // clamp arms from the brackets to the pole: edges not in the model
    const Vec3 from = p_world_antenna + R_world_antenna * Vec3(0, -0.11, dz * spec.panel.height_m);
    sim::MeshObject arm;
    arm.name = "arm";
    arm.mesh = sim::cylinder_mesh(from, Vec3(mast.x(), mast.y(), from.z()), 0.025, 12);
    arm.albedo = 0.4;
    scene.meshes.push_back(arm);
  }
  sim::TexturedPatch ground;
  ground.name = "ground";
  ground.min_xy = Eigen::Vector2d(-40, -40), ground.max_xy = Eigen::Vector2d(40, 40);
  ground.texture = sim::procedural_texture(7, 2.0, 256, 0.35, 0.12);
  scene.patches.push_back(ground);

  const Iso3 T_world_board = iso(exp_so3(Vec3(0.3, -0.2, 2.1)), Vec3(1.5, -3.0, 1.2));
  s.T_board_antenna = T_world_board.inverse() * iso(R_world_antenna, p_world_antenna);
  s.mast.up_board = T_world_board.linear().transpose() * Vec3::UnitZ();
  s.mast.axis_point_board = T_world_board.inverse() * Vec3(mast.x(), mast.y(), spec.antenna_height_m);
  s.mast.radius_m = spec.mast_radius_m;
  s.mast.low_m = spec.mast_base_m - spec.antenna_height_m, s.mast.high_m = 1.4;

  const sim::PhotoRenderer renderer(K, 2);
  sim::SensorModel sensor;
  sensor.jpeg_quality = 100;
  const double view_az = std::atan2(boresight.x(), boresight.y());
  int k = 0;
  for (double d : spec.view_offsets_deg) {
    const double a = view_az + deg2rad(d);
    const Vec3 from = p_world_antenna + spec.distance_m * Vec3(std::sin(a), std::cos(a), 0) - Vec3(0, 0, spec.below_m);
    Vec3 forward = (p_world_antenna - from).normalized();
    if (spec.look_away) forward = Vec3(-forward.x(), -forward.y(), 0.2);  // turned away from the mast
    // A little camera roll per view, as hand-held.
    const auto pose = test::level_camera(from, forward, deg2rad(2.0 * ((k % 3) - 1)));
    const cv::Mat radiance = renderer.render(scene, pose, sim::Lighting{});
    SilhouetteView v;
    v.image = sim::sensor_image(radiance, sensor, 100 + k++);
    const Iso3 T_camera_board = test::camera_from_board(pose, T_world_board);
    v.R_camera_board = T_camera_board.linear();
    v.t_camera_board = T_camera_board.translation();
    s.views.push_back(v);
  }
  return s;
}

}  // namespace antpose::registration::fixture
