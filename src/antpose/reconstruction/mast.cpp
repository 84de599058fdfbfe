#include "antpose/reconstruction/mast.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <ceres/ceres.h>
#include <opencv2/imgproc.hpp>

#include "antpose/calibration/least_squares.hpp"
#include "antpose/camera/board_pose.hpp"
#include "antpose/camera/edge_search.hpp"
#include "antpose/core/statistics.hpp"

namespace antpose::reconstruction {
namespace {

// Horizontal coordinates: the plane perpendicular to the axis, with an orthonormal basis.
struct Horizontal {
  Vec3 up, e1, e2;
  explicit Horizontal(const Vec3& up_board) : up(up_board.normalized()), e1(up.unitOrthogonal()), e2(up.cross(e1)) {}
  Vec2 of(const Vec3& p) const { return {e1.dot(p), e2.dot(p)}; }
  Vec3 point(const Vec2& h, double height) const { return h.x() * e1 + h.y() * e2 + height * up; }
};

struct Circle {
  Vec2 centre = Vec2::Zero();
  double radius = 0.0;
  double distance(const Vec2& p) const { return std::abs((p - centre).norm() - radius); }
};

// The circle through three points; nullopt when they are (nearly) collinear.
std::optional<Circle> circumcircle(const Vec2& a, const Vec2& b, const Vec2& c) {
  Eigen::Matrix2d A;
  A.row(0) = (b - a).transpose();
  A.row(1) = (c - a).transpose();
  const double det = A.determinant();
  if (std::abs(det) < 1e-12) return std::nullopt;
  const Vec2 rhs(0.5 * (b.squaredNorm() - a.squaredNorm()), 0.5 * (c.squaredNorm() - a.squaredNorm()));
  Circle circle;
  circle.centre = A.inverse() * rhs;
  circle.radius = (a - circle.centre).norm();
  return circle;
}

// Kåsa's algebraic fit: x² + y² + D x + E y + F = 0 by linear least squares.
std::optional<Circle> kasa_fit(const std::vector<Vec2>& pts) {
  if (pts.size() < 3) return std::nullopt;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    A.row(k) << pts[i].x(), pts[i].y(), 1.0;
    y(k) = -pts[i].squaredNorm();
  }
  const Eigen::Vector3d def = A.colPivHouseholderQr().solve(y);
  Circle circle;
  circle.centre = Vec2(-def(0) / 2, -def(1) / 2);
  const double r2 = circle.centre.squaredNorm() - def(2);
  if (!(r2 > 0.0)) return std::nullopt;
  circle.radius = std::sqrt(r2);
  return circle;
}

std::vector<Vec2> inliers_of(const std::vector<Vec2>& pts, const Circle& c, double tolerance) {
  std::vector<Vec2> in;
  for (const auto& p : pts)
    if (c.distance(p) <= tolerance) in.push_back(p);
  return in;
}

// Stage 1: RANSAC over circles, then two least-squares refits on the inliers.
std::optional<Circle> ransac_circle(const std::vector<Vec2>& pts, const MastOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
  std::optional<Circle> best;
  std::size_t best_count = 0;
  for (int it = 0; it < o.ransac_iterations; ++it) {
    const auto c = circumcircle(pts[pick(rng)], pts[pick(rng)], pts[pick(rng)]);
    if (!c || c->radius < o.min_radius_m || c->radius > o.max_radius_m) continue;
    std::size_t count = 0;
    for (const auto& p : pts) count += c->distance(p) <= o.point_tolerance_m;
    if (count > best_count) best_count = count, best = c;
  }
  for (int pass = 0; pass < 2 && best; ++pass) {
    const auto refit = kasa_fit(inliers_of(pts, *best, o.point_tolerance_m));
    if (!refit) break;
    best = refit;
  }
  return best;
}

// A photo's gradients around the mast's outline (camera/edge_search.hpp).
struct EdgeView {
  const PosedView* view = nullptr;
  Vec3 centre_board = Vec3::Zero();
  Vec2 offset = Vec2::Zero();  // crop origin, px
  cv::Mat gx, gy;
  cv::Mat hidden;  // CV_8UC1, non-zero where a known nearer object hides the mast (may be empty)

