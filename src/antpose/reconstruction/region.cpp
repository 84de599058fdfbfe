// reconstruct_region: the user's rectangle → per-view regions → points of the object.
//
//   1. Sparse: SIFT inside the ROI of the reference view, matched with the other views by guided
//      matching on the epipolar lines of the refined poses (a plain radome's few features are
//      not outvoted by the board's corners and the ground elsewhere), triangulated (features.hpp). The nearest cluster
//      of their depths (along the reference camera's axis) is the object's depth range: the
//      background (sky, ground, buildings) of a rectangle drawn around an antenna lies behind it.
//   2. The ROI's frustum cut to that depth range is a 3-D volume; its projection is the region
//      in every other view (nullopt when less than half of it is in the image).
//   3. Dense: pairs of views with a useful triangulation angle are rectified on the region only
//      (a common rotation with x along the baseline; cv::initUndistortRectifyMap removes the
//      distortion; an image pyramid level when the region is larger than needed) and matched
//      with semi-global matching (Hirschmüller, "Stereo processing by semiglobal matching and
//      mutual information", PAMI 2008; cv::StereoSGBM) over the disparity range of the volume
//      only, with its uniqueness and left–right checks. Each disparity is then refined by a 1-D
//      Lucas–Kanade step (SGBM's sub-pixel parabola is biased towards whole pixels and tilts
//      planes), which also applies a texture check against the image noise: on a plain radome
//      only edges and details survive. Points outside the volume are dropped, and a point must
//      be confirmed by another pair (multi-view consistency).
//      Sparse feature points inside the volume join the cloud. Measured figures and the
//      behaviour on plain and weathered radomes: docs/reconstruction.md.
//   4. Statistical outlier removal (Rusu et al., "Towards 3D point cloud based object maps for
//      household environments", RAS 2008), voxel downsampling, PCA normals oriented towards the
//      cameras.
#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/reconstruction/features.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/global_start.hpp"
#include "antpose/registration/kdtree.hpp"
#include "antpose/registration/local_geometry.hpp"

