// Meshes in the photo simulator and the antenna scenario's classic distribution: a rendered cube
// matches its analytic projection and shading, a two-triangle square renders like the equivalent
// patch, z-order between patches and meshes; classic antenna captures keep every antenna and the
// board in every photo, their truth is self-consistent, the device seed fixes the phone, the mast
// disturbance is position-dependent, bad option values are refused by name, and a seed still
// gives the first scenario's capture byte for byte.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/io/capture.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/capture_simulator.hpp"
#include "antpose/sim/photo_simulator.hpp"
#include "sim/truth_yaml.hpp"
#include "support/test_support.hpp"

namespace antpose::sim {
namespace {
namespace fs = std::filesystem;
using test::intrinsics_of;
using test::mat;
using test::vec;
using ::testing::HasSubstr;

camera::CameraIntrinsics test_camera() {
  camera::CameraIntrinsics K;
  K.width = 320, K.height = 240;
  K.fx = 300, K.fy = 301, K.cx = 161.3, K.cy = 118.7;
  K.distortion = {0.11, -0.26, 4e-4, -3e-4, 0.13};
  return K;
}

// Camera at the origin looking north (world y), image down = world down.
CameraPose north_pose() {
  CameraPose pose;
  pose.R_world_camera << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // columns: x east, y down, z north
  return pose;
}

// The ray of pixel (u, v)'s centre against an axis-aligned box: entry distance and the normal
// of the face it enters, or nothing.
std::optional<std::pair<double, Vec3>> ray_box(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi) {
  double t0 = -1e300, t1 = 1e300;
  Vec3 n = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (o[i] < lo[i] || o[i] > hi[i]) return std::nullopt;
      continue;
    }
    double a = (lo[i] - o[i]) / d[i], b = (hi[i] - o[i]) / d[i];
    Vec3 na = Vec3::Zero();
    na[i] = -1.0;
    if (a > b) std::swap(a, b), na = -na;
    if (a > t0) t0 = a, n = na;
    t1 = std::min(t1, b);
  }
  if (t0 > t1 || t0 <= 0) return std::nullopt;
  return std::make_pair(t0, n);
}

TEST(SimMeshRender, CubeSilhouetteAndShadingMatchTheAnalyticProjection) {
  const auto K = test_camera();
  const PhotoRenderer renderer(K, 3);
  const CameraPose pose = north_pose();
  const Vec3 centre(0.15, 2.0, -0.1), half(0.25, 0.2, 0.3);
  Scene scene;
  MeshObject cube;
  cube.name = "cube";
  cube.mesh = box_mesh(half);
  // Turned and tilted so that three faces are in view, each lit differently.
  cube.R_world_object = rot_z(deg2rad(30.0)) * rot_x(deg2rad(-20.0));
  cube.p_world_object = centre;
  cube.albedo = 0.8;
  scene.meshes.push_back(cube);
  Lighting light;
  cv::Mat ids;
  const cv::Mat img = renderer.render(scene, pose, light, &ids);

  int hits = 0, silhouette_mismatch = 0, shaded = 0;
  double worst_shading = 0.0;
  std::set<int> faces_seen;
  const Mat3 R_ow = cube.R_world_object.transpose();
  auto analytic = [&](double u, double v) -> std::optional<Vec3> {
    const Vec3 d = pose.R_world_camera * K.ray(Vec2(u, v));
    const auto hit = ray_box(R_ow * (pose.p_world_camera - centre), R_ow * d, -half, half);
    if (!hit) return std::nullopt;
    return Vec3(cube.R_world_object * hit->second);
  };
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const auto n = analytic(u, v);
      const bool rendered = ids.at<int>(v, u) == 0;
      if (n) ++hits;
      if (n.has_value() != rendered) {
        ++silhouette_mismatch;
        continue;
      }
      if (!n) continue;
      // Inside one face (the pixel's corners hit the same face): exact flat Lambert.
      bool interior = true;
      for (const double du : {-0.5, 0.5})
        for (const double dv : {-0.5, 0.5}) {
          const auto m = analytic(u + du, v + dv);
          interior = interior && m && (*m - *n).norm() < 1e-9;
        }
      if (!interior) continue;
      const double expected =
          cube.albedo * (light.ambient + light.direct * std::max(0.0, n->dot(light.towards_light_world)));
      worst_shading = std::max(worst_shading, std::abs(img.at<float>(v, u) - expected));
      ++shaded;
      faces_seen.insert(static_cast<int>(std::lround(n->dot(Vec3(1, 10, 100)) * 1000)));
    }
  EXPECT_GT(hits, 3000);
  EXPECT_GE(faces_seen.size(), 3u);  // three faces in view, shaded differently
  EXPECT_GT(shaded, hits / 2);
  EXPECT_LT(worst_shading, 1e-5);
  // The central sample is the pixel centre: only float round-off on the outline may differ.
  EXPECT_LE(silhouette_mismatch, 3) << "of " << hits;
}

