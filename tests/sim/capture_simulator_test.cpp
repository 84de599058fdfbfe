// Simulated photo captures: the truth files agree with each other and with the photos, the
// reference readings stay within the instruments' bounds, and a seed reproduces a capture.
#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/calibration/board_reference.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/sim/capture_simulator.hpp"
#include "sim/truth_yaml.hpp"
#include "support/test_support.hpp"

namespace antpose::sim {
namespace {
namespace fs = std::filesystem;
using test::intrinsics_of;
using test::mat;
using test::vec;

// q_world_device of the truth stream at t, by slerp between the neighbouring samples.
Mat3 truth_at(const Stream& truth, double t) {
  const auto it = std::upper_bound(truth.t.begin(), truth.t.end(), t);
  EXPECT_TRUE(it != truth.t.begin() && it != truth.t.end());
  const auto i1 = static_cast<Eigen::Index>(it - truth.t.begin()), i0 = i1 - 1;
  auto q = [&](Eigen::Index i) { return Quat(truth.values(i, 0), truth.values(i, 1), truth.values(i, 2), truth.values(i, 3)); };
  const double f = (t - truth.t[static_cast<std::size_t>(i0)]) / (truth.t[static_cast<std::size_t>(i1)] - truth.t[static_cast<std::size_t>(i0)]);
  return q(i0).slerp(f, q(i1)).toRotationMatrix();
}

// One joint-calibration capture shared by the tests below (rendering is the slow part).
class JointCapture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    CaptureScenario sc;
    sc.scenario = Scenario::kJointCalibration;
    sc.seed = 11;
    sc.device.width = 800, sc.device.height = 600;
    sc.device.supersampling = 2;
    sc.photos_per_placement = 3;
    sim_ = new SimulatedCapture(write_simulated_capture(sc, dir_->path() / "joint", false));
  }
  static void TearDownTestSuite() {
    delete sim_;
    delete dir_;
  }
  static fs::path folder() { return dir_->path() / "joint"; }
  static test::TempDir* dir_;
  static SimulatedCapture* sim_;
};
test::TempDir* JointCapture::dir_ = nullptr;
SimulatedCapture* JointCapture::sim_ = nullptr;

TEST_F(JointCapture, CaptureIsReadableWithPlacementsAndTruth) {
  Diagnostics diag;
  const Capture c = read_capture(folder(), diag);
  EXPECT_EQ(c.kind, "joint-calibration");
  EXPECT_EQ(c.truth_world, "enu-magnetic");
  ASSERT_EQ(c.shots.size(), 18u);
  ASSERT_EQ(c.shot_extra_columns, std::vector<std::string>{"placement"});
  EXPECT_EQ(calibration::shot_placements(c).front(), "hor_0");
  for (const char* f : {"board.yaml", "board_reference.csv", "truth/device.yaml", "truth/scene.yaml", "images/img_0017.jpg"})
    EXPECT_TRUE(fs::exists(folder() / f)) << f;
  // No scratch folder is left behind.
  for (const auto& e : fs::directory_iterator(dir_->path())) EXPECT_EQ(e.path().filename(), "joint");
  EXPECT_EQ(camera::read_board(folder() / "board.yaml").cols, 9);
}

TEST_F(JointCapture, CameraPosesFollowOrientationTruthAndTimeOffset) {
  Diagnostics diag;
  const Capture c = read_capture(folder(), diag);
  const YAML::Node device = YAML::Load(io::read_text(folder() / "truth/device.yaml"));
  const YAML::Node scene = YAML::Load(io::read_text(folder() / "truth/scene.yaml"));
  const Mat3 R_device_camera = mat(device["camera_imu"]["R_device_camera"]);
  const double offset = device["camera_imu"]["time_offset_s"].as<double>();
  EXPECT_GE(offset, 0.010);
  EXPECT_LE(offset, 0.060);
  const double mounting = rad2deg(rotation_distance(R_device_camera, camera::nominal_R_device_camera()));
  EXPECT_GE(mounting, 1.0 - 1e-9);
  EXPECT_LE(mounting, 3.0 + 1e-9);
  EXPECT_NEAR(mounting, device["camera_imu"]["mounting_error_deg"].as<double>(), 1e-9);
  ASSERT_EQ(scene["shots"].size(), c.shots.size());
  for (std::size_t i = 0; i < c.shots.size(); ++i) {
    const YAML::Node s = scene["shots"][i];
    // shots.csv t + time offset = the IMU-clock instant of the photo.
    EXPECT_NEAR(c.shots[i].t + offset, s["t_true"].as<double>(), 1e-12);
    const Mat3 R_world_device = truth_at(*c.truth_orientation, s["t_true"].as<double>());
    EXPECT_LT(rad2deg(rotation_distance(R_world_device * R_device_camera, mat(s["R_world_camera"]))), 0.01) << "shot " << i;
    // The phone moves at every photo: 10–40 °/s (what makes the time offset observable).
    const double rate = s["angular_rate_deg_s"].as<double>();
    EXPECT_GE(rate, 10.0) << "shot " << i;
    EXPECT_LE(rate, 40.0) << "shot " << i;
    // The same from the orientation truth by central differences.
    const double h = 0.004, t = s["t_true"].as<double>();
    const double fd = rad2deg(rotation_distance(truth_at(*c.truth_orientation, t - h), truth_at(*c.truth_orientation, t + h))) / (2 * h);
    EXPECT_NEAR(fd, rate, 0.05 * rate + 0.5) << "shot " << i;
  }
}

