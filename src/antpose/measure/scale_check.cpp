#include "antpose/measure/scale_check.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/geometry/point_cloud.hpp"

namespace antpose::measure {

OptionProblems ScaleCheckOptions::Check() const {
  OptionProblems p;
  p.require(max_median_speed_m_s > 0, "max_median_speed_m_s", "positive");
  p.require(min_interval_s >= 0, "min_interval_s", "not negative");
  p.require(max_extent_ratio > 1, "max_extent_ratio", "over 1");
  return p;
}

WalkScale check_walk_scale(const Capture& capture, const CameraPoses& poses, const camera::BoardSpec& board,
                           const ScaleCheckOptions& options) {
  throw_unless_ok(options.Check(), "ScaleCheckOptions");
  struct Stop {
    double t;
    Vec3 centre_board;
  };
  std::vector<Stop> stops;
  for (std::size_t v = 0; v < poses.views.size(); ++v) {
    const auto& view = poses.views[v];
    stops.push_back(
        {capture.shots[poses.shot_of_view[v]].t, camera::camera_centre(view.R_camera_board, view.t_camera_board)});
  }
  std::sort(stops.begin(), stops.end(), [](const Stop& a, const Stop& b) { return a.t < b.t; });
  std::vector<double> speeds;
  for (std::size_t i = 1; i < stops.size(); ++i)
    if (const double dt = stops[i].t - stops[i - 1].t; dt >= options.min_interval_s)
      speeds.push_back((stops[i].centre_board - stops[i - 1].centre_board).norm() / dt);
  WalkScale out;
  if (speeds.size() < 2) return out;
  out.median_speed_m_s = median(speeds);
  if (*out.median_speed_m_s > options.max_median_speed_m_s)
    out.warning = fmt::format(
        "by the board's size the phone moved at a median {:.1f} m/s between photos, faster than a person framing "
        "photos walks (limit {:.1f} m/s): check square_m ({} m in board.yaml) against the printed board, since "
        "every length of the measurement scales with it",
        *out.median_speed_m_s, options.max_median_speed_m_s, board.square_m);
  return out;
}

std::optional<std::string> model_scale_hint(const std::vector<Vec3>& points_board, const model::AntennaModel& model,
                                            const camera::BoardSpec& board, const ScaleCheckOptions& options) {
  throw_unless_ok(options.Check(), "ScaleCheckOptions");
  if (points_board.size() < 10) return std::nullopt;
  const Vec3 mean = centroid(points_board);
  Mat3 scatter = Mat3::Zero();
  for (const Vec3& p : points_board) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> es(scatter);
  const Vec3 axis = es.eigenvectors().col(2);  // the points' main axis
  std::vector<double> along;
  for (const Vec3& p : points_board) along.push_back(axis.dot(p - mean));
  // 2nd to 98th percentile: a few stray points do not set the extent.
  const double extent_m = quantile(along, 0.98) - quantile(along, 0.02);
  const double model_m = model.size_m.maxCoeff();
  if (!(extent_m > 0) || !(model_m > 0)) return std::nullopt;
  const double ratio = extent_m / model_m;
  if (ratio <= options.max_extent_ratio && ratio >= 1.0 / options.max_extent_ratio) return std::nullopt;
  return fmt::format(
      "the points in the rectangle span {:.2f} m where the model is {:.2f} m long ({:.2f}×): if the board's "
      "square_m ({} m in board.yaml) or the model's size is wrong, every length is off by such a factor",
      extent_m, model_m, ratio, board.square_m);
}

}  // namespace antpose::measure
