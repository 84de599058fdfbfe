// Board pose by PnP: synthetic projections with known pose and noise (accuracy and covariance
// consistency), and the per-photo poses of OpenCV's chessboard set against reference.yaml.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/camera/board_pose.hpp"
#include "camera/camera_test_support.hpp"
#include "support/test_support.hpp"

namespace antpose::camera {
namespace {

using ::testing::HasSubstr;
using test::shared_path;

CameraIntrinsics phone() {  // a phone-like camera with visible distortion
  return {1280, 960, 1050.0, 1052.0, 641.0, 479.0, {0.12, -0.25, 0.0008, -0.0005, 0.1}};
}

struct Synthetic {
  std::vector<Vec2> uv;
  std::vector<Vec3> P;
};

Synthetic project(const CameraIntrinsics& in, const BoardSpec& board, const Mat3& R, const Vec3& t, double noise_px,
                  std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, noise_px);
  Synthetic s;
  for (const auto& p : board.object_points()) {
    const auto u = in.project(R * p + t);
    if (!u) continue;
    s.uv.push_back(*u + Vec2(n(rng), n(rng)));
    s.P.push_back(p);
  }
  return s;
}

BoardSpec board_9x6() { return {BoardType::kChessboard, 9, 6, 0.025, 0.0, ""}; }

TEST(BoardPose, RecoversAKnownPoseWithoutNoise) {
  std::mt19937_64 rng(1);
  const Mat3 R = exp_so3(Vec3(0.3, -0.4, 0.2));
  const Vec3 t(-0.08, -0.05, 0.45);
  const auto s = project(phone(), board_9x6(), R, t, 0.0, rng);
  const BoardPose p = estimate_board_pose(s.uv, s.P, phone());
  EXPECT_LT(rotation_distance(p.R_camera_board, R), 1e-9);
  EXPECT_LT((p.t_camera_board - t).norm(), 1e-9);
  EXPECT_LT(p.rms_px, 1e-6);
  EXPECT_EQ(p.points, 54u);
}

// Over many noisy trials the normalised squared error eᵀ Σ⁻¹ e of (δ, t) is χ² with 6 degrees
// of freedom: mean 6. The covariance uses the per-photo residual variance, so the mean is a
// little above 6 (a Student-like factor (2N−6)/(2N−8) ≈ 1.02 for 54 points).
TEST(BoardPose, CovarianceIsConsistentWithTheError) {
  std::mt19937_64 rng(7);
  const CameraIntrinsics in = phone();
  const int trials = 300;
  double nees = 0.0;
  double rot_err = 0.0;
  for (int k = 0; k < trials; ++k) {
    std::uniform_real_distribution<double> a(-0.5, 0.5);
    const Mat3 R = exp_so3(Vec3(a(rng), a(rng), a(rng)));
    const Vec3 t(-0.1 + 0.1 * a(rng), -0.06 + 0.1 * a(rng), 0.35 + 0.2 * a(rng));
    const auto s = project(in, board_9x6(), R, t, 0.3, rng);
    const BoardPose p = estimate_board_pose(s.uv, s.P, in);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = log_so3(R * p.R_camera_board.transpose());  // R_true = exp(δ) R_est
    e.tail<3>() = t - p.t_camera_board;
    nees += e.dot(p.covariance.ldlt().solve(e));
    rot_err += e.head<3>().squaredNorm();
  }
  nees /= trials;
  fmt::print("mean NEES {:.3f} (expected ≈ 6), RMS rotation error {:.4f}°\n", nees,
             rad2deg(std::sqrt(rot_err / trials)));
  // χ²₆ mean over 300 trials: σ = sqrt(12/300) = 0.2; allow 3σ around 6.1.
  EXPECT_NEAR(nees, 6.1, 0.6);
}

TEST(BoardPose, RefusesTooFewOrCollinearPoints) {
  const CameraIntrinsics in = phone();
  std::mt19937_64 rng(3);
  const auto s = project(in, board_9x6(), Mat3::Identity(), Vec3(0, 0, 0.5), 0.0, rng);
  const std::vector<Vec2> uv3(s.uv.begin(), s.uv.begin() + 3);
  const std::vector<Vec3> P3(s.P.begin(), s.P.begin() + 3);
  try {
    estimate_board_pose(uv3, P3, in);
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("3 points, need at least 4"));
  }
  // The first row of the board only: collinear.
  const std::vector<Vec2> uv_row(s.uv.begin(), s.uv.begin() + 9);
  const std::vector<Vec3> P_row(s.P.begin(), s.P.begin() + 9);
  try {
    estimate_board_pose(uv_row, P_row, in);
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("collinear"));
  }
}