TEST_F(JointCapture, BoardReferenceIsWithinInstrumentBoundsOfTruth) {
  const YAML::Node scene = YAML::Load(io::read_text(folder() / "truth/scene.yaml"));
  std::map<std::string, Mat3> R_world_board;
  for (const auto& p : scene["placements"]) R_world_board[p["name"].as<std::string>()] = mat(p["R_world_board"]);
  ASSERT_EQ(R_world_board.size(), 6u);
  const auto ref = calibration::read_board_reference(folder() / "board_reference.csv");
  ASSERT_EQ(ref.placements().size(), 6u);
  std::size_t g = 0, n = 0;
  for (const auto& line : ref.lines) {
    const Vec3 axis = R_world_board.at(line.placement).col(static_cast<int>(line.axis));
    if (line.ref == calibration::AngleReference::kGravity) {
      EXPECT_LE(std::abs(rad2deg(line.angle - std::acos(-axis.z()))), 0.2 + 5e-4) << line.placement;
      ++g;
    } else {
      EXPECT_LE(std::abs(rad2deg(wrap_pi(line.angle - std::atan2(axis.x(), axis.y())))), 1.5 + 5e-4) << line.placement;
      ++n;
    }
  }
  EXPECT_EQ(g, 18u);
  EXPECT_GE(n, 10u);
  // The placements: face-up boards have Z,G = 0; vertical boards Y,G = 0 (rows run down); tilts.
  auto G = [&](const char* name, int axis) { return rad2deg(std::acos(-R_world_board.at(name).col(axis).z())); };
  EXPECT_NEAR(G("hor_0", 2), 0.0, 1e-9);
  EXPECT_NEAR(G("hor_60", 2), 0.0, 1e-9);
  EXPECT_NEAR(G("tilt_20", 2), 20.0, 1e-9);
  EXPECT_NEAR(G("tilt_45", 2), 45.0, 1e-9);
  EXPECT_NEAR(G("vert_n", 1), 0.0, 1e-9);
  EXPECT_NEAR(G("vert_e", 1), 0.0, 1e-9);
}

TEST_F(JointCapture, PhotosShowTheBoardWhereTheTruthProjectsIt) {
  Diagnostics diag;
  const Capture c = read_capture(folder(), diag);
  const YAML::Node device = YAML::Load(io::read_text(folder() / "truth/device.yaml"));
  const YAML::Node scene = YAML::Load(io::read_text(folder() / "truth/scene.yaml"));
  const auto K = intrinsics_of(device);
  const camera::BoardSpec board = camera::read_board(folder() / "board.yaml");
  std::map<std::string, std::pair<Mat3, Vec3>> placements;
  for (const auto& p : scene["placements"])
    placements[p["name"].as<std::string>()] = {mat(p["R_world_board"]), vec(p["p_world_board_m"])};
  double ss = 0;
  std::size_t count = 0, found = 0;
  for (std::size_t i = 0; i < c.shots.size(); ++i) {
    const YAML::Node s = scene["shots"][i];
    const CameraPose pose{mat(s["R_world_camera"]), vec(s["p_world_camera_m"])};
    const auto& [R_wb, p_wb] = placements.at(s["placement"].as<std::string>());
    std::vector<Vec2> truth;
    for (const Vec3& p : board.object_points()) {
      const auto uv = project_world(K, pose, p_wb + R_wb * p);
      ASSERT_TRUE(uv.has_value());
      EXPECT_TRUE(uv->x() > 0 && uv->y() > 0 && uv->x() < K.width - 1 && uv->y() < K.height - 1) << "shot " << i;
      truth.push_back(*uv);
    }
    const cv::Mat grey = cv::imread((folder() / c.shots[i].image).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(grey.cols, K.width);
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(grey, cv::Size(board.cols, board.rows), corners)) continue;
    ++found;
    cv::cornerSubPix(grey, corners, cv::Size(4, 4), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
    // Detector order = board.hpp order = the truth's order (no 180° flips of the board frame).
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const double d = std::hypot(corners[k].x - truth[k].x(), corners[k].y - truth[k].y());
      EXPECT_LT(d, 1.0) << "shot " << i << " corner " << k;
      ss += d * d;
      ++count;
    }
  }
  // Small photos (800 x 600, squares of 10–30 px) with JPEG, noise and motion blur.
  EXPECT_GE(found, c.shots.size() - 2);
  EXPECT_LT(std::sqrt(ss / static_cast<double>(count)), 0.1);  // 0.053 px with seed 11
}