  bool hides(const Vec2& q_crop) const {
    const int x = static_cast<int>(std::lround(q_crop.x())), y = static_cast<int>(std::lround(q_crop.y()));
    return !hidden.empty() && x >= 0 && y >= 0 && x < hidden.cols && y < hidden.rows && hidden.at<std::uint8_t>(y, x);
  }
};

// An edge found along an outline line: the ray through it (board frame) is tangent to the mast.
struct Tangency {
  Vec3 centre_board, ray_board;
  double px_per_m = 0.0;  // image scale at the mast's distance
  std::size_t view = 0;
  int side = 0;  // which of the photo's two outline lines (tangent_points' order), where confirming
};

struct TangentResidual {
  Vec3 centre, ray, e1, e2, up;
  double px_per_m;
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    using std::abs;
    using std::sqrt;
    const Eigen::Matrix<T, 3, 1> axis_point = p[0] * e1.cast<T>() + p[1] * e2.cast<T>();
    const Vec3 n = ray.cross(up);
    const T distance = abs((centre.cast<T>() - axis_point).dot(n.cast<T>())) / T(n.norm());
    residual[0] = (distance - p[2]) * T(px_per_m);
    return true;
  }
};

// The outline lines' points at heights z (absolute, along up) for a camera at `centre_board`.
std::optional<std::array<Vec2, 2>> tangent_points(const Horizontal& h, const Vec2& axis, double radius,
                                                  const Vec3& centre_board) {
  const Vec2 v = h.of(centre_board) - axis;
  const double d = v.norm();
  if (!(d > radius * 1.001)) return std::nullopt;
  const Vec2 w = v / d, across(-w.y(), w.x());
  const double c = radius / d, s = std::sqrt(1.0 - c * c);
  return std::array<Vec2, 2>{axis + radius * (c * w + s * across), axis + radius * (c * w - s * across)};
}

std::optional<Vec2> project(const camera::CameraIntrinsics& K, const PosedView& v, const Vec3& p_board) {
  return K.project(v.R_camera_board * p_board + v.t_camera_board);
}

// The strongest pair of opposite edges across the mast in one photo: the directional derivative
// along `normal`, averaged over the heights (the mast's edges are parallel to its axis' image),
// at offsets k·step from the line through `anchor` (a point on the mast's seen surface, so the
// mast's image contains offset 0 give or take `slack` px: the points scatter in depth). Returns
// the two offsets (px, sub-pixel), first < second.
std::optional<std::pair<double, double>> edge_pair(const std::vector<double>& profile, double step, double min_width,
                                                   double max_width, double min_gradient, double slack) {
  const int n = static_cast<int>(profile.size()), mid = n / 2;
  const auto peak = [&](int i) {
    return i > 0 && i + 1 < n && std::abs(profile[i]) >= min_gradient &&
           std::abs(profile[i]) >= std::abs(profile[i - 1]) && std::abs(profile[i]) >= std::abs(profile[i + 1]);
  };
  const auto sub = [&](int i) {
    const double a = std::abs(profile[i - 1]), b = std::abs(profile[i]), c = std::abs(profile[i + 1]);
    const double den = a - 2 * b + c;
    return (i - mid + (den < 0 ? std::clamp(0.5 * (a - c) / den, -0.5, 0.5) : 0.0)) * step;
  };
  double best = 0.0;
  std::optional<std::pair<double, double>> pair;
  const int reach = static_cast<int>(std::ceil(slack / step));
  for (int i = 1; i < std::min(n - 1, mid + reach + 1); ++i) {
    if (!peak(i)) continue;
    for (int j = std::max(i + 1, mid - reach); j + 1 < n; ++j) {
      const double width = (j - i) * step;
      if (width > max_width) break;
      if (width < min_width || !peak(j) || profile[i] * profile[j] >= 0.0) continue;
      const double strength = std::abs(profile[i]) + std::abs(profile[j]);
      if (strength > best) best = strength, pair = std::make_pair(sub(i), sub(j));
    }
  }
  return pair;
}