namespace antpose::reconstruction {
namespace detail {

// Nearest, not densest: whatever else a rectangle drawn around an antenna holds (sky, ground,
// buildings, trees) lies behind the antenna, and may carry more texture than its radome. The
// fifth rules out a few stray triangulations nearer than the object (the board's edge); but a
// textured wall behind a panel may hold more than five times its features (~30 on a panel 4.2 m
// away against 295 on a wall at 12–18 m), and kObjectSupport in one window are an object.
std::optional<DepthRange> nearest_depth_cluster(const std::vector<Vec3>& points_board, const Mat3& R, const Vec3& t,
                                                std::size_t min_support) {
  if (points_board.empty()) return std::nullopt;
  std::vector<std::pair<double, std::size_t>> z;
  for (std::size_t i = 0; i < points_board.size(); ++i) z.emplace_back((R * points_board[i] + t).z(), i);
  std::sort(z.begin(), z.end());
  // A panel is at most ~1.4 m deep along any ray; allow for triangulation noise at range.
  auto width = [&](std::size_t lo) { return std::max(1.5, 0.1 * z[lo].first); };
  auto end_of = [&](std::size_t lo) {
    std::size_t hi = lo;
    while (hi < z.size() && z[hi].first <= z[lo].first + width(lo)) ++hi;
    return hi;
  };
  std::size_t largest = 0;
  for (std::size_t lo = 0; lo < z.size(); ++lo) largest = std::max(largest, end_of(lo) - lo);
  const std::size_t needed = std::max(min_support, std::min(largest / 5, kObjectSupport));
  std::size_t first = z.size();
  for (std::size_t lo = 0; lo < z.size(); ++lo)
    if (end_of(lo) - lo >= needed) {
      first = lo;
      break;
    }
  DepthRange r;
  if (first == z.size()) {
    r.support = 0;
    for (std::size_t lo = 0; lo < z.size(); ++lo) r.support = std::max(r.support, end_of(lo) - lo);
    return r;
  }
  std::size_t best_lo = first, best_hi = end_of(first);
  for (std::size_t lo = first; lo < z.size() && z[lo].first <= z[first].first + width(first); ++lo)
    if (end_of(lo) - lo > best_hi - best_lo) best_lo = lo, best_hi = end_of(lo);
  r.support = best_hi - best_lo;
  const double zlo = z[best_lo].first, zhi = z[best_hi - 1].first;
  const double margin = 0.15 + 0.03 * zhi;
  r.near = std::max(0.1, zlo - margin);
  r.far = zhi + margin;
  for (std::size_t k = best_lo; k < best_hi; ++k) r.centre_board += points_board[z[k].second];
  r.centre_board /= double(r.support);
  return r;
}

}  // namespace detail

namespace {

/// Board-frame points on the boundary of `roi` of a view at the given depths (along the
/// camera's z), a few per edge so that the lens distortion's curvature is followed.
std::vector<Vec3> frustum_samples(const Roi& roi, const Mat3& R, const Vec3& t, const camera::CameraIntrinsics& K,
                                  const std::vector<double>& depths) {
  std::vector<Vec3> out;
  constexpr int kPerEdge = 6;
  const double x0 = roi.x - 0.5, y0 = roi.y - 0.5, x1 = roi.x + roi.width - 0.5, y1 = roi.y + roi.height - 0.5;
  std::vector<Vec2> px;
  for (int i = 0; i <= kPerEdge; ++i) {
    const double f = double(i) / kPerEdge;
    px.emplace_back(x0 + f * (x1 - x0), y0);
    px.emplace_back(x0 + f * (x1 - x0), y1);
    px.emplace_back(x0, y0 + f * (y1 - y0));
    px.emplace_back(x1, y0 + f * (y1 - y0));
  }
  for (const auto& p : px) {
    const Vec3 ray = K.ray(p);
    for (double z : depths) out.push_back(R.transpose() * (ray / ray.z() * z - t));
  }
  return out;
}

using detail::DepthRange;

struct PairCloud {
  int a = 0, b = 0;
  std::vector<Vec3> points;
  double tolerance_m = 0;  // expected depth noise scale of this pair (for consistency checks)
};

struct DenseContext {
  const std::vector<PosedView>* views;
  const RefinedPoses* poses;
  const camera::CameraIntrinsics* K;
  std::size_t roi_view;
  Roi roi;
  DepthRange range;
  std::vector<Vec3> volume;  // board-frame samples of the region's volume
  double max_depth_m;
  const RegionOptions* options;
};

/// Bounding box of points (cv::Rect's union ignores empty rectangles, so points need this).
struct Box {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  void add(const Vec2& p) {
    x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y()), x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
  }
  bool empty() const { return x1 < x0; }
  /// Integer pixel rectangle covering the box (coordinates clamped to ±1e6 first).
  cv::Rect pixels() const {
    auto c = [](double v) { return std::clamp(v, -1e6, 1e6); };
    const int ix0 = int(std::floor(c(x0))), iy0 = int(std::floor(c(y0)));
    return {ix0, iy0, int(std::ceil(c(x1))) + 1 - ix0, int(std::ceil(c(y1))) + 1 - iy0};
  }
};

bool inside(const Roi& r, const Vec2& p) {
  return p.x() >= r.x - 0.5 && p.y() >= r.y - 0.5 && p.x() < r.x + r.width - 0.5 && p.y() < r.y + r.height - 0.5;
}

/// Inside RegionOptions::exclude_board (the calibration board's box).
bool excluded(const RegionOptions& o, const Vec3& p) {
  return o.exclude_board && (p.array() >= o.exclude_board->first.array()).all() &&
         (p.array() <= o.exclude_board->second.array()).all();
}

/// The volume check shared by dense and sparse points: not excluded, inside the reference ROI,
/// within the depth range.
bool in_volume(const DenseContext& c, const Vec3& p) {
  if (excluded(*c.options, p)) return false;
  const Mat3& R = c.poses->R_camera_board[c.roi_view];
  const Vec3& t = c.poses->t_camera_board[c.roi_view];
  const Vec3 pc = R * p + t;
  if (pc.z() < c.range.near || pc.z() > c.range.far) return false;
  const auto uv = c.K->project(pc);
  return uv && inside(c.roi, *uv);
}

constexpr int kDenseMaxSide = 900;
constexpr double kTexture =
    4.0;  // window gradient variance / noise's (see dense_pair)  // px of the rectified region's longer side

/// Intrinsics of pyramid level `level` (pixel centres: (u + 0.5) / 2^level − 0.5).
cv::Mat level_K(const camera::CameraIntrinsics& K, int level) {
  const double s = std::ldexp(1.0, -level);
  cv::Mat m =
      (cv::Mat_<double>(3, 3) << K.fx * s, 0, (K.cx + 0.5) * s - 0.5, 0, K.fy * s, (K.cy + 0.5) * s - 0.5, 0, 0, 1);
  return m;
}

PairCloud dense_pair(const DenseContext& c, int a, int b, const std::vector<cv::Mat>& pyramid_a,
                     const std::vector<cv::Mat>& pyramid_b) {
  PairCloud out{a, b, {}, 0.0};
  const auto& P = *c.poses;
  const auto& K = *c.K;
  const Vec3 Ca = camera::camera_centre(P.R_camera_board[a], P.t_camera_board[a]);
  const Vec3 Cb = camera::camera_centre(P.R_camera_board[b], P.t_camera_board[b]);
  const double baseline = (Cb - Ca).norm();
  // Rectified frame: x along the baseline (so disparities u_a − u_b are positive), z towards the
  // object, y = z × x.
  const Vec3 x = (Cb - Ca) / baseline;
  Vec3 z = c.range.centre_board - 0.5 * (Ca + Cb);
  z = (z - z.dot(x) * x).normalized();
  const Vec3 y = z.cross(x);
  Mat3 R_rect_board;
  R_rect_board.row(0) = x.transpose();
  R_rect_board.row(1) = y.transpose();
  R_rect_board.row(2) = z.transpose();

  // The region's volume in normalised rectified coordinates of camera a; disparity B / Z.
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9, d0 = 1e9, d1 = -1e9;
  for (const auto& p : c.volume) {
    const Vec3 q = R_rect_board * (p - Ca);
    if (q.z() <= 0.05) return out;
    u0 = std::min(u0, q.x() / q.z()), u1 = std::max(u1, q.x() / q.z());
    v0 = std::min(v0, q.y() / q.z()), v1 = std::max(v1, q.y() / q.z());
    d0 = std::min(d0, baseline / q.z()), d1 = std::max(d1, baseline / q.z());
  }
  // Resolution: the original focal length, halved per pyramid level until the region fits.
  const double f_full = 0.5 * (K.fx + K.fy);
  const double extent = f_full * std::max(u1 - u0, v1 - v0);
  int level = 0;
  while (level + 1 < int(pyramid_a.size()) && extent * std::ldexp(1.0, -level) > kDenseMaxSide) ++level;
  const double f = f_full * std::ldexp(1.0, -level);
  constexpr int m = 4;  // margin, px
  const double x0 = f * u0, x1 = f * u1, y0 = f * v0, y1 = f * v1, dmin = f * d0, dmax = f * d1;
  const int N = std::max(16, int(std::ceil((dmax - dmin + 2 * m) / 16.0)) * 16);
  if (N > 512) return out;  // a depth range this wide is not an object; skip the pair
  const int W = int(std::ceil(x1 - x0)) + N + 2 * m, H = int(std::ceil(y1 - y0)) + 2 * m;
  const double cx_a = N + m - x0, cy = m - y0, cx_b = cx_a + dmin - m;
  const cv::Mat Ka = (cv::Mat_<double>(3, 3) << f, 0, cx_a, 0, f, cy, 0, 0, 1);
  const cv::Mat Kb = (cv::Mat_<double>(3, 3) << f, 0, cx_b, 0, f, cy, 0, 0, 1);
  const cv::Mat D(1, 5, CV_64F, const_cast<double*>(K.distortion.data()));
  auto rectify = [&](int v, const std::vector<cv::Mat>& pyr, const cv::Mat& Knew) {
    const Mat3 R_rect_cam = R_rect_board * P.R_camera_board[v].transpose();
    cv::Mat Rcv(3, 3, CV_64F);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) Rcv.at<double>(i, j) = R_rect_cam(i, j);
    cv::Mat mapx, mapy, out_img;
    cv::initUndistortRectifyMap(level_K(K, level), D, Rcv, Knew, cv::Size(W, H), CV_32FC1, mapx, mapy);
    cv::remap(pyr[level], out_img, mapx, mapy, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::Mat valid;
    cv::remap(cv::Mat(pyr[level].size(), CV_8UC1, cv::Scalar(255)), valid, mapx, mapy, cv::INTER_NEAREST,
              cv::BORDER_CONSTANT, cv::Scalar(0));
    return std::make_pair(out_img, valid);
  };
  const auto [rect_a, valid_a] = rectify(a, pyramid_a, Ka);
  const auto [rect_b, valid_b] = rectify(b, pyramid_b, Kb);

  constexpr int kBlock = 5;
  auto sgbm = cv::StereoSGBM::create(0, N, kBlock, 8 * kBlock * kBlock, 32 * kBlock * kBlock, /*disp12MaxDiff=*/1,
                                     /*preFilterCap=*/31, /*uniquenessRatio=*/10, /*speckleWindowSize=*/60,
                                     /*speckleRange=*/1, cv::StereoSGBM::MODE_SGBM);
  cv::Mat disparity;
  sgbm->compute(rect_a, rect_b, disparity);  // CV_16S, 16 × disparity; invalid < 0

  // Matching windows straddling a depth edge take the nearer surface's disparity ("foreground
  // fattening"): drop pixels within half a block of an invalid pixel or a disparity jump.
  cv::Mat good = (disparity > 0) & (valid_a > 0);
  cv::Mat jumps;
  {
    cv::Mat d32, gx, gy;
    disparity.convertTo(d32, CV_32F, 1.0 / 16);
    cv::Sobel(d32, gx, CV_32F, 1, 0, 3, 0.125);
    cv::Sobel(d32, gy, CV_32F, 0, 1, 3, 0.125);
    cv::Mat mag;
    cv::magnitude(gx, gy, mag);
    jumps = mag < 1.0f;
  }
  good &= jumps;
  cv::erode(good, good, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(kBlock, kBlock)));