TEST(CaptureSimulator, SameSeedSameCaptureOtherSeedDifferent) {
  test::TempDir dir;
  CaptureScenario sc;
  sc.scenario = Scenario::kJointCalibration;
  sc.seed = 4;
  sc.device.width = 160, sc.device.height = 120;
  sc.device.supersampling = 1;
  sc.photos_per_placement = 2;
  const auto a = simulate_capture(sc, dir / "a");
  const auto b = simulate_capture(sc, dir / "b");
  for (const char* f : {"truth/scene.yaml", "truth/device.yaml", "board_reference.csv"})
    EXPECT_EQ(a.capture.generated_files.at(f), b.capture.generated_files.at(f)) << f;
  ASSERT_EQ(a.capture.shots.size(), 12u);
  for (std::size_t i = 0; i < a.capture.shots.size(); ++i) {
    EXPECT_EQ(a.capture.shots[i].t, b.capture.shots[i].t);
    EXPECT_EQ(io::read_text(a.capture.shots[i].source), io::read_text(b.capture.shots[i].source));
  }
  for (const auto& [name, s] : a.capture.streams) EXPECT_EQ(s.values, b.capture.streams.at(name).values) << name;
  sc.seed = 5;
  const auto c = simulate_capture(sc, dir / "c");
  EXPECT_NE(a.capture.generated_files.at("truth/scene.yaml"), c.capture.generated_files.at("truth/scene.yaml"));
  EXPECT_NE(a.device.time_offset_s, c.device.time_offset_s);
}

TEST(CaptureSimulator, CameraCalibrationViewsFillTheImage) {
  test::TempDir dir;
  CaptureScenario sc;
  sc.scenario = Scenario::kCameraCalibration;
  sc.seed = 2;
  sc.photos = 12;
  sc.device.width = 320, sc.device.height = 240;
  sc.device.supersampling = 1;
  sc.board = default_board(camera::BoardType::kCharuco);
  const auto sim = simulate_capture(sc, dir / "cc");
  EXPECT_EQ(sim.capture.kind, "camera-calibration");
  EXPECT_TRUE(sim.capture.shot_extra_columns.empty());
  EXPECT_EQ(sim.capture.generated_files.count("board_reference.csv"), 0u);
  ASSERT_EQ(sim.shots.size(), 12u);
  ASSERT_EQ(sim.placements.size(), 1u);
  const auto& K = sim.device.intrinsics;
  // Board centres in all four quadrants and near the corners; views from varied angles.
  int quadrant[4] = {0, 0, 0, 0};
  double min_corner_distance = 1e9, max_tilt = 0;
  const Vec3 centre = 0.5 * (sc.board.extent().first + sc.board.extent().second);
  const auto& pl = sim.placements[0];
  for (const auto& s : sim.shots) {
    const CameraPose pose{s.R_world_camera, s.p_world_camera};
    const auto uv = project_world(K, pose, pl.p_world_board + pl.R_world_board * centre);
    ASSERT_TRUE(uv.has_value());
    ++quadrant[(uv->x() > K.width / 2.0 ? 1 : 0) + (uv->y() > K.height / 2.0 ? 2 : 0)];
    for (const auto& [cu, cv] : {std::pair{0.0, 0.0}, {1.0 * K.width, 0.0}, {0.0, 1.0 * K.height}, {1.0 * K.width, 1.0 * K.height}})
      min_corner_distance = std::min(min_corner_distance, std::hypot(uv->x() - cu, uv->y() - cv));
    const Vec3 to_camera = (s.p_world_camera - pl.p_world_board).normalized();
    max_tilt = std::max(max_tilt, rad2deg(std::acos(std::abs(to_camera.dot(pl.R_world_board.col(2))))));
    EXPECT_LT(s.angular_rate_deg_s, 5.0);  // held still (tremor only)
  }
  for (int q : quadrant) EXPECT_GE(q, 2);
  EXPECT_LT(min_corner_distance, 0.3 * K.width);
  EXPECT_GT(max_tilt, 25.0);
}

