// Board detection: every board type, and the per-photo reasons (no board, blurred, partly out
// of view, too few ChArUco corners) on images derived from the reference sets.
#include <cmath>
#include <map>
#include <numbers>

#include <Eigen/Dense>

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/board_detection.hpp"
#include "camera/camera_test_support.hpp"
#include "support/test_support.hpp"

namespace antpose::camera {
namespace {

using ::testing::HasSubstr;
using test::shared_path;

cv::Mat load(const std::string& relative, int mode = cv::IMREAD_UNCHANGED) {
  const cv::Mat m = cv::imread(shared_path("data/camera/" + relative).string(), mode);
  if (m.empty()) throw std::runtime_error("cannot read " + relative);
  return m;
}

BoardSpec chessboard() { return read_board(shared_path("data/camera/opencv-chessboard-9x6/board.yaml")); }
BoardSpec charuco() { return read_board(shared_path("data/camera/charuco/board.yaml")); }

// Moves the image content by (dx, dy) px inside the same frame (what a photo with the board
// nearer the edge looks like); the uncovered strip is filled with the border's grey.
cv::Mat shifted(const cv::Mat& image, double dx, double dy) {
  cv::Mat out;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(image, out, M, image.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  return out;
}

TEST(BoardDetection, ChessboardCornersMatchStoredCorners) {
  const auto views = test_data::read_corner_views(
      shared_path("data/camera/opencv-chessboard-9x6/corners.csv"));
  for (const auto& v : views) {
    const auto d = detect_board(load("opencv-chessboard-9x6/images/" + v.name), chessboard());
    ASSERT_TRUE(d.found) << v.name << ": " << d.reason;
    EXPECT_TRUE(d.reason.empty()) << d.reason;
    ASSERT_EQ(d.image_points.size(), 54u);
    fmt::print("{}: Laplacian variance {:.1f}\n", v.name, d.laplacian_variance);
    for (std::size_t i = 0; i < 54; ++i) {
      EXPECT_NEAR((d.image_points[i] - v.image_points[i]).norm(), 0.0, 1e-3) << v.name << " corner " << i;
      EXPECT_LT((d.object_points[i] - v.object_points[i]).norm(), 1e-12);
    }
  }
}

TEST(BoardDetection, CharucoCornersMatchStoredCorners) {
  const auto views = test_data::read_corner_views(shared_path("data/camera/charuco/corners.csv"));
  const auto ref = test_data::reference("charuco", "measured");
  DetectionOptions o;
  o.intrinsics = CameraIntrinsics{640, 480, ref.fx, ref.fy, ref.cx, ref.cy,
                                  {ref.distortion[0], ref.distortion[1], ref.distortion[2], ref.distortion[3],
                                   ref.distortion[4]}};
  for (const auto& v : views) {
    const cv::Mat image = load("charuco/images/" + v.name);
    ASSERT_EQ(image.channels(), 3);
    const auto d = detect_board(image, charuco(), o);
    ASSERT_TRUE(d.found) << v.name << ": " << d.reason;
    fmt::print("{}: {} markers, {} corners (stored {}), Laplacian variance {:.1f}, reason '{}'\n", v.name, d.markers,
               d.ids.size(), v.image_points.size(), d.laplacian_variance, d.reason);
    EXPECT_GE(d.ids.size(), 22u);
    std::map<std::pair<long, long>, Vec2> stored;  // by board position in µm
    auto key = [](const Vec3& p) { return std::pair{std::lround(p.x() * 1e6), std::lround(p.y() * 1e6)}; };
    for (std::size_t i = 0; i < v.image_points.size(); ++i)
      stored[key(v.object_points[i])] = v.image_points[i];
    double worst = 0.0;
    std::size_t matched = 0;
    for (std::size_t i = 0; i < d.ids.size(); ++i) {
      const auto it = stored.find(key(d.object_points[i]));
      if (it == stored.end()) continue;
      ++matched;
      worst = std::max(worst, (it->second - d.image_points[i]).norm());
    }
    fmt::print("    {} corners in common with corners.csv, largest difference {:.4f} px\n", matched, worst);
    EXPECT_EQ(matched, v.image_points.size());
    EXPECT_LT(worst, 0.05);
  }
}

TEST(BoardDetection, ReasonsForRefusedPhotos) {
  const BoardSpec board = chessboard();
  const cv::Mat sharp = load("opencv-chessboard-9x6/images/left01.jpg", cv::IMREAD_GRAYSCALE);
  // Another board (the ChArUco photo has 4x6 inner chessboard corners, not 9x6).
  auto d = detect_board(load("charuco/images/img_00.jpg"), board);
  EXPECT_FALSE(d.found);
  EXPECT_THAT(d.reason, HasSubstr("no board found"));
  // A blank page: no board, and nothing sharp.
  d = detect_board(cv::Mat(480, 640, CV_8UC1, cv::Scalar(200)), board);
  EXPECT_FALSE(d.found);
  EXPECT_EQ(d.reason, "no board found (no 9x6 chessboard) in a blurred or blank photo (variance of Laplacian 0.0 "
                      "below 30.0)");
  // Blurred: the board is still found, but refused.
  cv::Mat blurred;
  cv::GaussianBlur(sharp, blurred, cv::Size(), 2.0);
  d = detect_board(blurred, board);
  EXPECT_FALSE(d.found);
  EXPECT_THAT(d.reason, ::testing::MatchesRegex("blurred \\(variance of Laplacian 1[0-9]\\.[0-9] below 30\\.0\\)"));
  DetectionOptions lenient;
  lenient.min_laplacian_variance = 0.0;
  EXPECT_TRUE(detect_board(blurred, board, lenient).found);
  // Partly out of view: the board's left columns pushed out of the frame.
  d = detect_board(shifted(sharp, -300, 0), board);
  EXPECT_FALSE(d.found);
  EXPECT_THAT(d.reason, ::testing::MatchesRegex("board partly out of view \\([0-9]+ of 54 points visible, points at the "
                                                "image border\\)"));
  fmt::print("{}\n", d.reason);
}

// A 12-MP-like photo of the same scene has a much lower per-pixel Laplacian variance; the
// measure is taken at 640 px so that the blur threshold means the same for every camera.
TEST(BoardDetection, SharpnessDoesNotDependOnResolution) {
  const cv::Mat sharp = load("opencv-chessboard-9x6/images/left01.jpg", cv::IMREAD_GRAYSCALE);
  cv::Mat large;
  cv::resize(sharp, large, cv::Size(), 5.0, 5.0, cv::INTER_CUBIC);  // 3200x2400
  cv::Mat lap;
  cv::Laplacian(large, lap, CV_64F);
  cv::Scalar mean, sd;
  cv::meanStdDev(lap, mean, sd);
  const double native = laplacian_variance(sharp), at_640 = laplacian_variance(large);
  fmt::print("Laplacian variance: 640x480 {:.1f}, 3200x2400 at full resolution {:.1f}, measured at 640 px {:.1f}\n",
             native, sd[0] * sd[0], at_640);
  EXPECT_LT(sd[0] * sd[0], 30.0);  // a fixed full-resolution threshold would call it blurred
  EXPECT_GT(at_640, 0.5 * native);  // area averaging softens a little; hundreds, not units
}

TEST(BoardDetection, CharucoPartlyOutOfViewIsUsableWithANote) {
  const cv::Mat image = load("charuco/images/img_00.jpg");
  const auto full = detect_board(image, charuco());
  ASSERT_TRUE(full.found);
  // Push the board's right part out of the frame.
  double max_u = 0.0;
  for (const auto& p : full.image_points) max_u = std::max(max_u, p.x());
  const auto d = detect_board(shifted(image, 640 - max_u + 60, 0), charuco());
  fmt::print("charuco shifted: found {} with {} corners, reason '{}'\n", d.found, d.ids.size(), d.reason);
  ASSERT_TRUE(d.found);
  EXPECT_LT(d.ids.size(), full.ids.size());
  EXPECT_THAT(d.reason, HasSubstr("board partly out of view"));
  // Almost all of it out: too few corners.
  const auto gone = detect_board(shifted(image, 640 - max_u + 230, 0), charuco());
  EXPECT_FALSE(gone.found);
  EXPECT_THAT(gone.reason, ::testing::AnyOf(HasSubstr("too few ChArUco corners"), HasSubstr("no board found")));
  fmt::print("charuco mostly out: {}\n", gone.reason);
}

TEST(BoardDetection, CircleGridsSymmetricAndAsymmetric) {
  // Rendered grids of black discs on white, under a mild perspective.
  for (const BoardType type : {BoardType::kCircles, BoardType::kAsymmetricCircles}) {
    const BoardSpec board{type, 4, 11 - (type == BoardType::kCircles ? 4 : 0), 0.02, 0.0, ""};
    cv::Mat flat(700, 700, CV_8UC1, cv::Scalar(255));
    const auto pts = board.object_points();
    for (const auto& p : pts) cv::circle(flat, cv::Point(int(100 + p.x() * 3000), int(50 + p.y() * 3000)), 15, 0, -1,
                                         cv::LINE_AA);
    const std::vector<cv::Point2f> from{{0, 0}, {700, 0}, {700, 700}, {0, 700}}, to{{40, 30}, {600, 10}, {620, 470},
                                                                                    {20, 450}};
    cv::Mat image;
    cv::warpPerspective(flat, image, cv::getPerspectiveTransform(from, to), cv::Size(640, 480), cv::INTER_LINEAR,
                        cv::BORDER_CONSTANT, cv::Scalar(255));
    const auto d = detect_board(image, board);
    ASSERT_TRUE(d.found) << to_string(type) << ": " << d.reason;
    EXPECT_EQ(d.image_points.size(), pts.size());
    EXPECT_EQ(d.object_points, pts);
    // Neighbouring detections are one grid step apart in the image, in detector order.
    EXPECT_GT((d.image_points[1] - d.image_points[0]).norm(), 20.0);
    // A blank image: no board.
    const auto none = detect_board(cv::Mat(480, 640, CV_8UC1, cv::Scalar(255)), board);
    EXPECT_FALSE(none.found);
    EXPECT_THAT(none.reason, HasSubstr("no board found"));
  }
}

// A chessboard 8 m from a 12 MP camera, turned 40° away: 25 px squares, 12 px in the reduced
// search image. OpenCV's usual 11 px sub-pixel window reaches the neighbouring corners there and
// moved corners by a whole square (9–14 px); each corner must stay on its own.
TEST(BoardDetection, ChessboardSeenSmallInALargePhotoKeepsItsCorners) {
  const BoardSpec board{BoardType::kChessboard, 9, 6, 0.07, 0.0, ""};
  const double f = 3000.0, turn = 40.0 * std::numbers::pi / 180.0;
  // Board plane (x, y in metres, origin at the first inner corner) to pixels: H = K [r1 r2 t].
  const Eigen::Matrix3d K{{f, 0, 2000}, {0, f, 1500}, {0, 0, 1}};
  const Eigen::Vector3d r1(std::cos(turn), 0, std::sin(turn)), r2(0, 1, 0), t(-0.3, -0.2, 8.0);
  Eigen::Matrix3d H;
  H << r1, r2, t;
  H = K * H;
  const Eigen::Matrix3d H_inv = H.inverse();
  const auto to_image = [&](double x, double y) {
    const Eigen::Vector3d p = H * Eigen::Vector3d(x, y, 1);
    return Eigen::Vector2d(p.x() / p.z(), p.y() / p.z());
  };
  // Each pixel is the mean of 4 × 4 samples: grey ground, a white sheet one square beyond the
  // pattern, black and white squares.
  cv::Mat image(3000, 4000, CV_8UC1, cv::Scalar(110));
  const double s = board.square_m;
  const Eigen::Vector2d lo = to_image(-2 * s, -2 * s), hi = to_image(9 * s, 6 * s);
  for (int v = static_cast<int>(std::min(lo.y(), hi.y())) - 30; v < static_cast<int>(std::max(lo.y(), hi.y())) + 30;
       ++v)
    for (int u = static_cast<int>(std::min(lo.x(), hi.x())) - 30; u < static_cast<int>(std::max(lo.x(), hi.x())) + 30;
         ++u) {
      double sum = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
          const Eigen::Vector3d q = H_inv * Eigen::Vector3d(u - 0.375 + 0.25 * j, v - 0.375 + 0.25 * i, 1);
          const double x = q.x() / q.z() / s + 1, y = q.y() / q.z() / s + 1;  // in squares from the pattern's corner
          const bool sheet = x > -1 && x < 11 && y > -1 && y < 8;
          const bool pattern = x > 0 && x < 10 && y > 0 && y < 7;
          const bool black = pattern && (static_cast<int>(x) + static_cast<int>(y)) % 2 == 0;
          sum += !sheet ? 110 : black ? 25 : 235;
        }
      image.at<std::uint8_t>(v, u) = cv::saturate_cast<std::uint8_t>(sum / 16);
    }
  cv::GaussianBlur(image, image, cv::Size(), 0.7);  // a phone's optics
  const auto d = detect_board(image, board);
  ASSERT_TRUE(d.found) << d.reason;
  ASSERT_EQ(d.image_points.size(), 54u);
  double worst = 0, sum = 0;
  for (std::size_t i = 0; i < 54; ++i) {
    const double e = (d.image_points[i] - to_image(d.object_points[i].x(), d.object_points[i].y())).norm();
    worst = std::max(worst, e);
    sum += e;
  }
  fmt::print("corner error: mean {:.3f} px, largest {:.3f} px\n", sum / 54, worst);
  EXPECT_LT(sum / 54, 0.1);
  EXPECT_LT(worst, 0.3);
}

}  // namespace
}  // namespace antpose::camera