  // Sub-pixel disparity: SGBM's parabola through three matching costs is biased towards whole
  // pixels ("pixel locking", Shimizu & Okutomi, ICCV 2001), which tilts a plane whose disparity
  // spans less than a pixel — the front face of a panel seen nearly square. A 1-D Lucas–Kanade
  // refinement (Lucas & Kanade, IJCAI 1981) of an affine disparity over the window with a
  // brightness offset, sampling both images symmetrically, has no such bias. Pixels where it
  // diverges (moves > 1 px from SGBM) are dropped.
  cv::Mat fa, fb, ga, gb;
  rect_a.convertTo(fa, CV_32F);
  rect_b.convertTo(fb, CV_32F);
  cv::Sobel(fa, ga, CV_32F, 1, 0, 1, 0.5);  // central differences
  cv::Sobel(fb, gb, CV_32F, 1, 0, 1, 0.5);
  constexpr int kHalf = 3;  // 7 × 7 window
  // Texture check: a window's gradient variance must exceed kTexture times what sensor noise
  // alone gives (σ²/2 for the central difference). σ from the median absolute response to
  // Immerkær's noise mask ("Fast noise variance estimation", CVIU 1996; the median instead of
  // the mean so that texture edges do not count): |I * N| has σ_N = 6σ for white noise.
  // SGM's smoothness term fills a uniform face with disparities interpolated from its edges;
  // on a plain radome those points are off by centimetres, and this check removes them.
  double noise_var = 0;
  {
    cv::Mat lap;
    const cv::Mat mask_n = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
    cv::filter2D(fb, lap, CV_32F, mask_n);
    std::vector<float> v;
    for (int r = 1; r < H - 1; ++r)
      for (int col = N + 1; col < W - 1; ++col) v.push_back(std::abs(lap.at<float>(r, col)));
    if (!v.empty()) {
      const double sigma = median(std::move(v)) / 0.6745 / 6.0;
      noise_var = sigma * sigma;
    }
  }
  const double min_gradient_var = kTexture * std::max(0.25, noise_var) / 2.0;
  auto sample = [](const cv::Mat& img, int row, double x) {
    const int x0 = int(std::floor(x));
    const double f = x - x0;
    const float* p = img.ptr<float>(row);
    return (1 - f) * p[x0] + f * p[x0 + 1];
  };
  const Mat3 R_board_rect = R_rect_board.transpose();
  for (int r = kHalf; r < H - kHalf; ++r) {
    const short* drow = disparity.ptr<short>(r);
    const uchar* grow = good.ptr<uchar>(r);
    for (int col = N; col < W - kHalf; ++col) {
      if (!grow[col]) continue;
      double dc = drow[col] / 16.0, slope_x = 0, slope_y = 0, offset = 0;
      bool ok = true;
      for (int it = 0; it < 5 && ok; ++it) {
        // Symmetric sampling: a at x + f/2 and b at x − n − f/2 (local disparity n + f, |f| ≤ ½),
        // so both images pass through the same bilinear low-pass; interpolating only b biases
        // the shift towards whole pixels again (the interpolation bias of image correlation).
        // The disparity is affine over the window (dc + sx u + sy v: a slanted plane), plus a
        // brightness offset; a constant shift on a slanted face is biased by the window's
        // texture distribution, more so the larger the window.
        Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
        Eigen::Vector4d Jte = Eigen::Vector4d::Zero();
        double sg = 0, sgg = 0;
        int cnt = 0;
        for (int y = r - kHalf; y <= r + kHalf && ok; ++y)
          for (int x = col - kHalf; x <= col + kHalf; ++x) {
            const double u = x - col, v = y - r;
            const double dl = dc + slope_x * u + slope_y * v;
            const double n_int = std::round(dl), fr = dl - n_int;
            const double xa = x + 0.5 * fr, xb = x - n_int - 0.5 * fr;
            if (xb < 0 || xb >= W - 1 || xa < 0 || xa >= W - 1) {
              ok = false;
              break;
            }
            // e = a(xa + Δ/2) − b(xb − Δ/2) − offset ≈ e₀ + ½(g_a + g_b) Δ − δoffset.
            const double e = sample(fa, y, xa) - sample(fb, y, xb) - offset;
            const double g = 0.5 * (sample(ga, y, xa) + sample(gb, y, xb));
            const Eigen::Vector4d J(g, g * u, g * v, -1.0);
            JtJ.noalias() += J * J.transpose();
            Jte += J * e;
            sg += g, sgg += g * g, ++cnt;
          }
        if (!ok) break;
        // Texture check on the window's gradient variance.
        if (sgg - sg * sg / cnt < min_gradient_var * cnt) {
          ok = false;
          break;
        }
        JtJ.diagonal() += Eigen::Vector4d(1e-6, 1e-3, 1e-3, 1e-6) * cnt;  // slopes: mild damping
        const Eigen::Vector4d step = -JtJ.ldlt().solve(Jte);
        if (!step.allFinite()) {
          ok = false;
          break;
        }
        dc += step(0), slope_x += step(1), slope_y += step(2), offset += step(3);
        if (std::abs(dc - drow[col] / 16.0) > 1.0 || std::abs(slope_x) > 0.5 || std::abs(slope_y) > 0.5) ok = false;
        if (std::abs(step(0)) < 1e-3) break;
      }
      if (!ok) continue;
      const double d = dc + dmin - m;
      if (d <= 0) continue;
      const double Z = f * baseline / d;
      const Vec3 q((col - cx_a) * Z / f, (r - cy) * Z / f, Z);
      const Vec3 p = Ca + R_board_rect * q;
      if (q.norm() > c.max_depth_m || !in_volume(c, p)) continue;
      out.points.push_back(p);
    }
  }
  // Depth noise for 0.25 px of disparity at the region's distance (consistency tolerance).
  const double Zc = (R_rect_board * (c.range.centre_board - Ca)).z();
  out.tolerance_m = Zc * Zc * 0.25 / (f * baseline);
  return out;
}