// Stage 1's result: the points on the mast, a point of its seen surface, their height range.
struct SeenPoints {
  Circle circle;               // horizontal
  Vec2 anchor = Vec2::Zero();  // horizontal mean of the points on it
  double low = 0.0, high = 0.0;
  std::size_t count = 0;
};

std::optional<SeenPoints> points_on_mast(const PointCloud& points_board, const Horizontal& h, const MastOptions& o) {
  std::vector<Vec2> flat;
  for (const auto& p : points_board.points) flat.push_back(h.of(p));
  const auto circle = ransac_circle(flat, o);
  if (!circle) return std::nullopt;
  SeenPoints seen;
  seen.circle = *circle;
  seen.low = 1e300, seen.high = -1e300;
  for (std::size_t i = 0; i < flat.size(); ++i)
    if (circle->distance(flat[i]) <= o.point_tolerance_m) {
      const double z = h.up.dot(points_board.points[i]);
      seen.low = std::min(seen.low, z), seen.high = std::max(seen.high, z), ++seen.count;
      seen.anchor += flat[i];
    }
  if (seen.count < o.min_points || seen.high - seen.low < o.min_height_m) return std::nullopt;
  seen.anchor /= static_cast<double>(seen.count);
  return seen;
}

// The mast with its axis through `centre` (horizontal), from height z_low to z_high, placed at the
// middle of the heights its points span; without the photos' confirmation.
Mast cylinder(const Horizontal& h, const SeenPoints& seen, const Vec2& centre, double radius, double z_low,
              double z_high) {
  Mast mast;
  const double z_mid = 0.5 * (seen.low + seen.high);
  mast.axis_point_board = h.point(centre, z_mid);
  mast.up_board = h.up;
  mast.radius_m = radius;
  mast.low_m = z_low - z_mid, mast.high_m = z_high - z_mid;
  mast.points = seen.count;
  return mast;
}

// Stage 2a in one photo: gradients around the line through the anchor over the outline's
// stretch, and the pair of opposite edges across the mast (edge_pair). Adds the edges' tangent
// rays at three heights to `found` and returns the photo's estimate of the axis' place: the ray
// midway between the edges, at r / sin(half-angle) for the radius r its width gives.
struct PhotoEstimate {
  Vec2 camera, middle;  // horizontal: the camera, the ray midway between the edges
  double half_angle = 0.0, radius = 0.0;
};

