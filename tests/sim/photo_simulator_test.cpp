// Photo simulator: rendered boards give the projected truth to sub-pixel accuracy through
// OpenCV's own detectors, with lens distortion on; textures, noise and blur behave.
#include <chrono>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {
namespace {

camera::CameraIntrinsics small_camera() {
  camera::CameraIntrinsics K;
  K.width = 800, K.height = 600;
  K.fx = 660, K.fy = 662, K.cx = 402.3, K.cy = 297.6;
  K.distortion = {0.11, -0.26, 4e-4, -3e-4, 0.13};
  return K;
}

// Camera looking at the board centre from `distance` along a direction tilted `tilt` from the
// board's face normal, rolled by `roll` about the optical axis. Board frame = world frame here.
CameraPose view_of(const camera::BoardSpec& board, double face_normal_z, double distance, double tilt, double azimuth,
                   double roll) {
  const auto [lo, hi] = board.extent();
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 n = face_normal_z * Vec3::UnitZ();  // the printed face looks this way
  const Vec3 dir = (std::cos(tilt) * n + std::sin(tilt) * (std::cos(azimuth) * Vec3::UnitX() + std::sin(azimuth) * Vec3::UnitY())).normalized();
  CameraPose pose;
  pose.p_world_camera = centre + distance * dir;
  const Vec3 z = -dir;
  // Image "down" along the board's +y where possible (an upright view of the board).
  Vec3 y = Vec3::UnitY() - Vec3::UnitY().dot(z) * z;
  y.normalize();
  const Vec3 x = y.cross(z);
  Mat3 R;
  R << x, y, z;
  pose.R_world_camera = R * rot_z(roll);
  return pose;
}

struct CornerErrors {
  double rms = 0, max = 0;
  std::size_t n = 0;
};

CornerErrors compare(const std::vector<cv::Point2f>& found, const std::vector<Vec3>& object, const camera::CameraIntrinsics& K,
                     const CameraPose& pose, const std::vector<int>& ids = {}) {
  CornerErrors e;
  double ss = 0;
  for (std::size_t i = 0; i < found.size(); ++i) {
    const std::size_t k = ids.empty() ? i : static_cast<std::size_t>(ids[i]);
    const auto uv = project_world(K, pose, object[k]);
    EXPECT_TRUE(uv.has_value());
    const double d = std::hypot(found[i].x - uv->x(), found[i].y - uv->y());
    ss += d * d;
    e.max = std::max(e.max, d);
  }
  e.n = found.size();
  e.rms = std::sqrt(ss / static_cast<double>(std::max<std::size_t>(e.n, 1)));
  return e;
}

SensorModel clean_sensor() {
  SensorModel s;
  s.noise_scale = 0.0;
  s.blur_sigma_px = 0.5;
  return s;
}

TEST(PhotoSimulator, ChessboardCornersMatchProjectedTruthWithDistortion) {
  const camera::BoardSpec board{camera::BoardType::kChessboard, 9, 6, 0.03, 0.0, ""};
  const BoardTexture tex = board_texture(board);
  EXPECT_EQ(tex.face_normal_z, -1.0);
  const auto K = small_camera();
  const PhotoRenderer renderer(K, 3);
  // The board in front of a textured wall 0.3 m behind it (the printed face looks along −z).
  TexturedPatch wall;
  wall.name = "wall";
  wall.p_world_patch = Vec3(0.0, 0.0, 0.3);
  wall.min_xy = Eigen::Vector2d(-3.0, -3.0);
  wall.max_xy = Eigen::Vector2d(3.0, 3.0);
  wall.texture = procedural_texture(4, 1.0, 512, 0.5, 0.1);
  std::vector<TexturedPatch> patches{wall, board_patch(tex, Mat3::Identity(), Vec3::Zero())};
  double worst_rms = 0;
  int views = 0;
  for (const auto& [dist, tilt, az, roll] : std::vector<std::array<double, 4>>{
           {0.45, 0.0, 0.0, 0.0}, {0.5, 0.6, 0.3, 0.2}, {0.6, 0.8, 2.0, -0.4}, {0.4, 0.4, 4.0, 0.1}}) {
    const CameraPose pose = view_of(board, tex.face_normal_z, dist, tilt, az, roll);
    const cv::Mat grey = sensor_image(renderer.render(patches, pose, Lighting{}), clean_sensor(), 1);
    std::vector<cv::Point2f> corners;
    ASSERT_TRUE(cv::findChessboardCorners(grey, cv::Size(board.cols, board.rows), corners,
                                          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
        << "view " << views;
    cv::cornerSubPix(grey, corners, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
    const auto e = compare(corners, board.object_points(), K, pose);
    // Sub-pixel agreement in detector order: the rendered board frame is board.hpp's.
    EXPECT_LT(e.rms, 0.1) << "view " << views;
    EXPECT_LT(e.max, 0.3) << "view " << views;
    worst_rms = std::max(worst_rms, e.rms);
    ++views;
  }
  RecordProperty("worst_rms_px", std::to_string(worst_rms));
}

TEST(PhotoSimulator, JpegAndNoiseKeepChessboardCornersSubPixel) {
  const camera::BoardSpec board{camera::BoardType::kChessboard, 9, 6, 0.03, 0.0, ""};
  const BoardTexture tex = board_texture(board);
  const auto K = small_camera();
  const PhotoRenderer renderer(K, 2);
  std::vector<TexturedPatch> patches{board_patch(tex, Mat3::Identity(), Vec3::Zero())};
  const CameraPose pose = view_of(board, tex.face_normal_z, 0.5, 0.5, 1.0, 0.15);
  SensorModel s;  // default noise, blur 0.6 px
  const cv::Mat grey = sensor_image(motion_blur(renderer.render(patches, pose, Lighting{}), K, Vec3(0.3, -0.2, 0.1), 0.002), s, 7);
  const std::string jpeg = encode_jpeg(grey, 90);
  const cv::Mat decoded = cv::imdecode(std::vector<uchar>(jpeg.begin(), jpeg.end()), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(decoded.size(), grey.size());
  std::vector<cv::Point2f> corners;
  ASSERT_TRUE(cv::findChessboardCorners(decoded, cv::Size(board.cols, board.rows), corners));
  cv::cornerSubPix(decoded, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  EXPECT_LT(compare(corners, board.object_points(), K, pose).rms, 0.15);
}

TEST(PhotoSimulator, CircleGridCentresMatchProjectedTruth) {
  for (const auto type : {camera::BoardType::kCircles, camera::BoardType::kAsymmetricCircles}) {
    const camera::BoardSpec board{type, type == camera::BoardType::kCircles ? 7 : 4, type == camera::BoardType::kCircles ? 5 : 11,
                                  0.03, 0.0, ""};
    const BoardTexture tex = board_texture(board);
    const auto K = small_camera();
    const PhotoRenderer renderer(K, 3);
    std::vector<TexturedPatch> patches{board_patch(tex, Mat3::Identity(), Vec3::Zero())};
    const CameraPose pose = view_of(board, tex.face_normal_z, 0.55, 0.35, 0.7, 0.1);
    const cv::Mat grey = sensor_image(renderer.render(patches, pose, Lighting{}), clean_sensor(), 1);
    std::vector<cv::Point2f> centres;
    ASSERT_TRUE(cv::findCirclesGrid(grey, cv::Size(board.cols, board.rows), centres,
                                    type == camera::BoardType::kCircles ? cv::CALIB_CB_SYMMETRIC_GRID : cv::CALIB_CB_ASYMMETRIC_GRID))
        << camera::to_string(type);
    // Blob centres are ellipse centres, not the projected disc centres: a perspective bias of
    // about (r²/Z) · tilt ≈ 0.1 px here.
    const auto e = compare(centres, board.object_points(), K, pose);
    EXPECT_LT(e.rms, 0.3) << camera::to_string(type);
  }
}

TEST(PhotoSimulator, CharucoCornersMatchProjectedTruthById) {
  const camera::BoardSpec board{camera::BoardType::kCharuco, 7, 5, 0.04, 0.03, "DICT_5X5_100"};
  const BoardTexture tex = board_texture(board);
  const auto K = small_camera();
  const PhotoRenderer renderer(K, 3);
  std::vector<TexturedPatch> patches{board_patch(tex, Mat3::Identity(), Vec3::Zero())};
  const CameraPose pose = view_of(board, tex.face_normal_z, 0.55, 0.4, 2.5, -0.2);
  const cv::Mat grey = sensor_image(renderer.render(patches, pose, Lighting{}), clean_sensor(), 1);
  const auto dictionary = cv::aruco::getPredefinedDictionary(camera::aruco_dictionary_id(board.dictionary));
  const auto charuco = cv::aruco::CharucoBoard::create(board.cols, board.rows, 0.04f, 0.03f, dictionary);
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> marker_ids, ids;
  std::vector<cv::Point2f> corners;
  cv::aruco::detectMarkers(grey, dictionary, markers, marker_ids);
  ASSERT_GE(marker_ids.size(), 15u);
  cv::aruco::interpolateCornersCharuco(markers, marker_ids, grey, charuco, corners, ids);
  ASSERT_EQ(ids.size(), static_cast<std::size_t>(board.point_count()));
  const auto e = compare(corners, board.object_points(), K, pose, ids);
  // OpenCV 4.6's interpolateCornersCharuco returns corners ≈ (+0.5, +0.5) px off (it does so on
  // the flat drawing too, whose corners are exact), so its raw output is only checked loosely;
  // a cornerSubPix pass on the corners gives the sub-pixel truth.
  EXPECT_LT(e.rms, 1.0);
  std::vector<cv::Point2f> refined = corners;
  cv::cornerSubPix(grey, refined, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  EXPECT_LT(compare(refined, board.object_points(), K, pose, ids).rms, 0.1);
}

TEST(PhotoSimulator, ProceduralTextureTilesSeamlesslyAndIsDeterministic) {
  const auto a = procedural_texture(5, 2.0, 256, 0.4, 0.1);
  const auto b = procedural_texture(5, 2.0, 256, 0.4, 0.1);
  ASSERT_FALSE(a->levels.empty());
  EXPECT_EQ(cv::norm(a->levels[0], b->levels[0], cv::NORM_INF), 0.0);
  const cv::Mat& t = a->levels[0];
  // Across the seam the step is like any neighbouring step inside the tile.
  const double seam = cv::norm(t.col(0), t.col(t.cols - 1), cv::NORM_L2) / std::sqrt(t.rows);
  const double inside = cv::norm(t.col(100), t.col(101), cv::NORM_L2) / std::sqrt(t.rows);
  EXPECT_LT(seam, 3.0 * inside + 1e-3);
  cv::Scalar m, sd;
  cv::meanStdDev(t, m, sd);
  EXPECT_NEAR(m[0], 0.4, 0.02);
  EXPECT_NEAR(sd[0], 0.1, 0.02);
  // Each level is the 2 x 2 box average of the one below.
  cv::Mat half;
  cv::resize(a->levels[0], half, a->levels[1].size(), 0, 0, cv::INTER_AREA);
  EXPECT_LT(cv::norm(half, a->levels[1], cv::NORM_INF), 1e-6);
}

TEST(PhotoSimulator, SensorNoiseMatchesPhotonAndReadNoise) {
  // A flat field of radiance 0.5: 0.5 · 0.85 · 6000 = 2550 e⁻, σ = sqrt(2550 + 9) ≈ 50.6 e⁻,
  // i.e. σ_linear = 0.00843; gamma 2.2 maps it to σ_DN = 255 · σ_lin · (1/2.2) · lin^(1/2.2 − 1).
  const cv::Mat flat(400, 400, CV_32F, cv::Scalar(0.5));
  SensorModel s;
  s.blur_sigma_px = 0.0;
  const cv::Mat img = sensor_image(flat, s, 3);
  cv::Scalar m, sd;
  cv::meanStdDev(img, m, sd);
  const double lin = 0.5 * 0.85;
  const double sigma_lin = std::sqrt(lin * 6000 + 9.0) / 6000.0;
  const double expected = 255.0 * sigma_lin / 2.2 * std::pow(lin, 1.0 / 2.2 - 1.0);
  EXPECT_NEAR(m[0], 255.0 * std::pow(lin, 1.0 / 2.2), 0.5);
  EXPECT_NEAR(sd[0], std::sqrt(expected * expected + 1.0 / 12.0), 0.1 * expected);  // + quantisation
  // Deterministic for a seed, different for another.
  EXPECT_EQ(cv::norm(img, sensor_image(flat, s, 3), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(img, sensor_image(flat, s, 4), cv::NORM_INF), 0.0);
  s.noise_scale = 0.0;
  cv::meanStdDev(sensor_image(flat, s, 3), m, sd);
  EXPECT_EQ(sd[0], 0.0);
}

TEST(PhotoSimulator, MotionBlurSmearsAlongTheImageFlow) {
  const auto K = small_camera();
  cv::Mat dot = cv::Mat::zeros(101, 101, CV_32F);
  dot.at<float>(50, 50) = 1.0f;
  // ω_y = −1 rad/s for 5 ms: flow +fx · 0.005 = 3.3 px to the right, centred on the dot.
  const cv::Mat blurred = motion_blur(dot, K, Vec3(0.0, -1.0, 0.0), 0.005);
  const cv::Mat row = blurred.row(50);
  cv::Moments mo = cv::moments(blurred);
  EXPECT_NEAR(mo.m10 / mo.m00, 50.0, 1e-3);
  EXPECT_NEAR(mo.m01 / mo.m00, 50.0, 1e-3);
  EXPECT_NEAR(cv::sum(row)[0], 1.0, 1e-5);               // all along the row
  EXPECT_GT(row.at<float>(0, 51), 0.1f);
  EXPECT_GT(row.at<float>(0, 49), 0.1f);
  EXPECT_EQ(cv::norm(motion_blur(dot, K, Vec3::Zero(), 0.005), dot, cv::NORM_INF), 0.0);
}

TEST(PhotoSimulator, RejectsBadInputs) {
  auto K = small_camera();
  EXPECT_THROW(PhotoRenderer(K, 0), std::invalid_argument);
  K.fx = -1;
  EXPECT_THROW(PhotoRenderer(K, 2), std::invalid_argument);
  EXPECT_THROW(procedural_texture(1, 1.0, 300, 0.5, 0.1), std::invalid_argument);
  EXPECT_THROW(encode_jpeg(cv::Mat::zeros(4, 4, CV_8U), 0), std::invalid_argument);
  const camera::BoardSpec bad{camera::BoardType::kCharuco, 5, 5, 0.04, 0.03, "DICT_NOPE"};
  EXPECT_THROW(board_texture(bad), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::sim