TEST(SimMeshRender, TwoTrianglesRenderLikeTheEquivalentPatch) {
  const auto K = test_camera();
  const PhotoRenderer renderer(K, 3);
  const CameraPose pose = north_pose();
  // A 0.8 × 0.5 m rectangle 2 m ahead, tilted, facing roughly the camera.
  const Mat3 R = rot_x(deg2rad(100.0)) * rot_y(deg2rad(25.0));
  const Vec3 p(0.1, 2.0, 0.05);
  TexturedPatch patch;
  patch.name = "patch";
  patch.R_world_patch = R;
  patch.p_world_patch = p;
  patch.min_xy = Eigen::Vector2d(-0.4, -0.25);
  patch.max_xy = Eigen::Vector2d(0.4, 0.25);
  Eigen::Matrix<double, 2, 3> A;
  A << 64, 0, 32, 0, 64, 16;
  patch.texture =
      std::make_shared<const Texture>(Texture::from_image(cv::Mat(32, 64, CV_32F, cv::Scalar(1.0)), A, false));
  patch.albedo = 0.6;
  MeshObject quad;
  quad.name = "quad";
  quad.mesh.vertices = {Vec3(-0.4, -0.25, 0), Vec3(0.4, -0.25, 0), Vec3(0.4, 0.25, 0), Vec3(-0.4, 0.25, 0)};
  quad.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  quad.R_world_object = R;
  quad.p_world_object = p;
  quad.albedo = 0.6;
  quad.cull_back_faces = false;  // an open surface: shaded on the side facing the camera
  Scene a, b;
  a.patches.push_back(patch);
  b.meshes.push_back(quad);
  const Lighting light;
  const cv::Mat ia = renderer.render(a, pose, light), ib = renderer.render(b, pose, light);
  cv::Mat diff;
  cv::absdiff(ia, ib, diff);
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LT(cv::mean(diff)[0], 1e-5);
  // A sample exactly on the outline may fall on either side in float: at most one sample of 9.
  EXPECT_LE(max_diff, 0.9 / 9 + 1e-6);  // one sample of 9 between sky and surface
  EXPECT_LE(cv::countNonZero(diff > 1e-5), 4);
  // The diagonal shared by the two triangles leaves no crack: no sky inside the rectangle.
  cv::Mat ids;
  renderer.render(b, pose, light, &ids);
  const int inside = cv::countNonZero(ids == 0);
  cv::Mat pa_ids;
  renderer.render(a, pose, light, &pa_ids);
  EXPECT_GT(inside, 2000);
  EXPECT_LE(std::abs(inside - cv::countNonZero(pa_ids == 0)), 2);
}