std::optional<PhotoEstimate> edges_across(EdgeView& ev, std::size_t index, const Horizontal& h, const Vec2& anchor,
                                          double z_low, double z_high, const camera::CameraIntrinsics& K,
                                          const MastOptions& o, std::vector<Tangency>& found) {
  const PosedView& v = *ev.view;
  const double px_per_m = 0.5 * (K.fx + K.fy) / std::max((h.of(ev.centre_board) - anchor).norm(), 0.1);
  const auto a = project(K, v, h.point(anchor, z_low)), b = project(K, v, h.point(anchor, z_high));
  if (!a || !b || (*b - *a).norm() < 4.0) return std::nullopt;
  const Vec2 along = (*b - *a).normalized(), normal(-along.y(), along.x());
  const double reach = 2.0 * o.max_radius_m * px_per_m + 4.0;
  std::vector<cv::Point2f> corners;
  for (const Vec2& q : {*a, *b})
    for (const double k : {-reach - 8.0, reach + 8.0})
      corners.emplace_back(static_cast<float>(q.x() + k * normal.x()), static_cast<float>(q.y() + k * normal.y()));
  const cv::Rect box = cv::boundingRect(corners) & cv::Rect(0, 0, v.image.cols, v.image.rows);
  if (box.width < 8 || box.height < 8) return std::nullopt;
  ev.offset = Vec2(box.x, box.y);
  std::tie(ev.gx, ev.gy) =
      camera::smoothed_gradients(camera::linear_intensity(v.image(box), o.gamma), o.smoothing_sigma_px);
  const double step = 0.5;
  const int half = static_cast<int>(std::ceil(reach / step));
  const int heights = std::max(2, static_cast<int>((*b - *a).norm() / o.sample_spacing_px));
  std::vector<double> profile(static_cast<std::size_t>(2 * half + 1), 0.0);
  for (int j = 0; j < heights; ++j) {
    const Vec2 c = *a + (*b - *a) * ((j + 0.5) / heights) - ev.offset;
    for (int k = -half; k <= half; ++k) {
      const Vec2 z = c + (k * step) * normal;
      profile[static_cast<std::size_t>(k + half)] += camera::gradient_along(ev.gx, ev.gy, z, normal) / heights;
    }
  }
  const auto pair = edge_pair(profile, step, 2 * o.min_radius_m * px_per_m, 2 * o.max_radius_m * px_per_m,
                              o.min_edge_gradient, o.point_tolerance_m * px_per_m + 2.0);
  if (!pair) return std::nullopt;
  const auto horizontal_ray = [&](double offset) {
    return h.of(v.R_camera_board.transpose() * K.ray(0.5 * (*a + *b) + offset * normal)).normalized();
  };
  const Vec2 r1 = horizontal_ray(pair->first), r2 = horizontal_ray(pair->second);
  for (const double offset : {pair->first, pair->second})
    for (const double t : {0.1, 0.5, 0.9})
      found.push_back({ev.centre_board, v.R_camera_board.transpose() * K.ray(*a + (*b - *a) * t + offset * normal),
                       px_per_m, index});
  return PhotoEstimate{h.of(ev.centre_board), (r1 + r2).normalized(),
                       0.5 * std::acos(std::clamp(r1.dot(r2), -1.0, 1.0)),
                       0.5 * (pair->second - pair->first) / px_per_m};
}

// Stage 2b: both outline lines of the cylinder p = (axis x, y, radius) sampled in every photo,
// the nearest edge within ±search_px of each sample; returns how many samples were taken on each.
using SideCounts = std::array<std::size_t, 2>;
SideCounts outline_tangencies(const std::vector<EdgeView>& edge_views, const Horizontal& h, const double* p,
                              double z_low, double z_high, double search_px, const camera::CameraIntrinsics& K,
                              const MastOptions& o, std::vector<Tangency>& found) {
  found.clear();
  SideCounts sampled{};
  std::vector<double> scratch;
  const Vec2 axis(p[0], p[1]);
  for (std::size_t vi = 0; vi < edge_views.size(); ++vi) {
    const auto& ev = edge_views[vi];
    const auto t = tangent_points(h, axis, p[2], ev.centre_board);
    if (!t) continue;
    const double px_per_m = 0.5 * (K.fx + K.fy) / (h.of(ev.centre_board) - axis).norm();
    for (int side = 0; side < 2; ++side) {
      const Vec2& tp = (*t)[static_cast<std::size_t>(side)];
      const auto a = project(K, *ev.view, h.point(tp, z_low)), b = project(K, *ev.view, h.point(tp, z_high));
      if (!a || !b) continue;
      const int n = std::max(2, static_cast<int>((*b - *a).norm() / o.sample_spacing_px));
      const Vec2 along = (*b - *a).normalized(), normal(-along.y(), along.x());
      for (int j = 0; j < n; ++j) {
        const Vec2 q = *a + (*b - *a) * ((j + 0.5) / n);
        const Vec2 in_crop = q - ev.offset;
        // Out of the photo, or where a known nearer object hides the mast: not measurable.
        if (in_crop.x() < 0 || in_crop.y() < 0 || in_crop.x() > ev.gx.cols - 1 || in_crop.y() > ev.gx.rows - 1 ||
            ev.hides(in_crop))
          continue;
        ++sampled[static_cast<std::size_t>(side)];
        const auto edge =
            camera::nearest_edge(ev.gx, ev.gy, q - ev.offset, normal, camera::EdgeSearchSpan::symmetric(search_px),
                                 o.min_edge_gradient, scratch);
        if (edge)
          found.push_back(
              {ev.centre_board, ev.view->R_camera_board.transpose() * K.ray(q + *edge * normal), px_per_m, vi, side});
      }
    }
  }
  return sampled;
}