/// Rusu 2008: drop points whose mean distance to their k neighbours exceeds the cloud's mean of
/// that statistic by more than std_ratio standard deviations.
std::vector<Vec3> statistical_outlier_removal(const std::vector<Vec3>& points, int k, double std_ratio) {
  if (points.size() <= std::size_t(k)) return points;
  registration::KdTree tree(points);
  std::vector<double> mean_d(points.size());
  cv::parallel_for_(cv::Range(0, int(points.size())), [&](const cv::Range& r) {
    std::vector<std::size_t> idx;
    std::vector<double> d2;
    for (int i = r.start; i < r.end; ++i) {
      const std::size_t found = tree.knn(points[i], k + 1, idx, d2);
      double s = 0;
      for (std::size_t j = 1; j < found; ++j) s += std::sqrt(d2[j]);
      mean_d[i] = found > 1 ? s / double(found - 1) : 0;
    }
  });
  const double mu = std::accumulate(mean_d.begin(), mean_d.end(), 0.0) / double(mean_d.size());
  double var = 0;
  for (double d : mean_d) var += (d - mu) * (d - mu);
  const double sigma = std::sqrt(var / double(mean_d.size()));
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (mean_d[i] <= mu + std_ratio * sigma) out.push_back(points[i]);
  return out;
}

}  // namespace