TEST(SimMeshRender, NearestSurfaceWinsBetweenPatchesAndMeshes) {
  const auto K = test_camera();
  const PhotoRenderer renderer(K, 2);
  const CameraPose pose = north_pose();
  TexturedPatch wall;
  wall.name = "wall";
  wall.R_world_patch << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // the plane y = const, facing the camera
  wall.min_xy = Eigen::Vector2d(-5, -5);
  wall.max_xy = Eigen::Vector2d(5, 5);
  Eigen::Matrix<double, 2, 3> A;
  A << 10, 0, 50, 0, 10, 50;
  wall.texture =
      std::make_shared<const Texture>(Texture::from_image(cv::Mat(128, 128, CV_32F, cv::Scalar(0.5)), A, false));
  MeshObject cube;
  cube.name = "cube";
  cube.mesh = box_mesh(Vec3(0.2, 0.2, 0.2));
  cube.p_world_object = Vec3(0, 3, 0);
  const int c_u = static_cast<int>(std::lround(K.cx)), c_v = static_cast<int>(std::lround(K.cy));
  for (const double wall_y : {5.0, 2.0}) {
    wall.p_world_patch = Vec3(0, wall_y, 0);
    Scene s;
    s.patches.push_back(wall);
    s.meshes.push_back(cube);
    cv::Mat ids;
    renderer.render(s, pose, Lighting(), &ids);
    EXPECT_EQ(ids.at<int>(c_v, c_u), wall_y > 3.0 ? 1 : 0) << "wall at " << wall_y;
    EXPECT_EQ(ids.at<int>(5, 5), 0);  // the wall around the cube
  }
  // Behind the camera: nothing.
  cube.p_world_object = Vec3(0, -3, 0);
  Scene behind;
  behind.meshes.push_back(cube);
  cv::Mat ids;
  renderer.render(behind, pose, Lighting(), &ids);
  EXPECT_EQ(cv::countNonZero(ids != -1), 0);
}

TEST(SimMeshRender, SmoothNormalsFollowRoundedSurfacesAndKeepCreases) {
  const model::Mesh cyl = cylinder_mesh(Vec3::Zero(), Vec3(0, 0, 2), 0.1, 24);
  const auto normals = smooth_corner_normals(cyl, deg2rad(40.0));
  ASSERT_EQ(normals.size(), cyl.triangles.size());
  for (std::size_t t = 0; t < cyl.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3& p = cyl.vertices[cyl.triangles[t][k]];
      const Vec3 face = triangle_normal(cyl, t);
      if (std::abs(face.z()) > 0.99) {
        EXPECT_NEAR(normals[t][k].dot(face), 1.0, 1e-12);  // caps stay flat (90° crease)
      } else {
        EXPECT_NEAR(normals[t][k].dot(Vec3(p.x(), p.y(), 0).normalized()), 1.0, 1e-9);  // radial on the side
      }
    }
  // The panel's rounded vertical edges are smoothed, its box edges not.
  const auto panel = model::builtin_panel("panel-1310x300x160").mesh_antenna;
  const auto pn = smooth_corner_normals(panel, deg2rad(40.0));
  int smoothed = 0;
  for (std::size_t t = 0; t < panel.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) smoothed += pn[t][k].dot(triangle_normal(panel, t)) < 0.9999 ? 1 : 0;
  EXPECT_GT(smoothed, 50);
}

TEST(SimDipole, FieldIsTheDipoleFormulaAndTheMastDisturbanceHitsItsTarget) {
  const MagneticDipole d{Vec3(0, 0, 1), Vec3(0, 0, 1000)};
  // On the axis B = 2 · 1e-7 m / r³ T; in the equatorial plane −1e-7 m / r³.
  EXPECT_NEAR(dipole_field_uT(d, Vec3(0, 0, 3)).z(), 0.2 * 1000 / 8.0, 1e-9);
  EXPECT_NEAR(dipole_field_uT(d, Vec3(2, 0, 1)).z(), -0.1 * 1000 / 8.0, 1e-9);
  std::mt19937_64 rng(4);
  const AntennaLayout layout = draw_antenna_layout(AntennaSetting::kRooftop, 2, rng);
  const Vec3 field(0.0, 34.0, -30.0);
  const Vec3 p_ref(6.0, 2.0, 1.5);
  const auto dipoles = mast_dipoles(layout, field, p_ref, deg2rad(-5.0), rng);
  EXPECT_NEAR(rad2deg(north_shift(dipoles, field, p_ref)), -5.0, 1e-9);
  // Position-dependent: weaker far away, different elsewhere on the walk.
  EXPECT_LT(std::abs(north_shift(dipoles, field, 3.0 * p_ref)), std::abs(north_shift(dipoles, field, p_ref)) / 5);
  EXPECT_GT(std::abs(north_shift(dipoles, field, Vec3(2.0, 6.0, 1.5)) - north_shift(dipoles, field, p_ref)),
            deg2rad(0.2));
}

