#include "antpose/reconstruction/features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/SVD>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/board_pose.hpp"

namespace antpose::reconstruction::detail {

ViewFeatures detect_features(const cv::Mat& image, const cv::Mat& mask, const cv::Rect& area, int max_features,
                             int max_side, const camera::CameraIntrinsics& intrinsics, double max_upscale,
                             double contrast_threshold) {
  ViewFeatures out;
  const cv::Rect clipped = area & cv::Rect(0, 0, image.cols, image.rows);
  if (clipped.width < 16 || clipped.height < 16) return out;
  const double scale = std::min(max_upscale, double(max_side) / std::max(clipped.width, clipped.height));
  cv::Mat crop = image(clipped), crop_mask;
  if (!mask.empty()) crop_mask = mask(clipped);
  if (scale > 1.0) {
    cv::resize(crop, crop, cv::Size(), scale, scale, cv::INTER_CUBIC);
    if (!crop_mask.empty()) cv::resize(crop_mask, crop_mask, crop.size(), 0, 0, cv::INTER_NEAREST);
  } else if (scale < 1.0) {
    // INTER_AREA: the box filter keeps SIFT's scale space consistent with a smaller sensor.
    cv::resize(crop, crop, cv::Size(), scale, scale, cv::INTER_AREA);
    if (!crop_mask.empty()) cv::resize(crop_mask, crop_mask, crop.size(), 0, 0, cv::INTER_NEAREST);
  }
  out.scale = scale;
  auto sift = cv::SIFT::create(max_features, 3, contrast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  sift->detectAndCompute(crop, crop_mask, keypoints, out.descriptors);
  out.px.reserve(keypoints.size());
  out.xy.reserve(keypoints.size());
  for (const auto& kp : keypoints) {
    // OpenCV's SIFT (4.6) builds its first octave on the image doubled with pixel-centre
    // resampling but halves coordinates as if corners were aligned, so keypoints come out
    // +0.25 px in x and y (measured: 0.250, 0.249 px on an image and its 180° rotation). That
    // constant offset would tilt every feature ray against the board's, so it is removed.
    // Then pixel centres: x_full + 0.5 = (x_small + 0.5) / scale.
    constexpr double kSiftOffset = 0.25;
    const Vec2 px(clipped.x + (kp.pt.x - kSiftOffset + 0.5) / scale - 0.5,
                  clipped.y + (kp.pt.y - kSiftOffset + 0.5) / scale - 0.5);
    out.px.push_back(px);
    const Vec2 xd((px.x() - intrinsics.cx) / intrinsics.fx, (px.y() - intrinsics.cy) / intrinsics.fy);
    out.xy.push_back(intrinsics.undistort(xd));
  }
  return out;
}

std::vector<std::pair<int, int>> ratio_matches(const ViewFeatures& a, const ViewFeatures& b, double ratio) {
  std::vector<std::pair<int, int>> out;
  if (a.descriptors.rows < 2 || b.descriptors.rows < 2) return out;
  cv::BFMatcher matcher(cv::NORM_L2);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(a.descriptors, b.descriptors, knn, 2);
  for (const auto& m : knn)
    if (m.size() == 2 && m[0].distance <= ratio * m[1].distance) out.emplace_back(m[0].queryIdx, m[0].trainIdx);
  return out;
}

std::vector<std::pair<int, int>> epipolar_filter(const ViewFeatures& a, const ViewFeatures& b,
                                                 const std::vector<std::pair<int, int>>& candidates, const Mat3& R_b_a,
                                                 const Vec3& t_b_a, double max_epipolar_px, double focal_px) {
  // x_bᵀ E x_a = 0 with E = [t]x R (Hartley & Zisserman eq. 9.12 for normalised coordinates).
  const Mat3 E = skew(t_b_a) * R_b_a;
  const double limit = max_epipolar_px / focal_px;
  std::vector<int> used_b(b.xy.size(), -1);
  for (const auto& [ia, ib] : candidates) {
    const Vec3 xa(a.xy[ia].x(), a.xy[ia].y(), 1.0), xb(b.xy[ib].x(), b.xy[ib].y(), 1.0);
    const Vec3 lb = E * xa, la = E.transpose() * xb;  // line in b, line in a
    const double r = xb.dot(lb);
    const double da = std::abs(r) / la.head<2>().norm(), db = std::abs(r) / lb.head<2>().norm();
    if (std::max(da, db) > limit) continue;
    // A feature of b claimed twice makes both claims doubtful.
    if (used_b[ib] == -2) continue;
    used_b[ib] = used_b[ib] >= 0 ? -2 : ia;
  }
  std::vector<std::pair<int, int>> out;
  for (int ib = 0; ib < int(used_b.size()); ++ib)
    if (used_b[ib] >= 0) out.emplace_back(used_b[ib], ib);
  return out;
}

std::vector<std::pair<int, int>> guided_matches(const ViewFeatures& a, const ViewFeatures& b, const Mat3& R_b_a,
                                                const Vec3& t_b_a, double ratio, double max_epipolar_px,
                                                double focal_px, double max_descriptor_angle_rad) {
  const int na = int(a.xy.size()), nb = int(b.xy.size());
  std::vector<std::pair<int, int>> out;
  if (na == 0 || nb == 0) return out;
  const Mat3 E = skew(t_b_a) * R_b_a;
  const double limit = max_epipolar_px / focal_px;
  // Unit descriptors, so that distances compare with the angle cap (OpenCV scales SIFT's to ~512).
  auto unit = [](const cv::Mat& d) {
    using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    Rows m = Eigen::Map<const Rows>(d.ptr<float>(), d.rows, d.cols);
    m.rowwise().normalize();
    return m;
  };
  const auto da = unit(a.descriptors), db = unit(b.descriptors);
  // Epipolar lines of a's features in b, and the lengths of their normals and of b's lines in a
  // (the symmetric distance's denominators), outside the na × nb loop.
  std::vector<Vec3> line_b(na), xb(nb);
  std::vector<double> norm_b(na), norm_a(nb);
  for (int i = 0; i < na; ++i) {
    line_b[i] = E * Vec3(a.xy[i].x(), a.xy[i].y(), 1.0);
    norm_b[i] = line_b[i].head<2>().norm();
  }
  for (int j = 0; j < nb; ++j) {
    xb[j] = Vec3(b.xy[j].x(), b.xy[j].y(), 1.0);
    norm_a[j] = (E.transpose() * xb[j]).head<2>().norm();
  }
  struct Nearest {
    float first = std::numeric_limits<float>::infinity(), second = first;
    int index = -1;
    void add(float d, int k) {
      if (d < first) {
        second = first, first = d, index = k;
      } else if (d < second) {
        second = d;
      }
    }
  };
  std::vector<Nearest> of_a(na), of_b(nb);
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < nb; ++j) {
      const double r = std::abs(xb[j].dot(line_b[i]));
      if (r > limit * norm_b[i] || r > limit * norm_a[j]) continue;
      const float d = (da.row(i) - db.row(j)).norm();
      of_a[i].add(d, j);
      of_b[j].add(d, i);
    }
  }
  // Chord length of the angle cap between unit vectors.
  const float max_distance = float(2.0 * std::sin(0.5 * max_descriptor_angle_rad));
  for (int i = 0; i < na; ++i) {
    const Nearest& n = of_a[i];
    if (n.index < 0 || n.first > max_distance || n.first > float(ratio) * n.second) continue;
    if (of_b[n.index].index == i) out.emplace_back(i, n.index);
  }
  return out;
}