namespace {

// The refusal of a region that fewer than two photos see (`counted`: what counts as seeing it),
// with what to do.
MeasurementError seen_by_too_few(const std::string& photo, std::size_t seen, const char* counted) {
  return MeasurementError(
      fmt::format("the region of {} is seen in only {} photo(s) ({}); at least 2 are needed: add photos that show "
                  "the whole antenna from a few steps aside, or draw its rectangle in a photo taken nearer the "
                  "middle of the walk",
                  photo, seen, counted));
}

// What one object's reconstruction gave: its region, or why not — no object's depth among the
// features, or too few points on its surface (the region then holds those it gave). `range`: the
// depth range it was sought in.
struct ObjectAttempt {
  enum class Outcome { kFound, kTooFewPoints, kNoObject };
  Outcome outcome = Outcome::kFound;
  RegionReconstruction region;
  DepthRange range;
  std::string reason;
};

// The caller's expected depth range as the object's, centred on the rectangle's middle ray.
std::optional<DepthRange> expected_range(const RegionOptions& o, const Roi& roi, const Mat3& R, const Vec3& t,
                                         const camera::CameraIntrinsics& K) {
  if (!o.expected_depth_m) return std::nullopt;
  const auto [near, far] = *o.expected_depth_m;
  const Vec3 ray = K.ray(Vec2(roi.x + 0.5 * roi.width - 0.5, roi.y + 0.5 * roi.height - 0.5));
  DepthRange range;
  range.near = near, range.far = far;
  range.centre_board = R.transpose() * (ray / ray.z() * (0.5 * (near + far)) - t);
  return range;
}

// reconstruct_region without the fallback to the next object: the object is the nearest one more
// than options.beyond_m from the region's camera (along its axis). MeasurementError for a region
// outside the photo or seen in fewer than two photos.
ObjectAttempt reconstruct_object(const std::vector<PosedView>& views, const RefinedPoses& poses,
                                        std::size_t roi_view, const Roi& roi_in,
                                        const camera::CameraIntrinsics& intrinsics, const RegionOptions& options,
                                        const Progress& progress) {
  const int n = int(views.size());
  if (poses.R_camera_board.size() != views.size() || poses.t_camera_board.size() != views.size())
    throw MeasurementError(fmt::format("{} refined poses for {} photos", poses.R_camera_board.size(), views.size()));
  if (roi_view >= views.size())
    throw MeasurementError(fmt::format("the region's photo index {} is beyond the {} photos", roi_view, n));
  for (const auto& v : views)
    if (v.image.cols != intrinsics.width || v.image.rows != intrinsics.height || v.image.type() != CV_8UC1)
      throw MeasurementError(fmt::format("{}: the image is not an 8-bit grey image of {}×{} px", v.name,
                                         intrinsics.width, intrinsics.height));
  auto report = [&](const std::string& stage, int done, int total) {
    if (progress) progress(stage, done, total);
  };
  const auto& ref = views[roi_view];
  const cv::Rect image_rect(0, 0, intrinsics.width, intrinsics.height);
  const cv::Rect asked(roi_in.x, roi_in.y, roi_in.width, roi_in.height);
  const cv::Rect clipped = asked & image_rect;
  if (roi_in.width <= 0 || roi_in.height <= 0 || clipped.width < 8 || clipped.height < 8)
    throw MeasurementError(
        fmt::format("the region (x {}, y {}, {}×{} px) lies outside the image of {} ({}×{} px) or is too small",
                    roi_in.x, roi_in.y, roi_in.width, roi_in.height, ref.name, intrinsics.width, intrinsics.height));
  const Roi roi{clipped.x, clipped.y, clipped.width, clipped.height};
  RegionReconstruction out;
  if (clipped != asked) out.warnings.push_back("the region was cut to the image");

  const Mat3& Rr = poses.R_camera_board[roi_view];
  const Vec3& tr = poses.t_camera_board[roi_view];
  const double focal = 0.5 * (intrinsics.fx + intrinsics.fy);

  // 1. Sparse features of the region and their matches in the other photos, searched in the
  //    projection of the ROI's whole frustum (up to max_depth).
  constexpr int kSparseMaxSide = 1600, kSparseFeatures = 4000;
  std::vector<detail::ViewFeatures> features(n);
  // Weak radome texture: SIFT's contrast threshold lowered, small regions enlarged 2×.
  constexpr double kUpscale = 2.0, kContrast = 0.01;
  const auto frustum = frustum_samples(roi, Rr, tr, intrinsics, {0.5, 2.0, 8.0, options.max_depth_m});
  std::vector<detail::PairMatches> pairs;
  for (int v = 0; v < n; ++v) {
    if (v == int(roi_view)) continue;
    // A photo sees the region when some of its frustum projects into the image.
    bool sees = false;
    for (const auto& p : frustum)
      if (const auto uv = intrinsics.project(poses.R_camera_board[v] * p + poses.t_camera_board[v]))
        sees = sees || (uv->x() >= 0 && uv->y() >= 0 && uv->x() < intrinsics.width && uv->y() < intrinsics.height);
    if (sees) pairs.push_back({int(roi_view), v, {}});
  }
  if (pairs.empty())
    throw seen_by_too_few(ref.name, 1, "any of it inside the frame");
  // Where each photo is searched: the region itself in its own photo; in the others, the bounding
  // box of the frustum's projection (points behind the camera are skipped: the box is then
  // conservative only when the frustum lies in front, the usual case).
  std::vector<cv::Rect> areas(n);
  areas[roi_view] = clipped;
  for (const auto& pair : pairs) {
    Box box;
    for (const auto& p : frustum)
      if (const auto uv = intrinsics.project(poses.R_camera_board[pair.view_b] * p + poses.t_camera_board[pair.view_b]))
        box.add(*uv);
    if (!box.empty()) areas[pair.view_b] = box.pixels() & image_rect;
  }
  // Every photo's features at once (the region's own too: its enlarged crop is the largest), then
  // the matches.
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
    for (int v = r.start; v < r.end; ++v)
      if (!areas[v].empty())
        features[v] = detail::detect_features(views[v].image, {}, areas[v], kSparseFeatures, kSparseMaxSide, intrinsics,
                                              kUpscale, kContrast);
  });
  cv::parallel_for_(cv::Range(0, int(pairs.size())), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      const int v = pairs[k].view_b;
      if (areas[v].empty()) continue;
      const Mat3& R = poses.R_camera_board[v];
      const Vec3& t = poses.t_camera_board[v];
      const Mat3 R_b_a = R * Rr.transpose();
      const Vec3 t_b_a = t - R_b_a * tr;
      const double tol = 2.0 / std::min({1.0, features[roi_view].scale, features[v].scale});
      pairs[k].matches = detail::guided_matches(features[roi_view], features[v], R_b_a, t_b_a, 0.8, tol, focal);
    }
  });
  std::vector<std::size_t> counts(n);
  for (int v = 0; v < n; ++v) counts[v] = features[v].px.size();
  auto tracks = detail::build_tracks(counts, pairs);
  detail::TriangulationChecks checks;
  checks.max_reprojection_px = 2.0 / std::min(1.0, features[roi_view].scale);
  checks.min_angle_rad = deg2rad(1.0);
  checks.max_depth_m = options.max_depth_m;
  std::vector<Vec3> sparse;
  std::vector<std::vector<detail::Observation>> sparse_tracks;
  for (auto& track : tracks)
    if (auto X = detail::triangulate_track(track, features, poses.R_camera_board, poses.t_camera_board, intrinsics,
                                           checks)) {
      if (excluded(options, *X)) continue;
      sparse.push_back(*X);
      sparse_tracks.push_back(track);
    }
  report("region features", 1, 1);

  // 2. Depth range and the region in every view.
  // Few: a plain radome gives only a handful of features (its corners, brackets); the nearest
  // cluster rule keeps them from being outvoted by the background.
  constexpr std::size_t kMinSparse = 3;
  std::vector<Vec3> candidates;
  for (const Vec3& p : sparse)
    if ((Rr * p + tr).z() > options.beyond_m) candidates.push_back(p);
  auto range = detail::nearest_depth_cluster(candidates, Rr, tr, kMinSparse);
  if (!range || range->support < kMinSparse) {
    const auto expected = options.beyond_m <= 0.0 ? expected_range(options, roi, Rr, tr, intrinsics) : std::nullopt;
    if (!expected)
      return {ObjectAttempt::Outcome::kNoObject, {}, {},
              fmt::format("no texture or object in the region of {}: only {} feature points could be triangulated "
                          "there (at least {} on one object are needed to find its distance); draw the region "
                          "tightly around the antenna",
                          ref.name, range ? range->support : 0, kMinSparse)};
    range = expected;
    out.warnings.push_back(
        fmt::format("too few features in the region of {} to find the object's distance: it is sought where the "
                    "model fills the rectangle ({:.1f}–{:.1f} m)",
                    ref.name, expected->near, expected->far));
  }
  DenseContext ctx{&views, &poses, &intrinsics, roi_view, roi, *range, {}, options.max_depth_m, &options};
  ctx.volume = frustum_samples(roi, Rr, tr, intrinsics, {range->near, 0.5 * (range->near + range->far), range->far});
  out.depth_near_m = range->near;
  out.depth_far_m = range->far;
  out.rois.assign(n, std::nullopt);
  out.rois[roi_view] = roi;
  std::vector<int> seen_by;
  for (int v = 0; v < n; ++v) {
    if (v == int(roi_view)) {
      seen_by.push_back(v);
      continue;
    }
    Box box;
    bool ok = true;
    for (const auto& p : ctx.volume) {
      const auto uv = intrinsics.project(poses.R_camera_board[v] * p + poses.t_camera_board[v]);
      if (!uv) {
        ok = false;
        break;
      }
      box.add(*uv);
    }
    if (!ok || box.empty()) continue;
    const cv::Rect full = box.pixels();
    const cv::Rect vis = full & image_rect;
    if (vis.area() < 0.5 * full.area() || vis.width < 8 || vis.height < 8) continue;
    out.rois[v] = Roi{vis.x, vis.y, vis.width, vis.height};
    seen_by.push_back(v);
  }
  if (seen_by.size() < 2)
    throw seen_by_too_few(ref.name, seen_by.size(), "at least half of it inside the frame");

  // 3. Dense stereo on pairs with a useful triangulation angle (3°–40° at the object, the best
  //    two partners per view, preferring ~15°: wide enough for depth, narrow enough to match).
  std::vector<std::pair<int, int>> dense_pairs;
  {
    const Vec3 O = range->centre_board;
    std::vector<std::tuple<double, int, int>> candidates;
    for (std::size_t i = 0; i < seen_by.size(); ++i)
      for (std::size_t j = i + 1; j < seen_by.size(); ++j) {
        const int a = seen_by[i], b = seen_by[j];
        const double angle = angle_between(camera::camera_centre(poses.R_camera_board[a], poses.t_camera_board[a]) - O,
                                           camera::camera_centre(poses.R_camera_board[b], poses.t_camera_board[b]) - O);
        if (angle < deg2rad(3) || angle > deg2rad(40)) continue;
        candidates.emplace_back(std::abs(angle - deg2rad(15)), a, b);
      }
    std::sort(candidates.begin(), candidates.end());
    std::vector<int> partners(n, 0);
    for (const auto& [score, a, b] : candidates) {
      if (partners[a] >= 2 && partners[b] >= 2) continue;
      ++partners[a], ++partners[b];
      dense_pairs.emplace_back(a, b);
      if (dense_pairs.size() >= 12) break;
    }
  }
  std::vector<std::vector<cv::Mat>> pyramids(n);
  for (int v : seen_by) {
    pyramids[v].push_back(views[v].image);
    for (int l = 0; l < 3; ++l) {
      cv::Mat down;
      cv::pyrDown(pyramids[v].back(), down);
      pyramids[v].push_back(down);
    }
  }
  std::vector<PairCloud> clouds(dense_pairs.size());
  std::mutex progress_mutex;  // the caller's callback need not be thread-safe
  int done = 0;
  cv::parallel_for_(cv::Range(0, int(dense_pairs.size())), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      const auto [a, b] = dense_pairs[k];
      clouds[k] = dense_pair(ctx, a, b, pyramids[a], pyramids[b]);
      std::lock_guard lock(progress_mutex);
      report("dense stereo", ++done, int(dense_pairs.size()));
    }
  });

  // Multi-view consistency: a point of one pair needs a point of another pair within the
  // larger of the two pairs' depth-noise tolerances (3σ) or one voxel.
  std::vector<Vec3> dense;
  std::vector<char> contributed(n, 0);
  if (clouds.size() >= 2) {
    std::vector<std::unique_ptr<registration::KdTree>> trees;
    for (const auto& c : clouds) trees.push_back(std::make_unique<registration::KdTree>(c.points));
    for (std::size_t p = 0; p < clouds.size(); ++p)
      for (const auto& pt : clouds[p].points) {
        for (std::size_t q = 0; q < clouds.size(); ++q) {
          if (q == p || trees[q]->size() == 0) continue;
          std::size_t idx;
          double d2;
          const double tol = std::max({options.voxel_m, 3 * clouds[p].tolerance_m, 3 * clouds[q].tolerance_m});
          if (trees[q]->nearest(pt, idx, d2, tol * tol)) {
            dense.push_back(pt);
            contributed[clouds[p].a] = contributed[clouds[p].b] = 1;
            break;
          }
        }
      }
  } else if (clouds.size() == 1) {
    out.warnings.push_back("only one stereo pair sees the region: its points are not confirmed by another pair");
    dense = clouds[0].points;
    if (!dense.empty()) contributed[clouds[0].a] = contributed[clouds[0].b] = 1;
  } else {
    out.warnings.push_back("no pair of photos views the region at a usable angle (3°–40°) for dense matching");
  }

  // Sparse points inside the volume join the cloud (they cover textured details that dense
  // matching rejected and carry no disparity quantisation).
  std::vector<Vec3> sparse_in;
  for (std::size_t k = 0; k < sparse.size(); ++k)
    if (in_volume(ctx, sparse[k])) {
      sparse_in.push_back(sparse[k]);
      for (const auto& [v, i] : sparse_tracks[k]) contributed[v] = 1;
    }

  // 4. Filters.
  std::vector<Vec3> all = dense;
  all.insert(all.end(), sparse_in.begin(), sparse_in.end());
  all = statistical_outlier_removal(all, options.sor_neighbours, options.sor_std_ratio);
  PointCloud cloud;
  cloud.points = std::move(all);
  cloud = registration::voxel_downsample(cloud, options.voxel_m);
  const std::size_t dense_voxels = [&] {
    PointCloud d;
    d.points = dense;
    return registration::voxel_downsample(d, options.voxel_m).size();
  }();
  if (cloud.size() < options.min_points) {
    const auto message = fmt::format(
        "no texture or object in the region of {}: only {} points remain after matching and filtering "
        "(at least {} are needed); a plain, untextured radome gives too few points — add photos closer "
        "to it or draw the region tightly around the antenna",
        ref.name, cloud.size(), options.min_points);
    out.cloud_board = std::move(cloud);
    out.views_used = std::count(contributed.begin(), contributed.end(), 1);
    out.method = "features";
    return {ObjectAttempt::Outcome::kTooFewPoints, std::move(out), *range, message};
  }
  out.method = dense_voxels >= cloud.size() / 2 ? (sparse_in.empty() ? "dense" : "dense+features") : "features";
  // Coverage: the fraction of cells (≥ 8 × 8 px) inside the convex hull of the points' projections
  // in the reference view (the object's outline, roughly) that hold a point. A plain radome
  // leaves its faces empty: only edges, brackets and clamps carry texture.
  {
    // Cells no smaller than 1.5 voxels at the object's distance, so a complete surface fills them.
    const double z_centre = (Rr * range->centre_board + tr).z();
    const int kCell = std::max(8, int(std::ceil(1.5 * focal * options.voxel_m / z_centre)));
    const int cw = (roi.width + kCell - 1) / kCell, ch = (roi.height + kCell - 1) / kCell;
    cv::Mat occupied(ch, cw, CV_8UC1, cv::Scalar(0)), hull_mask(ch, cw, CV_8UC1, cv::Scalar(0));
    std::vector<cv::Point> cells;
    for (const auto& p : cloud.points)
      if (const auto uv = intrinsics.project(Rr * p + tr)) {
        const int cx = int(std::floor((uv->x() - roi.x + 0.5) / kCell));
        const int cy = int(std::floor((uv->y() - roi.y + 0.5) / kCell));
        if (cx < 0 || cy < 0 || cx >= cw || cy >= ch) continue;
        occupied.at<uchar>(cy, cx) = 1;
        cells.emplace_back(cx, cy);
      }
    if (cells.size() >= 3) {
      std::vector<cv::Point> hull;
      cv::convexHull(cells, hull);
      cv::fillConvexPoly(hull_mask, hull, cv::Scalar(1));
    }
    const double inside_hull = std::max(1.0, double(cv::countNonZero(hull_mask)));
    out.region_coverage = double(cv::countNonZero(occupied & hull_mask)) / inside_hull;
    if (out.region_coverage < options.min_coverage)
      out.warnings.push_back(
          fmt::format("the points cover only {:.0f}% of the object's outline in {}: little texture (a plain radome?) — "
                      "the points lie on "
                      "edges and details, and the faces' planes rest on them alone",
                      100 * out.region_coverage, ref.name));
  }
  report("filtering", 1, 1);

  // Normals (PCA of the neighbourhood) oriented towards the camera that sees the surface most
  // squarely among those that contributed.
  registration::KdTree tree(cloud.points);
  cloud.normals = registration::estimate_normals(tree, 12);
  std::vector<Vec3> centres;
  for (int v : seen_by) centres.push_back(camera::camera_centre(poses.R_camera_board[v], poses.t_camera_board[v]));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    double best = -1, sign = 1;
    for (const auto& c : centres) {
      const Vec3 d = (c - cloud.points[i]).normalized();
      const double cosine = cloud.normals[i].dot(d);
      if (std::abs(cosine) > best) best = std::abs(cosine), sign = cosine >= 0 ? 1 : -1;
    }
    cloud.normals[i] *= sign;
  }
  out.cloud_board = std::move(cloud);
  out.views_used = std::count(contributed.begin(), contributed.end(), 1);
  return {ObjectAttempt::Outcome::kFound, std::move(out), *range, {}};
}

}  // namespace

