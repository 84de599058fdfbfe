// A rendered test scene for the reconstruction tests: a panel antenna (a 0.30 × 0.16 × 1.30 m box
// of 6 textured patches), a chessboard, a textured ground and a far wall, seen by a row of
// cameras. World frame = board frame (board.hpp: x along the columns, y along the rows = down,
// z into the board); the cameras stand at z ≈ −2.6 m looking +z.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "antpose/camera/board.hpp"
#include "antpose/camera/board_pose.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::test {

/// 960 × 720 px (scale 1) or that times `scale` (e.g. 4000 × 3000 for a 12 MP phone, scale 4.1667).
inline camera::CameraIntrinsics scene_intrinsics(double scale = 1.0) {
  camera::CameraIntrinsics K;
  K.width = int(std::lround(960 * scale)), K.height = int(std::lround(720 * scale));
  K.fx = K.fy = 850 * scale;
  K.cx = 0.5 * K.width - 0.5, K.cy = 0.5 * K.height - 0.5;
  K.distortion = {0.05, -0.1, 0.0005, -0.0003, 0.02};
  return K;
}

struct AntennaBox {
  Mat3 R_world_antenna;  // columns x_a, y_a (boresight), z_a (up the panel)
  Vec3 centre;
  Vec3 half{0.15, 0.08, 0.65};
  /// Unsigned distance of a world point to the box surface, m.
  double distance(const Vec3& p_world) const {
    const Vec3 p = R_world_antenna.transpose() * (p_world - centre);
    const Vec3 outside = (p.cwiseAbs() - half).cwiseMax(0.0);
    const double in = (half - p.cwiseAbs()).minCoeff();
    return outside.norm() > 0 ? outside.norm() : in;
  }
  Vec3 front_normal() const { return R_world_antenna.col(1); }
};

inline AntennaBox scene_antenna(const Vec3& centre = Vec3(1.0, -0.3, 1.2)) {
  // Boresight towards the cameras (−z world), up = −y world, then 20° of azimuth and 4° of tilt.
  Mat3 base;
  base.col(1) = Vec3(0, 0, -1);
  base.col(2) = Vec3(0, -1, 0);
  base.col(0) = base.col(1).cross(base.col(2));
  AntennaBox box;
  box.R_world_antenna = rot_y(deg2rad(20)) * base * rot_x(deg2rad(4));
  box.centre = centre;
  return box;
}

struct SceneOptions {
  double radome_contrast = 0.15;  // 1σ reflectance texture of the radome; 0: plain grey
  int views = 5;
  double board_noise_px = 0.3;
  std::uint64_t seed = 7;
  double spacing_m = 0.5;    // between neighbouring cameras
  double image_scale = 1.0;  // scene_intrinsics(image_scale)
  int supersampling = 2;
  Vec3 antenna_centre = Vec3(1.0, -0.3, 1.2);  // world (= board frame), m
  double wall_z = 9.0;                         // the far wall's distance, m
  /// Small textured cards facing the cameras (centre in the world, half-size, m): objects nearer
  /// than the antenna that give features but too few points for an antenna.
  std::vector<std::pair<Vec3, double>> cards;
};

struct Scene {
  camera::CameraIntrinsics K;
  AntennaBox antenna;
  std::vector<sim::CameraPose> cameras;          // truth
  std::vector<reconstruction::PosedView> views;  // PnP poses from noisy board points
};

inline std::vector<sim::TexturedPatch> antenna_patches(const AntennaBox& box, double contrast, std::uint64_t seed) {
  auto texture = sim::procedural_texture(seed, 0.5, 256, 0.7, contrast);
  const Mat3& R = box.R_world_antenna;
  std::vector<sim::TexturedPatch> out;
  auto face = [&](const Vec3& u, const Vec3& v, const Vec3& offset, double hu, double hv, double shade) {
    sim::TexturedPatch p;
    p.name = "antenna";
    p.R_world_patch.col(0) = R * u;
    p.R_world_patch.col(1) = R * v;
    p.R_world_patch.col(2) = (R * u).cross(R * v);
    p.p_world_patch = box.centre + R * offset;
    p.min_xy = Eigen::Vector2d(-hu, -hv);
    p.max_xy = Eigen::Vector2d(hu, hv);
    p.texture = texture;
    p.albedo = shade;
    out.push_back(p);
  };
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  const Vec3& h = box.half;
  for (double s : {-1.0, 1.0}) {
    face(ex, ez, s * h.y() * ey, h.x(), h.z(), 1.0);
    face(ey, ez, s * h.x() * ex, h.y(), h.z(), 1.0);
    face(ex, ey, s * h.z() * ez, h.x(), h.y(), 1.0);
  }
  return out;
}