namespace {
struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};
}  // namespace

std::vector<std::vector<Observation>> build_tracks(const std::vector<std::size_t>& features_per_view,
                                                   const std::vector<PairMatches>& pairs) {
  std::vector<int> offset(features_per_view.size() + 1, 0);
  for (std::size_t v = 0; v < features_per_view.size(); ++v) offset[v + 1] = offset[v] + int(features_per_view[v]);
  UnionFind uf(offset.back());
  std::vector<char> matched(offset.back(), 0);
  for (const auto& p : pairs)
    for (const auto& [ia, ib] : p.matches) {
      uf.unite(offset[p.view_a] + ia, offset[p.view_b] + ib);
      matched[offset[p.view_a] + ia] = matched[offset[p.view_b] + ib] = 1;
    }
  std::vector<std::vector<Observation>> by_root(offset.back());
  for (int v = 0; v < int(features_per_view.size()); ++v)
    for (int i = 0; i < int(features_per_view[v]); ++i)
      if (matched[offset[v] + i]) by_root[uf.find(offset[v] + i)].emplace_back(v, i);
  std::vector<std::vector<Observation>> tracks;
  for (auto& t : by_root) {
    if (t.size() < 2) continue;
    std::sort(t.begin(), t.end());
    bool conflict = false;
    for (std::size_t k = 1; k < t.size(); ++k) conflict |= t[k].first == t[k - 1].first;
    if (!conflict) tracks.push_back(std::move(t));
  }
  return tracks;
}

