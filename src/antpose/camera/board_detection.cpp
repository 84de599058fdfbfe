#include "antpose/camera/board_detection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/core/error.hpp"

namespace antpose::camera {
namespace {

cv::Mat to_grey(const cv::Mat& image) {
  if (image.empty()) throw Error("detect_board: empty image");
  if (image.depth() != CV_8U) throw Error("detect_board: expected an 8-bit image");
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

bool at_border(const cv::Point2f& p, const cv::Size& size, double margin) {
  return p.x < margin || p.y < margin || p.x > size.width - 1 - margin || p.y > size.height - 1 - margin;
}

int count_at_border(const std::vector<cv::Point2f>& points, const cv::Size& size, double margin) {
  return static_cast<int>(
      std::count_if(points.begin(), points.end(), [&](const cv::Point2f& p) { return at_border(p, size, margin); }));
}

// cornerSubPix's half-window for a chessboard whose corners are `corners` (row-major, `pattern`
// inner corners): at most `largest`, and under 0.6 of the shortest step between neighbouring
// corners. A window reaching the neighbouring corners takes in their gradients and can settle a
// whole square away: a board 8 m from a 12 MP camera has 12 px squares in the reduced search image,
// where an 11 px half-window moved its corners by 9–14 px (0.05 px from the sector-based
// detector's with 7 px).
int subpix_half_window(const std::vector<cv::Point2f>& corners, cv::Size pattern, int largest) {
  double step = std::numeric_limits<double>::infinity();
  for (int r = 0; r < pattern.height; ++r)
    for (int c = 0; c < pattern.width; ++c) {
      const cv::Point2f& p = corners[static_cast<std::size_t>(r * pattern.width + c)];
      if (c + 1 < pattern.width)
        step = std::min(step, cv::norm(corners[static_cast<std::size_t>(r * pattern.width + c + 1)] - p));
      if (r + 1 < pattern.height)
        step = std::min(step, cv::norm(corners[static_cast<std::size_t>((r + 1) * pattern.width + c)] - p));
    }
  return std::min(largest, std::max(2, static_cast<int>(0.6 * step)));
}

void fill_points(BoardDetection& d, const BoardSpec& board, const std::vector<cv::Point2f>& points,
                 const std::vector<int>& ids) {
  const std::vector<Vec3> all = board.object_points();
  d.image_points.clear();
  d.object_points.clear();
  d.ids = ids;
  for (std::size_t i = 0; i < points.size(); ++i) {
    d.image_points.emplace_back(points[i].x, points[i].y);
    d.object_points.push_back(all.at(static_cast<std::size_t>(ids[i])));
  }
}

std::vector<int> iota_ids(std::size_t n) {
  std::vector<int> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<int>(i);
  return ids;
}

// The full pattern was not found: is a part of it visible and cut by the image border? The
// sector-based detector (findChessboardCornersSB with CALIB_CB_LARGER) returns any chessboard
// of at least 3×3 inner corners with its size, so a cropped board shows up as a smaller grid.
std::string chessboard_miss_reason(const cv::Mat& grey, const BoardSpec& board, const DetectionOptions& o) {
  std::vector<cv::Point2f> part;
  cv::Mat meta;
  bool found_part = false;
  try {
    found_part = cv::findChessboardCornersSB(grey, cv::Size(3, 3), part, cv::CALIB_CB_LARGER, meta);
  } catch (const cv::Exception&) {
    found_part = false;
  }
  const int m = board.point_count();
  if (!found_part || part.empty()) return fmt::format("no board found (no {}x{} chessboard)", board.cols, board.rows);
  const int n = static_cast<int>(part.size());
  const bool full =
      (meta.cols == board.cols && meta.rows == board.rows) || (meta.cols == board.rows && meta.rows == board.cols);
  if (full)
    return fmt::format(
        "no board found by findChessboardCorners (the sector-based detector sees a {}x{} board; "
        "try other detector flags)",
        board.cols, board.rows);
  // A fragment cut by the border: corners next to it, or the fragment's outer row/column within
  // one square spacing of it (the next row would lie outside the image).
  const int n_border = count_at_border(part, grey.size(), o.border_margin_px);
  const cv::Rect2f box = cv::boundingRect(part);
  const double spacing = std::sqrt(static_cast<double>(box.area()) / n);
  const bool near_edge = box.x < spacing || box.y < spacing || box.br().x > grey.cols - 1 - spacing ||
                         box.br().y > grey.rows - 1 - spacing;
  if (n < m && (n_border > 0 || near_edge))
    return fmt::format("board partly out of view ({} of {} points visible, points at the image border)", n, m);
  return fmt::format("no board found (a {}x{} chessboard is visible, expected {}x{} inner corners)", meta.cols,
                     meta.rows, board.cols, board.rows);
}

void detect_chessboard(const cv::Mat& grey, const BoardSpec& board, const DetectionOptions& o, BoardDetection& d) {
  int flags = 0;
  if (o.adaptive_threshold) flags |= cv::CALIB_CB_ADAPTIVE_THRESH;
  if (o.normalize_image) flags |= cv::CALIB_CB_NORMALIZE_IMAGE;
  if (o.fast_check) flags |= cv::CALIB_CB_FAST_CHECK;
  if (o.filter_quads) flags |= cv::CALIB_CB_FILTER_QUADS;
  std::vector<cv::Point2f> corners;
  const int side = std::max(grey.cols, grey.rows);
  const double f = o.chessboard_search_max_side_px > 0 && side > o.chessboard_search_max_side_px
                       ? static_cast<double>(o.chessboard_search_max_side_px) / side
                       : 1.0;
  cv::Mat search = grey;
  if (f < 1.0) cv::resize(grey, search, cv::Size(), f, f, cv::INTER_AREA);
  // findChessboardCorners' quad search takes seconds on a textured scene (gravel, a roof): the
  // sector-based detector (Duda & Frese, BMVC 2018) finds the board in a fraction of that, and the
  // classic detector then runs on the board's neighbourhood only, keeping its corner order and
  // refinement. Where the sector-based one sees nothing, the classic one searches everything, as
  // it does in photos up to 1024 px (quick there; OpenCV's published samples are that size and
  // its initial corners, hence the refined ones to 1e-4 px, depend on the search area).
  const cv::Size pattern(board.cols, board.rows);
  cv::Rect crop(0, 0, search.cols, search.rows);
  if (std::vector<cv::Point2f> seen;
      std::max(search.cols, search.rows) > 1024 && cv::findChessboardCornersSB(search, pattern, seen, 0)) {
    const cv::Rect box = cv::boundingRect(seen);
    const int margin =
        static_cast<int>(std::ceil(2.0 * std::max(box.width / (board.cols - 1.0), box.height / (board.rows - 1.0))));
    crop = cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) & crop;
  }
  bool found = cv::findChessboardCorners(search(crop), pattern, corners, flags);
  if (!found && crop.area() < search.cols * search.rows) {
    crop = cv::Rect(0, 0, search.cols, search.rows);
    found = cv::findChessboardCorners(search, pattern, corners, flags);
  }
  if (!found) {
    d.reason = chessboard_miss_reason(search, board, o);
    return;
  }
  for (auto& c : corners) c += cv::Point2f(static_cast<float>(crop.x), static_cast<float>(crop.y));
  const int largest = std::max(o.subpix_window, 1);
  const cv::TermCriteria until(cv::TermCriteria::EPS + cv::TermCriteria::MAX_ITER, o.subpix_iterations,
                               o.subpix_epsilon);
  if (f < 1.0) {
    // Refined on the reduced image first (to ~0.1 px there), then taken back to full-size pixel
    // centres, u = (u' + 0.5) / f − 0.5 (INTER_AREA keeps pixel areas), and refined again there
    // with the usual window, which a larger one could push into the neighbouring squares.
    const int w = subpix_half_window(corners, pattern, largest);
    cv::cornerSubPix(search, corners, cv::Size(w, w), cv::Size(-1, -1), until);
    for (auto& c : corners)
      c = cv::Point2f(static_cast<float>((c.x + 0.5) / f - 0.5), static_cast<float>((c.y + 0.5) / f - 0.5));
  }
  const int w = subpix_half_window(corners, pattern, largest);
  cv::cornerSubPix(grey, corners, cv::Size(w, w), cv::Size(-1, -1), until);
  d.found = true;
  fill_points(d, board, corners, iota_ids(corners.size()));
}

void detect_circles(const cv::Mat& grey, const BoardSpec& board, const DetectionOptions& o, BoardDetection& d) {
  const bool asymmetric = board.type == BoardType::kAsymmetricCircles;
  std::vector<cv::Point2f> centres;
  const int flags = asymmetric ? cv::CALIB_CB_ASYMMETRIC_GRID : cv::CALIB_CB_SYMMETRIC_GRID;
  if (cv::findCirclesGrid(grey, cv::Size(board.cols, board.rows), centres, flags)) {
    d.found = true;
    fill_points(d, board, centres, iota_ids(centres.size()));
    return;
  }
  // Not found: count the blobs that findCirclesGrid's default blob detector sees, to tell a
  // board cut by the border from no board at all.
  std::vector<cv::KeyPoint> blobs;
  cv::SimpleBlobDetector::create()->detect(grey, blobs);
  std::vector<cv::Point2f> p;
  for (const auto& k : blobs) p.push_back(k.pt);
  const int m = board.point_count();
  const int n = static_cast<int>(p.size());
  if (n >= m / 2 && n < m && count_at_border(p, grey.size(), o.border_margin_px + 10.0) > 0)
    d.reason = fmt::format("board partly out of view ({} of {} points visible, points at the image border)", n, m);
  else
    d.reason = fmt::format("no board found (no {}x{} {} circle grid; {} blobs)", board.cols, board.rows,
                           asymmetric ? "asymmetric" : "symmetric", n);
}

void detect_charuco(const cv::Mat& image, const cv::Mat& grey, const BoardSpec& board, const DetectionOptions& o,
                    BoardDetection& d) {
  const int dict_id = aruco_dictionary_id(board.dictionary);
  if (dict_id < 0) throw Error(fmt::format("detect_board: unknown ArUco dictionary '{}'", board.dictionary));
  const auto dictionary = cv::aruco::getPredefinedDictionary(dict_id);
  const auto charuco = cv::aruco::CharucoBoard::create(board.cols, board.rows, static_cast<float>(board.square_m),
                                                       static_cast<float>(board.marker_m), dictionary);
  std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
  std::vector<int> marker_ids;
  // Markers on the colour image, as OpenCV's ChArUco calibration sample (detectMarkers converts).
  cv::aruco::detectMarkers(image, dictionary, marker_corners, marker_ids, cv::aruco::DetectorParameters::create(),
                           rejected);
  d.markers = static_cast<int>(marker_ids.size());
  const int m = board.point_count();
  const int total_markers = static_cast<int>(charuco->ids.size());
  if (marker_ids.empty()) {
    d.reason = fmt::format("no board found (no {} marker)", board.dictionary);
    return;
  }
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  if (o.intrinsics && o.charuco_camera_pass) {
    cv::Mat K, dist;
    cv::eigen2cv(Eigen::Matrix3d(o.intrinsics->K()), K);
    dist = cv::Mat(1, 5, CV_64F);
    for (int i = 0; i < 5; ++i) dist.at<double>(i) = o.intrinsics->distortion[static_cast<std::size_t>(i)];
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco, corners, ids, K, dist);
  } else {
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco, corners, ids);
  }
  const int n = static_cast<int>(ids.size());
  const int n_border = count_at_border(corners, grey.size(), o.border_margin_px);
  if (n < std::max(o.charuco_min_corners, 4)) {
    d.reason = fmt::format("too few ChArUco corners ({} of {}, need {}; {} of {} markers found)", n, m,
                           std::max(o.charuco_min_corners, 4), d.markers, total_markers);
    return;
  }
  d.found = true;
  fill_points(d, board, corners, ids);
  // A ChArUco view with missing corners is still usable; say why they are missing. The plane
  // homography of the found corners (lens distortion neglected: enough to tell inside from
  // outside) places the missing ones: outside the image means the board is partly out of view.
  if (n < m) {
    std::vector<cv::Point2f> plane;
    for (const auto& p : d.object_points) plane.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    const cv::Mat H = cv::findHomography(plane, corners, 0);
    std::vector<bool> present(static_cast<std::size_t>(m), false);
    for (int id : ids) present[static_cast<std::size_t>(id)] = true;
    std::vector<cv::Point2f> missing_plane, missing_image;
    const auto all = board.object_points();
    for (int id = 0; id < m; ++id)
      if (!present[static_cast<std::size_t>(id)])
        missing_plane.emplace_back(static_cast<float>(all[static_cast<std::size_t>(id)].x()),
                                   static_cast<float>(all[static_cast<std::size_t>(id)].y()));
    int outside = 0;
    if (!H.empty()) {
      cv::perspectiveTransform(missing_plane, missing_image, H);
      for (const auto& p : missing_image) outside += p.x < 0 || p.y < 0 || p.x > grey.cols - 1 || p.y > grey.rows - 1;
    }
    if (outside > 0 || n_border > 0)
      d.reason = fmt::format("board partly out of view ({} of {} points; {} missing points lie outside the image)", n,
                             m, outside);
    else
      d.reason = fmt::format("{} of {} ChArUco corners found ({} of {} markers; occlusion, glare or blur?)", n, m,
                             d.markers, total_markers);
  }
}

}  // namespace