inline Scene make_scene(const SceneOptions& options) {
  Scene scene;
  scene.K = scene_intrinsics(options.image_scale);
  scene.antenna = scene_antenna(options.antenna_centre);
  camera::BoardSpec board;
  board.type = camera::BoardType::kChessboard;
  board.cols = 8, board.rows = 6, board.square_m = 0.05;
  const auto board_tex = sim::board_texture(board);
  std::vector<sim::TexturedPatch> patches = antenna_patches(scene.antenna, options.radome_contrast, options.seed);
  patches.push_back(sim::board_patch(board_tex, Mat3::Identity(), Vec3::Zero()));
  // Ground 1.5 m below the board, a wall 9 m away (below the horizon of the antenna: the region
  // around the antenna holds sky above and wall below).
  auto ground_tex = sim::procedural_texture(options.seed + 1, 2.0, 256, 0.35, 0.12);
  sim::TexturedPatch ground;
  ground.name = "ground";
  ground.R_world_patch.col(0) = Vec3::UnitX();
  ground.R_world_patch.col(1) = Vec3::UnitZ();
  ground.R_world_patch.col(2) = Vec3::UnitX().cross(Vec3::UnitZ());
  ground.p_world_patch = Vec3(0, 1.5, 0);
  ground.min_xy = Eigen::Vector2d(-10, -5);
  ground.max_xy = Eigen::Vector2d(10, options.wall_z);
  ground.texture = ground_tex;
  patches.push_back(ground);
  sim::TexturedPatch wall = ground;
  wall.name = "wall";
  wall.R_world_patch = Mat3::Identity();
  wall.p_world_patch = Vec3(0, 0, options.wall_z);
  wall.min_xy = Eigen::Vector2d(-10, 0.0);
  wall.max_xy = Eigen::Vector2d(10, 1.5);
  wall.texture = sim::procedural_texture(options.seed + 2, 2.0, 256, 0.5, 0.12);
  patches.push_back(wall);
  for (std::size_t i = 0; i < options.cards.size(); ++i) {
    sim::TexturedPatch card;
    card.name = "card";
    card.p_world_patch = options.cards[i].first;
    const double h = options.cards[i].second;
    card.min_xy = Eigen::Vector2d(-h, -h), card.max_xy = Eigen::Vector2d(h, h);
    card.texture = sim::procedural_texture(options.seed + 10 + i, 2 * h, 256, 0.5, 0.45);
    patches.push_back(card);
  }

  const sim::PhotoRenderer renderer(scene.K, options.supersampling);
  sim::Lighting light;
  light.towards_light_world = Vec3(-0.5, -0.7, -0.5).normalized();
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, options.board_noise_px);
  // Between the board and the antenna, so that both are in view.
  const Vec3 target = 0.5 * (Vec3(0.2, 0.1, 0.0) + options.antenna_centre);
  const auto board_points = board.object_points();
  for (int k = 0; k < options.views; ++k) {
    const double s = k - 0.5 * (options.views - 1);
    const Vec3 C(0.5 + options.spacing_m * s, -0.4 + 0.1 * options.spacing_m * s,
                 -2.6 + 0.2 * options.spacing_m * std::abs(s));
    sim::CameraPose pose;
    const Vec3 z = (target - C).normalized();
    const Vec3 x = Vec3::UnitY().cross(z).normalized();
    pose.R_world_camera.col(0) = x;
    pose.R_world_camera.col(1) = z.cross(x);
    pose.R_world_camera.col(2) = z;
    pose.p_world_camera = C;
    scene.cameras.push_back(pose);
    sim::SensorModel sensor;
    const cv::Mat radiance = renderer.render(patches, pose, light);
    const cv::Mat image8 = sim::sensor_image(radiance, sensor, options.seed * 100 + k);
    const std::string jpeg = sim::encode_jpeg(image8, sensor.jpeg_quality);
    reconstruction::PosedView view;
    view.name = "view " + std::to_string(k);
    view.image =
        cv::imdecode(cv::Mat(1, int(jpeg.size()), CV_8UC1, const_cast<char*>(jpeg.data())), cv::IMREAD_GRAYSCALE);
    for (const auto& p : board_points) {
      const auto uv = sim::project_world(scene.K, pose, p);
      view.board_image_px.push_back(*uv + Vec2(noise(rng), noise(rng)));
      view.board_points_m.push_back(p);
    }
    const auto pnp = camera::estimate_board_pose(view.board_image_px, view.board_points_m, scene.K);
    view.R_camera_board = pnp.R_camera_board;
    view.t_camera_board = pnp.t_camera_board;
    scene.views.push_back(std::move(view));
  }
  return scene;
}

/// True pose of camera k in the board (= world) frame.
inline std::pair<Mat3, Vec3> true_pose(const Scene& s, std::size_t k) {
  const Mat3 R = s.cameras[k].R_world_camera.transpose();
  return {R, -R * s.cameras[k].p_world_camera};
}

/// The tight rectangle around the antenna's projection in view k, px.
inline reconstruction::Roi antenna_roi(const Scene& s, std::size_t k, int margin_px = 6) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    const Vec3 p = s.antenna.centre + s.antenna.R_world_antenna * c.cwiseProduct(s.antenna.half);
    const auto uv = sim::project_world(s.K, s.cameras[k], p);
    x0 = std::min(x0, uv->x()), x1 = std::max(x1, uv->x()), y0 = std::min(y0, uv->y()), y1 = std::max(y1, uv->y());
  }
  return {int(x0) - margin_px, int(y0) - margin_px, int(x1 - x0) + 2 * margin_px, int(y1 - y0) + 2 * margin_px};
}

}  // namespace antpose::test