namespace {
std::optional<Vec3> dlt(const std::vector<Observation>& track, const std::vector<ViewFeatures>& features,
                        const std::vector<Mat3>& R, const std::vector<Vec3>& t) {
  Eigen::MatrixXd A(2 * track.size(), 4);
  for (std::size_t k = 0; k < track.size(); ++k) {
    const auto [v, i] = track[k];
    Eigen::Matrix<double, 3, 4> P;
    P << R[v], t[v];
    const Vec2& x = features[v].xy[i];
    A.row(2 * k) = x.x() * P.row(2) - P.row(0);
    A.row(2 * k + 1) = x.y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  if (std::abs(X(3)) < 1e-12) return std::nullopt;  // a point at infinity
  return Vec3(X.head<3>() / X(3));
}
}  // namespace

std::optional<Vec3> triangulate_track(std::vector<Observation>& track, const std::vector<ViewFeatures>& features,
                                      const std::vector<Mat3>& R_camera_board, const std::vector<Vec3>& t_camera_board,
                                      const camera::CameraIntrinsics& intrinsics, const TriangulationChecks& checks) {
  // Remove the worst observation while any exceeds the limit (one bad match pulls the linear
  // solution, so the others may look bad too until it is gone).
  while (track.size() >= 2) {
    const auto X = dlt(track, features, R_camera_board, t_camera_board);
    if (!X) return std::nullopt;
    std::size_t worst = 0;
    double worst_px = -1;
    for (std::size_t k = 0; k < track.size(); ++k) {
      const auto [v, i] = track[k];
      const Vec3 pc = R_camera_board[v] * *X + t_camera_board[v];
      double e = 1e9;
      if (pc.z() > 0)
        if (const auto uv = intrinsics.project(pc)) e = (*uv - features[v].px[i]).norm();
      if (e > worst_px) worst_px = e, worst = k;
    }
    if (worst_px > checks.max_reprojection_px) {
      track.erase(track.begin() + std::ptrdiff_t(worst));
      continue;
    }
    double best = 0;  // largest angle between two rays: a small one leaves depth undetermined
    for (std::size_t a = 0; a < track.size(); ++a) {
      const int va = track[a].first;
      const Vec3 ca = camera::camera_centre(R_camera_board[va], t_camera_board[va]);
      if ((ca - *X).norm() > checks.max_depth_m) return std::nullopt;
      for (std::size_t b = a + 1; b < track.size(); ++b) {
        const int vb = track[b].first;
        const Vec3 cb = camera::camera_centre(R_camera_board[vb], t_camera_board[vb]);
        best = std::max(best, angle_between(ca - *X, cb - *X));
      }
    }
    if (best < checks.min_angle_rad) return std::nullopt;
    return X;
  }
  return std::nullopt;
}

cv::Mat mask_outside_hull(const cv::Size& size, const std::vector<Vec2>& points, double grow_px) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  if (points.size() < 3) return mask;
  std::vector<cv::Point2f> pts;
  for (const auto& p : points) pts.emplace_back(float(p.x()), float(p.y()));
  std::vector<cv::Point2f> hull;
  cv::convexHull(pts, hull);
  // Grow about the centroid so the board's quiet zone and outer squares are covered too.
  cv::Point2f c(0, 0);
  for (const auto& h : hull) c += h;
  c *= 1.0f / float(hull.size());
  std::vector<cv::Point> poly;
  for (const auto& h : hull) {
    const cv::Point2f d = h - c;
    const float n = std::max(1e-3f, std::hypot(d.x, d.y));
    const cv::Point2f g = h + d * float(grow_px / n);
    poly.emplace_back(cvRound(g.x), cvRound(g.y));
  }
  cv::fillConvexPoly(mask, poly, cv::Scalar(0));
  return mask;
}

}  // namespace antpose::reconstruction::detail
