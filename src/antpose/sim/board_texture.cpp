#include "antpose/sim/board_texture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>

namespace antpose::sim {

namespace {

constexpr float kInk = 0.05f;
constexpr float kPaper = 0.85f;

// Discs with an anti-aliased rim: coverage ramps over one texel across the circle (the
// distance-based approximation of the area coverage, exact for a straight edge).
void draw_discs(cv::Mat& img, const std::vector<Vec3>& centres, double radius_m, double ppm, const Eigen::Vector2d& origin) {
  const double r_tex = radius_m * ppm;
  for (const Vec3& c : centres) {
    const double cx = (c.x() - origin.x()) * ppm, cy = (c.y() - origin.y()) * ppm;  // edge coordinates
    const int x0 = std::max(0, static_cast<int>(std::floor(cx - r_tex - 2))), x1 = std::min(img.cols - 1, static_cast<int>(std::ceil(cx + r_tex + 2)));
    const int y0 = std::max(0, static_cast<int>(std::floor(cy - r_tex - 2))), y1 = std::min(img.rows - 1, static_cast<int>(std::ceil(cy + r_tex + 2)));
    for (int y = y0; y <= y1; ++y) {
      float* row = img.ptr<float>(y);
      for (int x = x0; x <= x1; ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        const double cover = std::clamp(r_tex - d + 0.5, 0.0, 1.0);
        row[x] = static_cast<float>(row[x] * (1.0 - cover) + kInk * cover);
      }
    }
  }
}

}  // namespace

BoardTexture board_texture(const camera::BoardSpec& board, const BoardTextureOptions& options) {
  if (board.cols < 2 || board.rows < 2 || !(board.square_m > 0.0))
    throw std::invalid_argument(fmt::format("board_texture: {}x{} board with square {} m is not drawable", board.cols,
                                            board.rows, board.square_m));
  if (options.texels_per_square < 8 || !(options.margin_squares >= 0.0))
    throw std::invalid_argument("board_texture: texels_per_square must be >= 8 and the margin >= 0");
  const double s = board.square_m;
  const double ppm = options.texels_per_square / s;
  const auto [lo, hi] = board.extent();
  const double margin = options.margin_squares * s;
  BoardTexture out;
  out.min_xy = Eigen::Vector2d(lo.x() - margin, lo.y() - margin);
  out.max_xy = Eigen::Vector2d(hi.x() + margin, hi.y() + margin);
  const int W = static_cast<int>(std::lround((out.max_xy.x() - out.min_xy.x()) * ppm));
  const int H = static_cast<int>(std::lround((out.max_xy.y() - out.min_xy.y()) * ppm));
  // Make the rectangle exactly W x H texels (it already is up to rounding of the margin).
  out.max_xy = out.min_xy + Eigen::Vector2d(W / ppm, H / ppm);
  Eigen::Matrix<double, 2, 3> A;
  A << ppm, 0.0, -out.min_xy.x() * ppm, 0.0, ppm, -out.min_xy.y() * ppm;

  cv::Mat img(H, W, CV_32FC1, cv::Scalar(kPaper));
  switch (board.type) {
    case camera::BoardType::kChessboard: {
      // Square (qx, qy) covers [qx s, (qx+1) s] x [qy s, (qy+1) s], qx = −1 … cols − 1; the
      // texel grid is aligned with the square edges, so point sampling at texel centres is exact.
      for (int y = 0; y < H; ++y) {
        float* row = img.ptr<float>(y);
        const double by = out.min_xy.y() + (y + 0.5) / ppm;
        if (by < -s || by > board.rows * s) continue;
        const int qy = static_cast<int>(std::floor(by / s));
        for (int x = 0; x < W; ++x) {
          const double bx = out.min_xy.x() + (x + 0.5) / ppm;
          if (bx < -s || bx > board.cols * s) continue;
          const int qx = static_cast<int>(std::floor(bx / s));
          if (((qx + qy) % 2 + 2) % 2 == 0) row[x] = kInk;
        }
      }
      break;
    }
    case camera::BoardType::kCircles:
    case camera::BoardType::kAsymmetricCircles:
      draw_discs(img, board.object_points(), 0.25 * s, ppm, out.min_xy);
      break;
    case camera::BoardType::kCharuco: {
      const int dict_id = camera::aruco_dictionary_id(board.dictionary);
      if (dict_id < 0) throw std::invalid_argument(fmt::format("board_texture: unknown ArUco dictionary '{}'", board.dictionary));
      if (!(board.marker_m > 0.0 && board.marker_m < s))
        throw std::invalid_argument("board_texture: marker_m must be between 0 and square_m");
      const auto dictionary = cv::aruco::getPredefinedDictionary(dict_id);
      const auto charuco = cv::aruco::CharucoBoard::create(board.cols, board.rows, static_cast<float>(s),
                                                           static_cast<float>(board.marker_m), dictionary);
      const int t = options.texels_per_square;
      const int margin_px = static_cast<int>(std::lround(margin * ppm));
      cv::Mat drawn;
      charuco->draw(cv::Size(board.cols * t + 2 * margin_px, board.rows * t + 2 * margin_px), drawn, margin_px, 1);
      // Which way up did OpenCV draw it? Detect the drawing and compare the corners with the
      // four axis flips of (margin + k x, margin + k y).
      std::vector<std::vector<cv::Point2f>> marker_corners;
      std::vector<int> marker_ids;
      cv::aruco::detectMarkers(drawn, dictionary, marker_corners, marker_ids);
      std::vector<cv::Point2f> corners;
      std::vector<int> ids;
      if (!marker_ids.empty()) cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, drawn, charuco, corners, ids);
      if (ids.size() < 4)
        throw std::runtime_error(fmt::format("board_texture: the drawn ChArUco board ({}) was not re-detected", board.dictionary));
      const auto object = board.object_points();
      double best = std::numeric_limits<double>::infinity();
      int best_flip = 0;
      for (int flip = 0; flip < 4; ++flip) {
        double err = 0.0;
        for (std::size_t i = 0; i < ids.size(); ++i) {
          const Vec3& p = object[static_cast<std::size_t>(ids[i])];
          const double ex = (flip & 1) ? drawn.cols - margin_px - p.x() * ppm : margin_px + p.x() * ppm;
          const double ey = (flip & 2) ? drawn.rows - margin_px - p.y() * ppm : margin_px + p.y() * ppm;
          err += std::hypot(corners[i].x + 0.5 - ex, corners[i].y + 0.5 - ey);
        }
        err /= static_cast<double>(ids.size());
        if (err < best) best = err, best_flip = flip;
      }
      if (best > 2.0)
        throw std::runtime_error(fmt::format("board_texture: the drawn ChArUco corners are {:.1f} texels from every expected layout", best));
      // A drawing with the ids running against the image axes is not mirrored: the board frame
      // is then oriented against the texture axes (a negative texel_from_patch determinant flips
      // which side of the frame the printed face is on).
      drawn.convertTo(img, CV_32F, (kPaper - kInk) / 255.0, kInk);
      const double sx = (best_flip & 1) ? -ppm : ppm, sy = (best_flip & 2) ? -ppm : ppm;
      const double ox = (best_flip & 1) ? drawn.cols - margin_px : margin_px;
      const double oy = (best_flip & 2) ? drawn.rows - margin_px : margin_px;
      A << sx, 0.0, ox, 0.0, sy, oy;
      // The rectangle covered, in the board frame: the drawing's extent mapped back.
      const double xa = -ox / sx, xb = (drawn.cols - ox) / sx, ya = -oy / sy, yb = (drawn.rows - oy) / sy;
      out.min_xy = Eigen::Vector2d(std::min(xa, xb), std::min(ya, yb));
      out.max_xy = Eigen::Vector2d(std::max(xa, xb), std::max(ya, yb));
      out.face_normal_z = (sx * sy > 0.0) ? -1.0 : 1.0;
      break;
    }
  }
  out.texture = std::make_shared<const Texture>(Texture::from_image(img, A, false));
  return out;
}