// The classic distribution: these tests pin its narrow scenes (wide sites: antenna_site_test.cpp).
CaptureScenario small_antenna_scenario(std::uint64_t seed) {
  CaptureScenario sc;
  sc.scenario = Scenario::kAntenna;
  sc.distribution = Distribution::kClassic;
  sc.seed = seed;
  sc.device.width = 640, sc.device.height = 480;
  sc.device.supersampling = 1;
  sc.photos = 5;
  sc.antennas = 3;
  sc.disturbance = true;
  sc.device.phone = "ideal";
  return sc;
}

// One rooftop capture with three antennas and the disturbance, shared by the tests below.
class SimAntennaCapture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    sim_ = new SimulatedCapture(write_simulated_capture(small_antenna_scenario(21), dir_->path() / "ant", false));
  }
  static void TearDownTestSuite() {
    delete sim_;
    delete dir_;
  }
  static fs::path folder() { return dir_->path() / "ant"; }
  static test::TempDir* dir_;
  static SimulatedCapture* sim_;
};
test::TempDir* SimAntennaCapture::dir_ = nullptr;
SimulatedCapture* SimAntennaCapture::sim_ = nullptr;

TEST_F(SimAntennaCapture, EveryPhotoShowsEveryAntennaAndTheBoard) {
  Diagnostics diag;
  const Capture c = read_capture(folder(), diag);
  EXPECT_EQ(c.kind, "antenna");
  ASSERT_EQ(c.shots.size(), 5u);
  const YAML::Node scene = YAML::LoadFile((folder() / "truth/scene.yaml").string());
  const YAML::Node device = YAML::LoadFile((folder() / "truth/device.yaml").string());
  const auto K = intrinsics_of(device);
  EXPECT_EQ(scene["setting"].as<std::string>(), "rooftop");
  ASSERT_EQ(scene["antennas"].size(), 3u);
  EXPECT_THAT(io::read_text(folder() / "board.yaml"), HasSubstr("square_m: 0.07"));
  const double decl = scene["declination_deg"].as<double>();
  for (const auto& a : scene["antennas"]) {
    const Mat3 R = mat(a["R_world_antenna"]);
    const Vec3 p = vec(a["p_world_antenna_m"]);
    const double az = a["azimuth_magnetic_deg"].as<double>(), tilt = a["downtilt_deg"].as<double>(),
                 roll = a["roll_deg"].as<double>();
    EXPECT_LT((R - rot_z(-deg2rad(az)) * rot_x(-deg2rad(tilt)) * rot_y(deg2rad(roll))).norm(), 1e-9);
    EXPECT_NEAR(std::remainder(a["azimuth_true_deg"].as<double>() - az - decl, 360.0), 0.0, 1e-9);
    EXPECT_GE(tilt, 0.0);
    EXPECT_LE(tilt, 12.0);
    EXPECT_LE(std::abs(roll), 2.0);
    EXPECT_GT(a["viewing_span_deg"].as<double>(), 20.0);
    const model::AntennaModel m = model::builtin_panel(a["model"].as<std::string>());
    EXPECT_NEAR(a["panel"]["height_m"].as<double>(), m.size_m.z(), 1e-12);
    const Vec3 half(a["panel"]["width_m"].as<double>() / 2, a["panel"]["depth_m"].as<double>() / 2,
                    a["panel"]["height_m"].as<double>() / 2);
    const auto roi = a["roi"];
    const cv::Rect box(roi["x"].as<int>(), roi["y"].as<int>(), roi["width"].as<int>(), roi["height"].as<int>());
    EXPECT_TRUE((box & cv::Rect(0, 0, K.width, K.height)) == box);
    for (const auto& s : scene["shots"]) {
      const CameraPose pose{mat(s["R_world_camera"]), vec(s["p_world_camera_m"])};
      for (int i = 0; i < 8; ++i) {
        const Vec3 corner =
            p + R * Vec3((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(), (i & 4 ? 1 : -1) * half.z());
        const auto uv = project_world(K, pose, corner);
        ASSERT_TRUE(uv.has_value());
        EXPECT_GT(uv->x(), 0.0);
        EXPECT_GT(uv->y(), 0.0);
        EXPECT_LT(uv->x(), K.width - 1.0);
        EXPECT_LT(uv->y(), K.height - 1.0);
        if (s["image"].as<std::string>() == roi["image"].as<std::string>()) {
          EXPECT_TRUE(box.contains(cv::Point(static_cast<int>(uv->x()), static_cast<int>(uv->y()))));
        }
      }
    }
    for (const auto& f : a["visible_fraction"]) EXPECT_GE(f.as<double>(), 0.5);
  }
  // The board as well, on its tripod 1.5–4 m from the phone.
  const auto pl = scene["placements"][0];
  const camera::BoardSpec board = camera::read_board(folder() / "board.yaml");
  Vec3 board_centre = Vec3::Zero();
  for (const Vec3& q : board.object_points()) board_centre += q / static_cast<double>(board.object_points().size());
  board_centre = vec(pl["p_world_board_m"]) + mat(pl["R_world_board"]) * board_centre;
  for (const auto& s : scene["shots"]) {
    const CameraPose pose{mat(s["R_world_camera"]), vec(s["p_world_camera_m"])};
    for (const Vec3& q : board.object_points()) {
      const auto uv = project_world(K, pose, vec(pl["p_world_board_m"]) + mat(pl["R_world_board"]) * q);
      ASSERT_TRUE(uv.has_value());
      EXPECT_TRUE(uv->x() > 0 && uv->y() > 0 && uv->x() < K.width - 1 && uv->y() < K.height - 1);
    }
    const double dist = (board_centre - pose.p_world_camera).norm();
    EXPECT_GT(dist, 1.4);
    EXPECT_LT(dist, 4.1);
  }
  // The board is detected where the truth projects it (640 × 480: squares of 10–20 px).
  int found = 0;
  for (const auto& s : scene["shots"]) {
    const cv::Mat grey = cv::imread((folder() / s["image"].as<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(grey, cv::Size(board.cols, board.rows), corners)) continue;
    ++found;
    cv::cornerSubPix(grey, corners, cv::Size(3, 3), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
    const CameraPose pose{mat(s["R_world_camera"]), vec(s["p_world_camera_m"])};
    const auto object = board.object_points();
    double ss = 0;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const auto uv = project_world(K, pose, vec(pl["p_world_board_m"]) + mat(pl["R_world_board"]) * object[k]);
      ss += std::pow(corners[k].x - uv->x(), 2) + std::pow(corners[k].y - uv->y(), 2);
    }
    EXPECT_LT(std::sqrt(ss / static_cast<double>(corners.size())), 0.3) << s["image"].as<std::string>();
  }
  EXPECT_GE(found, 4);

  // The region of interest in the photo is not plain sky: the panel is drawn there.
  const auto roi = scene["antennas"][0]["roi"];
  const cv::Mat img = cv::imread((folder() / roi["image"].as<std::string>()).string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty());
  cv::Scalar mean, sd;
  cv::meanStdDev(img(cv::Rect(roi["x"].as<int>(), roi["y"].as<int>(), roi["width"].as<int>(), roi["height"].as<int>())),
                 mean, sd);
  EXPECT_GT(sd[0], 5.0);
}

TEST_F(SimAntennaCapture, DisturbanceIsPositionDependentAndAbsentWithoutTheFlag) {
  const YAML::Node scene = YAML::LoadFile((folder() / "truth/scene.yaml").string());
  const auto dist = scene["disturbance"];
  EXPECT_EQ(dist["model"].as<std::string>(), "dipole-line");
  ASSERT_EQ(dist["north_shift_deg"].size(), 5u);
  const double mid = dist["north_shift_deg"][2].as<double>();
  EXPECT_GE(std::abs(mid), 2.9);
  EXPECT_LE(std::abs(mid), 8.1);
  EXPECT_GT(std::abs(dist["north_shift_deg"][0].as<double>() - dist["north_shift_deg"][4].as<double>()), 0.05);
  EXPECT_NEAR(dist["heading_error_deg"][2].as<double>(), -mid, 1e-9);
  EXPECT_THAT(io::read_text(folder() / "truth/device.yaml"), HasSubstr("dipoles:"));

  // Same seed without the flag: the same walk and photos, only the magnetometer differs.
  test::TempDir dir;
  CaptureScenario sc = small_antenna_scenario(21);
  sc.disturbance = false;
  const SimulatedCapture clean = write_simulated_capture(sc, dir / "clean", false);
  Diagnostics diag;
  const Capture a = read_capture(folder(), diag), b = read_capture(dir / "clean", diag);
  const YAML::Node clean_scene = YAML::LoadFile((dir / "clean/truth/scene.yaml").string());
  EXPECT_EQ(clean_scene["disturbance"]["model"].as<std::string>(), "none");
  EXPECT_EQ(clean_scene["disturbance"]["north_shift_deg"][2].as<double>(), 0.0);
  EXPECT_EQ(io::read_text(folder() / "sensors/accelerometer.csv"),
            io::read_text(dir / "clean/sensors/accelerometer.csv"));
  const Stream& ma = a.streams.at("magnetometer");
  const Stream& mb = b.streams.at("magnetometer");
  ASSERT_EQ(ma.t.size(), mb.t.size());
  const double diff = (ma.values - mb.values).rowwise().norm().maxCoeff();
  EXPECT_GT(diff, 1.0);  // µT
  EXPECT_LT(diff, 40.0);
}

TEST(SimAntennaDevice, DeviceSeedFixesThePhoneAcrossScenes) {
  test::TempDir dir;
  CaptureScenario a = small_antenna_scenario(31), b = small_antenna_scenario(32);
  a.photos = b.photos = 3;
  a.antennas = b.antennas = 1;
  a.disturbance = b.disturbance = false;
  a.device.phone = b.device.phone = "random";
  a.device_seed = b.device_seed = 7;
  const SimulatedCapture sa = write_simulated_capture(a, dir / "a", false);
  const SimulatedCapture sb = write_simulated_capture(b, dir / "b", false);
  const YAML::Node da = YAML::LoadFile((dir / "a/truth/device.yaml").string());
  const YAML::Node db = YAML::LoadFile((dir / "b/truth/device.yaml").string());
  for (const char* key : {"camera", "camera_imu", "accelerometer", "gyroscope", "magnetometer"})
    EXPECT_EQ(YAML::Dump(da[key]), YAML::Dump(db[key])) << key;
  // The scenes differ.
  EXPECT_NE(sa.antenna->layout.antennas[0].azimuth_magnetic, sb.antenna->layout.antennas[0].azimuth_magnetic);
  // Without a device seed the phone follows the scene seed.
  CaptureScenario c = small_antenna_scenario(31);
  c.photos = 3, c.antennas = 1, c.disturbance = false, c.device.phone = "random";
  const SimulatedDevice dc = make_device(c.device, 31), d7 = make_device(c.device, 7);
  EXPECT_EQ(sa.device.intrinsics.fx, d7.intrinsics.fx);
  EXPECT_NE(dc.intrinsics.fx, d7.intrinsics.fx);
}

TEST(SimAntennaCli, WritesAGroundCaptureAndNamesBadOptions) {
  test::TempDir dir;
  const std::string out = (dir / "g").string();
  const auto r = test::run_cli("simulate capture -o '" + out +
                               "' --scenario antenna --distribution classic --setting ground --antennas 2 --radome plain "
                               "--photos 4 --width 480 --height 360 --supersampling 1 --seed 8 --device-seed 3");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("2 antenna(s) on a ground mast"));
  const YAML::Node scene = YAML::LoadFile((dir / "g/truth/scene.yaml").string());
  EXPECT_EQ(scene["setting"].as<std::string>(), "ground");
  EXPECT_EQ(scene["antennas"].size(), 2u);
  EXPECT_EQ(scene["antennas"][0]["radome"].as<std::string>(), "plain");
  for (const auto& a : scene["antennas"]) {
    EXPECT_GE(a["p_world_antenna_m"][2].as<double>(), 9.9);
    EXPECT_LE(a["p_world_antenna_m"][2].as<double>(), 20.1);
  }
  EXPECT_EQ(scene["shots"].size(), 4u);

  // The board's greatest distance from the phone bounds the walk: 4 m by default, or as given
  // (measured from the board's first corner, within 0.45 m of its centre, which the walk keeps in range).
  const auto farthest_photo_from_board_m = [](const YAML::Node& t) {
    const Vec3 board = vec(t["placements"][0]["p_world_board_m"]);
    double far = 0;
    for (const auto& shot : t["shots"]) far = std::max(far, (vec(shot["p_world_device_m"]) - board).norm());
    return far;
  };
  const auto wide = test::run_cli("simulate capture -o '" + (dir / "wide").string() +
                                  "' --scenario antenna --distribution classic --setting ground --photos 4 --width 480 "
                                  "--height 360 --supersampling 1 --seed 8 --device-seed 3 --board-max-distance 8");
  ASSERT_EQ(wide.status, 0) << wide.err;
  const double near = farthest_photo_from_board_m(scene),
               far = farthest_photo_from_board_m(YAML::LoadFile((dir / "wide/truth/scene.yaml").string()));
  std::printf("farthest photo from the board: %.2f m by default, %.2f m with --board-max-distance 8\n", near, far);
  EXPECT_LE(near, 4.0 + 0.45);
  EXPECT_GT(far, 5.5);
  EXPECT_LE(far, 8.0 + 0.45);

  const std::string o = " -o '" + (dir / "x").string() + "' --scenario antenna";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--setting moon", "--setting"}, {"--antennas 4", "--antennas"},
      {"--antennas 0", "--antennas"},  {"--radome shiny", "--radome"},
      {"--photos 61", "--photos"},     {"--board-max-distance 1", "--board-max-distance"},
  };
  for (const auto& [args, name] : cases) {
    const auto e = test::run_cli("simulate capture" + o + " " + args);
    EXPECT_EQ(e.status, 2) << args;
    EXPECT_THAT(e.err, HasSubstr(name)) << args << ": " << e.err;
    EXPECT_THAT(e.err, ::testing::AnyOf(HasSubstr("outside"), HasSubstr("is not"))) << args << ": " << e.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x"));
  // The library names the options too.
  CaptureScenario sc = small_antenna_scenario(1);
  sc.antennas = 5;
  EXPECT_THAT(test::input_error([&] { simulate_capture(sc, dir / "scratch"); }), HasSubstr("--antennas"));
  EXPECT_THAT(test::input_error([&] { parse_antenna_setting("sea"); }), HasSubstr("--setting"));
  EXPECT_THAT(test::input_error([&] { parse_radome_look("gold"); }), HasSubstr("--radome"));
}

// Regression sites are stored as seeds: the classic distribution must draw, render and write
// exactly what the first antenna scenario did. The hashes (FNV-1a 64 of each file) are those of
// that scenario's capture with these options, before the wide distribution existed.
TEST(SimAntennaCli, ClassicReproducesTheFirstScenarioByteForByte) {
  test::TempDir dir;
  const auto r = test::run_cli("simulate capture -o '" + (dir / "c").string() +
                               "' --scenario antenna --distribution classic --seed 7 --setting rooftop --antennas 2 "
                               "--width 320 --height 240 --supersampling 1 --photos 3");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::pair<std::string, std::uint64_t>> expected = {
      {"board.yaml", 0x008f479983b02b4aULL},
      {"capture.yaml", 0x60861bced4b9e436ULL},
      {"shots.csv", 0xb00448a72b2b3fffULL},
      {"images/img_0000.jpg", 0xfbc97d4a6441c24aULL},
      {"images/img_0001.jpg", 0x58efb6365db48977ULL},
      {"images/img_0002.jpg", 0x2d7ab82bdd041e67ULL},
      {"sensors/accelerometer.csv", 0xf5e0e29ea232592bULL},
      {"sensors/gyroscope.csv", 0x4cb8238418f4322aULL},
      {"sensors/magnetometer.csv", 0x4ac0005cdbd23c48ULL},
      {"truth/device.yaml", 0xc14cd2ab060ef899ULL},
      {"truth/orientation.csv", 0x6e0656eae68436b4ULL},
      {"truth/scene.yaml", 0x5edfe7d881b74647ULL},
  };
  const auto fnv1a = [](const std::string& bytes) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (const unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ULL;
    return h;
  };
  std::size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "c")) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, expected.size());
  for (const auto& [file, hash] : expected) {
    std::ifstream in(dir / "c" / file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(fnv1a(bytes), hash) << file;
  }
}

}  // namespace
}  // namespace antpose::sim