// The nearest object in the rectangle is the antenna's (detail::nearest_depth_cluster), but an
// object nearer than the antenna may reach into it: a roof's edge or parapet across the end of the
// rectangle, the board's tripod, or false matches at depths where the scene holds nothing. Where
// the nearest object's surface gives too few points, the next object beyond it is reconstructed
// instead, with a warning, and so on.
RegionReconstruction reconstruct_region(const std::vector<PosedView>& views, const RefinedPoses& poses,
                                        std::size_t roi_view, const Roi& roi,
                                        const camera::CameraIntrinsics& intrinsics, const RegionOptions& options,
                                        const Progress& progress) {
  std::string nearest;  // why the nearest object gave too few points
  std::optional<RegionReconstruction> nearest_partial;
  std::vector<std::string> passed;  // the depth ranges that gave too few points
  RegionOptions here = options;
  for (int k = 0; k < std::max(1, options.max_objects); ++k) {
    auto attempt = reconstruct_object(views, poses, roi_view, roi, intrinsics, here, progress);
    if (attempt.outcome == ObjectAttempt::Outcome::kFound) {
      if (!passed.empty())
        attempt.region.warnings.insert(
            attempt.region.warnings.begin(),
            fmt::format("the nearer object(s) in the region of {}, {} m from the camera, gave too few points for an "
                        "antenna (the roof's edge, a parapet, false matches?): the object beyond was reconstructed; "
                        "check the model drawn over the photos",
                        views[roi_view].name, fmt::join(passed, " and ")));
      return std::move(attempt.region);
    }
    if (nearest.empty()) nearest = attempt.reason;
    if (attempt.outcome == ObjectAttempt::Outcome::kNoObject) break;  // nothing beyond
    if (!nearest_partial) nearest_partial = std::move(attempt.region);
    passed.push_back(fmt::format("{:.1f}–{:.1f}", attempt.range.near, attempt.range.far));
    here.beyond_m = attempt.range.far;
  }
  if (options.allow_few_points && nearest_partial) {
    nearest_partial->warnings.push_back(nearest + " (the model's outline alone places the antenna)");
    return std::move(*nearest_partial);
  }
  throw MeasurementError(nearest);  // the nearest object's reason: nothing beyond it did better
}

}  // namespace antpose::reconstruction