TEST(CaptureSimulator, PlanesScenarioPhotographsTheRoom) {
  test::TempDir dir;
  CaptureScenario sc;
  sc.scenario = Scenario::kPlanes;
  sc.seed = 6;
  sc.photos = 4;
  sc.device.width = 160, sc.device.height = 120;
  sc.device.supersampling = 1;
  const auto sim = write_simulated_capture(sc, dir / "planes", false);
  Diagnostics diag;
  const Capture c = read_capture(dir / "planes", diag);
  EXPECT_EQ(c.kind, "imu-log");
  EXPECT_FALSE(fs::exists(dir / "planes/board.yaml"));
  ASSERT_EQ(c.shots.size(), 4u);
  const YAML::Node scene = YAML::Load(io::read_text(dir / "planes/truth/scene.yaml"));
  EXPECT_FALSE(scene["board"]);
  ASSERT_EQ(scene["planes"].size(), 5u);
  for (std::size_t i = 0; i < c.shots.size(); ++i) {
    const YAML::Node s = scene["shots"][i];
    // The optical axis meets a plane of the room in front of the camera, inside its rectangle.
    const Mat3 R_wc = mat(s["R_world_camera"]);
    const Vec3 c_w = vec(s["p_world_camera_m"]), axis = R_wc.col(2);
    double nearest = 1e9;
    for (const auto& p : scene["planes"]) {
      const Mat3 R = mat(p["R_world_plane"]);
      const Vec3 o = R.transpose() * (c_w - vec(p["p_world_plane_m"])), e = R.transpose() * axis;
      const double lam = -o.z() / e.z();
      const Vec3 hit = o + lam * e;
      if (lam > 0 && hit.x() >= p["min_xy_m"][0].as<double>() && hit.x() <= p["max_xy_m"][0].as<double>() &&
          hit.y() >= p["min_xy_m"][1].as<double>() && hit.y() <= p["max_xy_m"][1].as<double>())
        nearest = std::min(nearest, lam);
    }
    EXPECT_LT(nearest, 12.0) << "shot " << i;
    // Textured surfaces, not a blank sky.
    const cv::Mat grey = cv::imread((dir / "planes" / c.shots[i].image).string(), cv::IMREAD_GRAYSCALE);
    cv::Scalar mean, sd;
    cv::meanStdDev(grey, mean, sd);
    EXPECT_GT(sd[0], 5.0) << "shot " << i;
    const Mat3 R_world_device = truth_at(*c.truth_orientation, s["t_true"].as<double>());
    EXPECT_LT(rad2deg(rotation_distance(R_world_device * sim.device.R_device_camera, R_wc)), 0.01);
  }
}

TEST(CaptureSimulator, DeviceIsDrawnWithinItsRanges) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto d = make_device({}, seed);
    EXPECT_GE(d.mounting_error_deg, 1.0);
    EXPECT_LE(d.mounting_error_deg, 3.0);
    EXPECT_NEAR(rad2deg(rotation_distance(d.R_device_camera, camera::nominal_R_device_camera())), d.mounting_error_deg, 1e-9);
    EXPECT_GE(d.time_offset_s, 0.010);
    EXPECT_LE(d.time_offset_s, 0.060);
    EXPECT_NEAR(d.intrinsics.fx, 1300.0, 40.0);
    EXPECT_FALSE(d.intrinsics.invalid_reason().has_value());
    // The distortion stays monotonic out to the image corners (the renderer inverts it).
    const double r_max = std::hypot(d.intrinsics.width, d.intrinsics.height) / 2.0 / d.intrinsics.fx;
    const auto& k = d.intrinsics.distortion;
    for (double r = 0; r <= r_max; r += 0.01) EXPECT_GT(1 + 3 * k[0] * r * r + 5 * k[1] * std::pow(r, 4) + 7 * k[4] * std::pow(r, 6), 0.5);
  }
  DeviceOptions o;
  o.time_offset_s = -0.025;
  EXPECT_DOUBLE_EQ(make_device(o, 3).time_offset_s, -0.025);
  o.phone = "fancy";
  EXPECT_THROW(make_device(o, 3), std::invalid_argument);
  o = {};
  o.jpeg_quality = 0;
  EXPECT_THROW(make_device(o, 3), std::invalid_argument);
  EXPECT_EQ(parse_scenario("planes"), Scenario::kPlanes);
  EXPECT_THROW(parse_scenario("forest"), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::sim