TexturedPatch board_patch(const BoardTexture& texture, const Mat3& R_world_board, const Vec3& p_world_board, std::string name) {
  TexturedPatch p;
  p.name = std::move(name);
  p.R_world_patch = R_world_board;
  p.p_world_patch = p_world_board;
  p.min_xy = texture.min_xy;
  p.max_xy = texture.max_xy;
  p.texture = texture.texture;
  return p;
}

std::shared_ptr<const Texture> procedural_texture(std::uint64_t seed, double tile_m, int texels, double mean, double contrast) {
  if (texels < 128 || (texels & (texels - 1)) != 0)
    throw std::invalid_argument(fmt::format("procedural_texture: {} texels is not a power of two >= 128", texels));
  if (!(tile_m > 0.0)) throw std::invalid_argument("procedural_texture: the tile size must be positive");
  cv::RNG rng(seed == 0 ? 0x9e3779b97f4a7c15ULL : seed);
  cv::Mat sum = cv::Mat::zeros(texels, texels, CV_32F);
  // Octaves: σ as a fraction of the tile and weight (a 1/f-like spectrum).
  const std::array<std::pair<double, double>, 4> octaves{{{1.0 / 40, 0.55}, {1.0 / 120, 0.3}, {1.0 / 400, 0.15}, {0.0, 0.1}}};
  for (const auto& [frac, weight] : octaves) {
    cv::Mat white(texels, texels, CV_32F);
    rng.fill(white, cv::RNG::NORMAL, 0.0, 1.0);
    const double sigma = std::max(0.7, frac * texels);
    const int pad = static_cast<int>(std::ceil(4 * sigma));
    cv::Mat padded, blurred;
    // Circular convolution (wrapped border) keeps the texture seamless.
    cv::copyMakeBorder(white, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
    cv::GaussianBlur(padded, blurred, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
    cv::Mat octave = blurred(cv::Rect(pad, pad, texels, texels)).clone();
    cv::Scalar m, sd;
    cv::meanStdDev(octave, m, sd);
    sum += (octave - m[0]) * (weight / std::max(sd[0], 1e-12));
  }
  cv::Scalar m, sd;
  cv::meanStdDev(sum, m, sd);
  cv::Mat reflectance = (sum - m[0]) * (contrast / std::max(sd[0], 1e-12)) + mean;
  cv::min(cv::max(reflectance, 0.02), 0.98, reflectance);
  Eigen::Matrix<double, 2, 3> A;
  const double ppm = texels / tile_m;
  A << ppm, 0.0, 0.0, 0.0, ppm, 0.0;
  return std::make_shared<const Texture>(Texture::from_image(reflectance, A, true));
}

std::vector<TexturedPatch> room_patches(std::uint64_t seed, double half_size_m, double height_m) {
  std::vector<TexturedPatch> out;
  TexturedPatch ground;
  ground.name = "ground";
  ground.R_world_patch = Mat3::Identity();
  ground.min_xy = Eigen::Vector2d(-half_size_m, -half_size_m);
  ground.max_xy = Eigen::Vector2d(half_size_m, half_size_m);
  ground.texture = procedural_texture(seed * 7 + 1, 2.0, 1024, 0.30, 0.08);
  out.push_back(ground);
  // Walls: patch x horizontal along the wall, y up, normal into the room.
  const std::array<std::pair<const char*, double>, 4> walls{{{"wall-north", 0.0}, {"wall-east", 90.0}, {"wall-south", 180.0}, {"wall-west", 270.0}}};
  for (std::size_t i = 0; i < walls.size(); ++i) {
    const double az = deg2rad(walls[i].second);
    const Vec3 outward(std::sin(az), std::cos(az), 0.0);
    TexturedPatch w;
    w.name = walls[i].first;
    const Vec3 x(std::cos(az), -std::sin(az), 0.0);
    const Vec3 y = Vec3::UnitZ();
    w.R_world_patch.col(0) = x;
    w.R_world_patch.col(1) = y;
    w.R_world_patch.col(2) = x.cross(y);
    w.p_world_patch = half_size_m * outward;
    w.min_xy = Eigen::Vector2d(-half_size_m, 0.0);
    w.max_xy = Eigen::Vector2d(half_size_m, height_m);
    w.texture = procedural_texture(seed * 7 + 2 + i, 1.5, 512, 0.62, 0.07);
    out.push_back(w);
  }
  return out;
}

}  // namespace antpose::sim