// A photo's gradients around a cylinder's two outline lines from z_low to z_high, cropped to
// their reach (the largest radius either side) and zeroed on known nearer objects; false where
// the outline falls outside the photo.
bool outline_crop(EdgeView& ev, const Horizontal& h, const Vec2& axis, double z_low, double z_high,
                  const camera::CameraIntrinsics& K, const MastOptions& o,
                  const std::vector<std::vector<cv::Point2f>>& occluders) {
  const PosedView& v = *ev.view;
  const auto a = project(K, v, h.point(axis, z_low)), b = project(K, v, h.point(axis, z_high));
  if (!a || !b || (*b - *a).norm() < 4.0) return false;
  const double px_per_m = 0.5 * (K.fx + K.fy) / std::max((h.of(ev.centre_board) - axis).norm(), 0.1);
  const Vec2 along = (*b - *a).normalized(), normal(-along.y(), along.x());
  const double reach = 2.0 * o.max_radius_m * px_per_m + 4.0 + o.search_px.front();
  std::vector<cv::Point2f> corners;
  for (const Vec2& q : {*a, *b})
    for (const double k : {-reach, reach})
      corners.emplace_back(static_cast<float>(q.x() + k * normal.x()), static_cast<float>(q.y() + k * normal.y()));
  const cv::Rect box = cv::boundingRect(corners) & cv::Rect(0, 0, v.image.cols, v.image.rows);
  if (box.width < 8 || box.height < 8) return false;
  ev.offset = Vec2(box.x, box.y);
  std::tie(ev.gx, ev.gy) =
      camera::smoothed_gradients(camera::linear_intensity(v.image(box), o.gamma), o.smoothing_sigma_px);
  if (occluders.empty()) return true;
  cv::Mat mask = cv::Mat::zeros(box.size(), CV_8UC1);
  for (const auto& poly : occluders) {
    std::vector<cv::Point> q;
    for (const auto& c : poly)
      q.emplace_back(static_cast<int>(std::lround(c.x - box.x)), static_cast<int>(std::lround(c.y - box.y)));
    if (q.size() >= 3) cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{q}, 255);
  }
  // A known object's blurred border would pass for an edge: a few pixels more.
  cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  ev.gx.setTo(0, mask);
  ev.gy.setTo(0, mask);
  ev.hidden = mask;
  return true;
}

// The cylinder p = (axis x, y, radius) tangent to the rays (Ceres, Cauchy loss).
void fit_tangencies(const std::vector<Tangency>& found, const Horizontal& h, const MastOptions& o, double* p) {
  ceres::Problem problem;
  for (const auto& t : found)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<TangentResidual, 1, 3>(
                                 new TangentResidual{t.centre_board, t.ray_board, h.e1, h.e2, h.up, t.px_per_m}),
                             new ceres::CauchyLoss(o.loss_px), p);
  problem.SetParameterLowerBound(p, 2, o.min_radius_m);
  problem.SetParameterUpperBound(p, 2, o.max_radius_m);
  calibration::solve_levenberg_marquardt(problem, 50, 1e-10);
}

}  // namespace