namespace antpose::sim {
namespace {

// Render time of an antenna scene (mast, three panels, arms, clamps, tripod, board, roof,
// parapets, street) at `width` × 3/4 width with supersampling S, seconds (best of 2).
double antenna_render_seconds(int width, int S) {
  test::TempDir dir;
  CaptureScenario sc = small_antenna_scenario(21);
  sc.photos = 3;
  const SimulatedCapture sim = write_simulated_capture(sc, dir / "s", false);
  DeviceOptions big = sc.device;
  big.width = width, big.height = width * 3 / 4;
  const SimulatedDevice d = make_device(big, sc.seed);  // same field of view as the small capture
  const PhotoRenderer renderer(d.intrinsics, S);
  Scene scene;
  scene.patches = sim.surfaces;
  scene.patches.push_back(board_patch(board_texture(antenna_board(camera::BoardType::kChessboard)),
                                      sim.placements[0].R_world_board, sim.placements[0].p_world_board));
  scene.meshes = sim.meshes;
  const CameraPose pose{sim.shots[1].R_world_camera, sim.shots[1].p_world_camera};
  double best = 1e9;
  for (int k = 0; k < 2; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const cv::Mat img = renderer.render(scene, pose, Lighting());
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    EXPECT_EQ(img.cols, width);
  }
  std::printf("antenna scene %dx%d S=%d: %.3f s per render\n", width, width * 3 / 4, S, best);
  return best;
}

TEST(SimMeshRender, AntennaSceneRendersInSeconds) { EXPECT_LT(antenna_render_seconds(1600, 3), 10.0); }

// 12 MP: run with --gtest_also_run_disabled_tests (≈ a minute with the setup).
TEST(SimMeshRender, DISABLED_AntennaScene12MegapixelSpeed) { EXPECT_LT(antenna_render_seconds(4000, 2), 60.0); }

}  // namespace
}  // namespace antpose::sim