TEST(BoardPose, ChessboardPosesMatchReference) {
  const auto ref = test_data::reference("opencv-chessboard-9x6", "measured_default");
  const CameraIntrinsics in{640, 480, ref.fx, ref.fy, ref.cx, ref.cy,
                            {ref.distortion[0], ref.distortion[1], ref.distortion[2], ref.distortion[3],
                             ref.distortion[4]}};
  Diagnostics diagnostics;
  const Capture capture = read_capture(shared_path("data/camera/opencv-chessboard-9x6"), diagnostics);
  const BoardSpec board = read_board(capture.root / "board.yaml");
  const auto poses = board_poses(capture, board, in, diagnostics);
  ASSERT_EQ(poses.size(), 13u);
  EXPECT_TRUE(diagnostics.empty());
  double worst_deg = 0.0, worst_mm = 0.0;
  for (const auto& p : poses) {
    ASSERT_TRUE(p.pose) << p.image << ": " << p.reason;
    const std::string name = p.image.substr(p.image.find('/') + 1);
    const auto rv = ref.node["extrinsics"][name]["rvec"].as<std::vector<double>>();
    const auto tv = ref.node["extrinsics"][name]["tvec"].as<std::vector<double>>();
    const Mat3 R_ref = exp_so3(Vec3(rv[0], rv[1], rv[2]));
    const Vec3 t_ref(tv[0], tv[1], tv[2]);
    const double deg = rad2deg(rotation_distance(p.pose->R_camera_board, R_ref));
    const double mm = 1000.0 * (p.pose->t_camera_board - t_ref).norm();
    worst_deg = std::max(worst_deg, deg);
    worst_mm = std::max(worst_mm, mm);
    // The calibration's own extrinsics and a per-photo PnP minimise the same residual.
    EXPECT_LT(deg, 1e-3) << name;
    EXPECT_LT(mm, 1e-2) << name;
    EXPECT_NEAR(p.pose->rms_px, ref.node["per_view_rms_px"][name].as<double>(), 1e-3) << name;
    // 1σ of the rotation from the covariance: a few hundredths of a degree for 54 corners.
    const double sigma_deg = rad2deg(std::sqrt(p.pose->covariance.topLeftCorner<3, 3>().trace()));
    EXPECT_GT(sigma_deg, 0.001);
    EXPECT_LT(sigma_deg, 1.0);
  }
  fmt::print("largest difference to reference.yaml: {:.2e}° and {:.2e} mm\n", worst_deg, worst_mm);
}

TEST(BoardPose, ImageSizeMismatchIsAPerPhotoReason) {
  Diagnostics diagnostics;
  const Capture capture = read_capture(shared_path("data/camera/opencv-chessboard-9x6"), diagnostics);
  CameraIntrinsics portrait{480, 640, 536.0, 536.0, 240.0, 320.0, {}};
  const auto poses = board_poses(capture, read_board(capture.root / "board.yaml"), portrait, diagnostics);
  ASSERT_EQ(poses.size(), 13u);
  EXPECT_FALSE(poses[0].pose);
  EXPECT_THAT(poses[0].reason, HasSubstr("image is 640x480 px but the intrinsics are for 480x640 px (rotated"));
  ASSERT_EQ(diagnostics.warnings().size(), 13u);
  EXPECT_EQ(diagnostics.warnings()[0].file.filename(), "left01.jpg");
  EXPECT_THAT(diagnostics.warnings()[0].message, HasSubstr("photo skipped: image is 640x480 px"));
}

}  // namespace
}  // namespace antpose::camera