std::optional<Mast> fit_mast(const PointCloud& points_board, const Vec3& up_board, const std::vector<PosedView>& views,
                             const camera::CameraIntrinsics& K, double outline_low_m, double outline_high_m,
                             const MastOptions& o) {
  if (points_board.size() < o.min_points || !(outline_high_m > outline_low_m)) return std::nullopt;
  // Stage 1: the points on the mast, and a point of its seen surface. From 20–30 m they scatter by
  // centimetres over the arc the region shows, so the circle itself is not trusted (a 0.25 m mast
  // came out 0.10 m), only which points lie on it.
  const Horizontal h(up_board);
  const auto seen = points_on_mast(points_board, h, o);
  if (!seen) return std::nullopt;
  const double z_low = outline_low_m, z_high = outline_high_m;

  // Stage 2a: each photo's pair of edges across the mast; the start is the median of the photos'
  // estimates, per coordinate, at their median radius.
  std::vector<EdgeView> edge_views;
  std::vector<Tangency> found;
  std::vector<PhotoEstimate> estimates;
  for (const auto& v : views) {
    EdgeView ev;
    ev.view = &v;
    ev.centre_board = camera::camera_centre(v.R_camera_board, v.t_camera_board);
    const auto estimate = edges_across(ev, edge_views.size(), h, seen->anchor, z_low, z_high, K, o, found);
    if (ev.gx.empty()) continue;
    edge_views.push_back(std::move(ev));
    if (estimate) estimates.push_back(*estimate);
  }
  if (estimates.size() < o.min_views) return std::nullopt;
  std::vector<double> radii, cx, cy;
  for (const auto& e : estimates) radii.push_back(e.radius);
  const double r0 = std::clamp(median(radii), o.min_radius_m, o.max_radius_m);
  for (const auto& e : estimates) {
    const Vec2 c = e.camera + e.middle * (r0 / std::max(std::sin(e.half_angle), 1e-6));
    cx.push_back(c.x()), cy.push_back(c.y());
  }
  double p[3] = {median(cx), median(cy), r0};
  fit_tangencies(found, h, o, p);
  const Mast start = cylinder(h, *seen, Vec2(p[0], p[1]), p[2], std::min(z_low, seen->low - o.extend_m),
                              std::max(z_high, seen->high + o.extend_m));
  return confirm_mast(start, views, K, z_low, z_high, {}, o);
}

std::optional<Mast> confirm_mast(const Mast& start, const std::vector<PosedView>& views,
                                 const camera::CameraIntrinsics& K, double outline_low_m, double outline_high_m,
                                 const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                                 const MastOptions& o) {
  const Horizontal h(start.up_board);
  const double z_low = outline_low_m, z_high = outline_high_m;
  const Vec2 axis0 = h.of(start.axis_point_board);
  double p[3] = {axis0.x(), axis0.y(), start.radius_m};
  // Every photo's gradients around the cylinder's outline, known nearer objects masked.
  std::vector<EdgeView> edge_views;
  const std::vector<std::vector<cv::Point2f>> none;
  for (std::size_t i = 0; i < views.size(); ++i) {
    EdgeView ev;
    ev.view = &views[i];
    ev.centre_board = camera::camera_centre(views[i].R_camera_board, views[i].t_camera_board);
    if (outline_crop(ev, h, axis0, z_low, z_high, K, o, i < occluders.size() ? occluders[i] : none))
      edge_views.push_back(std::move(ev));
  }
  // Every outline sample, the nearest edge within a shrinking range.
  std::vector<Tangency> found;
  SideCounts sampled{};
  for (const double search : o.search_px) {
    sampled = outline_tangencies(edge_views, h, p, z_low, z_high, search, K, o, found);
    if (found.size() < 3) return std::nullopt;
    fit_tangencies(found, h, o, p);
  }
  // Confirmation by the last round's samples.
  std::vector<std::size_t> per_view(edge_views.size(), 0);
  double ss = 0.0;
  SideCounts inliers{};
  for (const auto& t : found) {
    double r = 0.0;
    TangentResidual{t.centre_board, t.ray_board, h.e1, h.e2, h.up, t.px_per_m}(p, &r);
    if (std::abs(r) > 2.0 * o.loss_px) continue;
    ss += r * r, ++inliers[static_cast<std::size_t>(t.side)], ++per_view[t.view];
  }
  Mast mast = start;
  mast.axis_point_board = h.point(Vec2(p[0], p[1]), h.up.dot(start.axis_point_board));
  mast.radius_m = p[2];
  mast.views = static_cast<std::size_t>(std::count_if(per_view.begin(), per_view.end(), [](auto n) { return n >= 5; }));
  mast.edge_samples = inliers[0] + inliers[1];
  mast.edge_rms_px = mast.edge_samples ? std::sqrt(ss / static_cast<double>(mast.edge_samples)) : 0.0;
  // Both lines, each at half the share asked of the two: one line alone is tangent to a whole
  // family of cylinders (the radius traded against the axis' offset), so it fixes none of them.
  const auto share = [&](std::size_t side, double fraction) {
    return static_cast<double>(inliers[side]) >= fraction * static_cast<double>(sampled[side]);
  };
  const bool both_lines = share(0, 0.5 * o.min_edge_fraction) && share(1, 0.5 * o.min_edge_fraction);
  if (mast.views < o.min_views || !both_lines ||
      static_cast<double>(mast.edge_samples) < o.min_edge_fraction * static_cast<double>(sampled[0] + sampled[1]) ||
      mast.edge_rms_px > o.max_rms_px)
    return std::nullopt;
  return mast;
}