double laplacian_variance(const cv::Mat& grey) {
  // On a 640-px-wide version of larger photos: the variance falls with resolution (edges are
  // lines, their share of the pixels shrinks as 1/scale), so a fixed threshold would refuse
  // sharp 12-MP photos; at 640 px it means the same for every camera.
  const int longer = std::max(grey.cols, grey.rows);
  cv::Mat small = grey;
  if (longer > 800) {
    const double f = 640.0 / longer;
    cv::resize(grey, small, cv::Size(), f, f, cv::INTER_AREA);
  }
  cv::Mat lap;
  cv::Laplacian(small, lap, CV_64F);
  cv::Scalar mean, sd;
  cv::meanStdDev(lap, mean, sd);
  return sd[0] * sd[0];
}

BoardDetection detect_board(const cv::Mat& image, const BoardSpec& board, const DetectionOptions& options) {
  BoardDetection d;
  const cv::Mat grey = to_grey(image);
  d.width = grey.cols;
  d.height = grey.rows;
  d.laplacian_variance = laplacian_variance(grey);
  switch (board.type) {
    case BoardType::kChessboard:
      detect_chessboard(grey, board, options, d);
      break;
    case BoardType::kCircles:
    case BoardType::kAsymmetricCircles:
      detect_circles(grey, board, options, d);
      break;
    case BoardType::kCharuco:
      detect_charuco(image, grey, board, options, d);
      break;
  }
  // Blur: corners found on a blurred photo lose their sub-pixel accuracy, so it is refused; a
  // photo without a board that is also blurred (or blank) says both.
  if (options.min_laplacian_variance > 0.0 && d.laplacian_variance < options.min_laplacian_variance) {
    const std::string blur =
        fmt::format("variance of Laplacian {:.1f} below {:.1f}", d.laplacian_variance, options.min_laplacian_variance);
    if (d.found) {
      d = BoardDetection{false,     "blurred (" + blur + ")", {},      {},      {},
                         d.markers, d.laplacian_variance,     d.width, d.height};
    } else {
      d.reason += " in a blurred or blank photo (" + blur + ")";
    }
  }
  return d;
}

}  // namespace antpose::camera