std::optional<Mast> mast_from_points(const PointCloud& points_board, const Vec3& up_board, const MastOptions& o) {
  const Horizontal h(up_board);
  const auto seen = points_on_mast(points_board, h, o);
  if (!seen) return std::nullopt;
  return cylinder(h, *seen, seen->circle.centre, seen->circle.radius, seen->low, seen->high);
}

std::array<std::vector<cv::Point2f>, 2> mast_outline(const Mast& mast, const camera::CameraIntrinsics& K,
                                                     const Mat3& R_camera_board, const Vec3& t_camera_board,
                                                     int segments) {
  const Horizontal h(mast.up_board);
  const Vec3 centre = camera::camera_centre(R_camera_board, t_camera_board);
  const double z0 = h.up.dot(mast.axis_point_board);
  const auto t = tangent_points(h, h.of(mast.axis_point_board), mast.radius_m, centre);
  std::array<std::vector<cv::Point2f>, 2> lines;
  if (!t) return lines;
  for (int side = 0; side < 2; ++side)
    for (int j = 0; j <= segments; ++j) {
      const double z = z0 + mast.low_m + (mast.high_m - mast.low_m) * j / segments;
      const auto uv = K.project(R_camera_board * h.point((*t)[side], z) + t_camera_board);
      if (!uv) return {};
      lines[side].emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
    }
  return lines;
}

double distance_from_axis(const Mast& mast, const Vec3& p_board) {
  const Horizontal h(mast.up_board);
  return (h.of(p_board) - h.of(mast.axis_point_board)).norm();
}

bool same_mast(const Mast& a, const Mast& b, const Vec3& p_board, double tolerance_m) {
  const auto on_axis = [&](const Mast& m, double above_m) {
    return Vec3(m.axis_point_board + (m.up_board.dot(p_board - m.axis_point_board) + above_m) * m.up_board);
  };
  const auto end = [](const Mast& m, double along_m) { return m.up_board.dot(m.axis_point_board) + along_m; };
  return (on_axis(a, 0.0) - on_axis(b, 0.0)).norm() <= tolerance_m &&
         (on_axis(a, 1.0) - on_axis(b, 1.0)).norm() <= tolerance_m &&
         std::abs(a.radius_m - b.radius_m) <= tolerance_m &&
         std::abs(end(a, a.low_m) - end(b, b.low_m)) <= tolerance_m &&
         std::abs(end(a, a.high_m) - end(b, b.high_m)) <= tolerance_m;
}

double distance_from_surface(const Mast& mast, const Vec3& p_board) {
  return std::abs(distance_from_axis(mast, p_board) - mast.radius_m);
}

bool on_mast(const Mast& mast, const Vec3& p_board, double clearance_m) {
  const double along = mast.up_board.normalized().dot(p_board - mast.axis_point_board);
  return distance_from_axis(mast, p_board) <= mast.radius_m + clearance_m && along >= mast.low_m - clearance_m &&
         along <= mast.high_m + clearance_m;
}

bool mast_in_front(const Mast& mast, const Vec3& camera_centre_board, const Vec3& p_board) {
  const Horizontal h(mast.up_board);
  const Vec2 c = h.of(camera_centre_board);
  return (c - h.of(mast.axis_point_board)).norm() < (c - h.of(p_board)).norm();
}

}  // namespace antpose::reconstruction
