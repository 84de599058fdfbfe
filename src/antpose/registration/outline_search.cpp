#include "antpose/registration/outline_search.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/registration/pose_selection.hpp"

namespace antpose::registration {
namespace {

// A frame whose z is the board frame's up: the panel's orientations are drawn in it.
Mat3 level_frame(const Vec3& up_board) {
  const Vec3 z = up_board.normalized();
  const Vec3 x = z.unitOrthogonal();
  Mat3 R;
  R << x, z.cross(x), z;
  return R;
}

// The orientations of the file comment, R_board_antenna, yaw over 180°.
std::vector<Mat3> hanging_orientations(const Vec3& up_board, const OutlineSearchOptions& o) {
  const Mat3 R_board_level = level_frame(up_board);
  std::vector<Mat3> out;
  const int yaws = std::max(1, static_cast<int>(std::lround(180.0 / o.yaw_step_deg)));
  for (int k = 0; k < yaws; ++k)
    for (const double tilt : o.tilt_deg)
      for (const double roll : o.roll_deg)
        out.push_back(R_board_level * rot_z(-deg2rad(k * 180.0 / yaws)) * rot_x(-deg2rad(tilt)) * rot_y(deg2rad(roll)));
  return out;
}

// The box's corners in the board frame at a pose.
std::array<Vec3, 8> corners(const Vec3& size_m, const Mat3& R_board_antenna, const Vec3& p_board) {
  std::array<Vec3, 8> c;
  for (int i = 0; i < 8; ++i)
    c[static_cast<std::size_t>(i)] =
        p_board + R_board_antenna * Vec3((i & 1 ? 0.5 : -0.5) * size_m.x(), (i & 2 ? 0.5 : -0.5) * size_m.y(),
                                         (i & 4 ? 0.5 : -0.5) * size_m.z());
  return c;
}

struct Probe {
  Vec3 p_board = Vec3::Zero();
  double cost = 1.0;
  std::size_t views = 0;
};

// The box's centre on the rectangle's centre ray at the depth where the box at R_board_antenna
// spans `fill` of the rectangle's larger side: the projection's size goes as 1/depth, refined
// twice for perspective. Also the projected larger side there (px).
std::optional<std::pair<Vec3, double>> filling_start(const OutlineSearchInput& in, const camera::CameraIntrinsics& K,
                                                     const Mat3& R, double fill) {
  const auto& view = (*in.views)[in.region_view];
  const cv::Rect& roi = *in.roi;
  const Vec3 ray = K.ray(Vec2(roi.x + 0.5 * roi.width - 0.5, roi.y + 0.5 * roi.height - 0.5));
  const double target = fill * std::max(roi.width, roi.height);
  const Mat3 R_board_camera = view.R_camera_board.transpose();
  const auto centre_at = [&](double depth) {
    return Vec3(R_board_camera * (ray / ray.z() * depth - view.t_camera_board));
  };
  double depth = K.fx * in.box_size_m.z() / target, size = target;
  for (int k = 0; k < 3; ++k) {
    Eigen::AlignedBox2d box;
    for (const Vec3& c : corners(in.box_size_m, R, centre_at(depth))) {
      const auto uv = K.project(view.R_camera_board * c + view.t_camera_board);
      if (!uv) return std::nullopt;
      box.extend(*uv);
    }
    size = box.sizes().maxCoeff();
    if (!(size > 0)) return std::nullopt;
    depth *= size / target;
  }
  return std::pair{centre_at(depth), size};
}

// How much of the rectangle the antenna fills is the user's habit: from all of its larger side
// down to the least that still spans `min_roi_span` of it. The box's centre is swept along the
// rectangle's centre ray over those depths, each step moving the box's ends by about the
// chamfer's truncation (so that no depth falls between two samples' basins), and the best start
// kept: a single guessed fill leaves a long box's ends outside the truncation, with no gradient.
std::optional<Vec3> swept_start(const BoxOutlineCost& cost, const OutlineSearchInput& in,
                                const camera::CameraIntrinsics& K, const Mat3& R, const OutlineSearchOptions& o,
                                std::size_t& evaluations) {
  const auto full = filling_start(in, K, R, 1.0);
  if (!full) return std::nullopt;
  const double length_map_px = full->second * cost.map_scale();
  const double least = in.min_roi_span;
  const double ratio = std::max(1.0 + 2.0 * o.truncation_px / std::max(1.0, length_map_px),
                                std::pow(1.0 / least, 1.0 / static_cast<double>(o.max_depth_starts)));
  std::optional<Vec3> best;
  double best_cost = 2.0;
  for (double fill = 1.0; fill >= least; fill /= ratio) {
    const auto start = filling_start(in, K, R, fill);
    if (!start) continue;
    Iso3 T = Iso3::Identity();
    T.linear() = R, T.translation() = start->first;
    ++evaluations;
    if (const double c = cost(T).first; c < best_cost) best_cost = c, best = start->first;
  }
  return best;
}

// The compass search for the box's centre at one orientation: steps along the region photo's
// image axes and its line of sight, each halved when no move along it lowers the cost.
Probe place_box(const BoxOutlineCost& cost, const Mat3& R, const Vec3& start, const Mat3& R_board_camera,
                const Vec3& step0, const Vec3& step_min, std::size_t& evaluations) {
  const auto eval = [&](const Vec3& p) {
    ++evaluations;
    Iso3 T = Iso3::Identity();
    T.linear() = R, T.translation() = p;
    const auto [c, views] = cost(T);
    return Probe{p, c, views};
  };
  Probe best = eval(start);
  Vec3 step = step0;
  while ((step.array() >= step_min.array()).any()) {
    bool moved = false;
    for (int axis = 0; axis < 3; ++axis) {
      if (step[axis] < step_min[axis]) continue;
      for (const double sign : {1.0, -1.0}) {
        const Probe p = eval(best.p_board + sign * step[axis] * R_board_camera.col(axis));
        if (p.cost < best.cost) {
          best = p, moved = true;
          break;
        }
      }
    }
    if (!moved) step /= 2.0;
  }
  return best;
}

// The compass search of place_box over the orientation too: turns about the box's own axes
// (yaw about its long axis first: the least fixed), each step halved when no move along it
// lowers the cost; the grid's candidate refined between the grid's orientations.
Probe polish_box(const BoxOutlineCost& cost, Iso3& T, const Mat3& R_board_camera, const Vec3& step_m,
                 const Vec3& step_min_m, double step_rad, double step_min_rad, std::size_t& evaluations) {
  const auto eval = [&](const Iso3& U) {
    ++evaluations;
    const auto [c, views] = cost(U);
    return Probe{U.translation(), c, views};
  };
  Probe best = eval(T);
  Vec3 step = step_m;
  // About z (the yaw), y (the roll) and x (the tilt): the yaw in full steps, the others in halves.
  Vec3 turn(step_rad, step_rad / 2, step_rad / 2);
  const Vec3 turn_min(step_min_rad, step_min_rad / 2, step_min_rad / 2);
  while ((step.array() >= step_min_m.array()).any() || (turn.array() >= turn_min.array()).any()) {
    bool moved = false;
    for (int axis = 0; axis < 6 && !moved; ++axis) {
      const bool rotation = axis >= 3;
      const int k = axis % 3;
      if (rotation ? turn[k] < turn_min[k] : step[k] < step_min_m[k]) continue;
      for (const double sign : {1.0, -1.0}) {
        Iso3 U = T;
        if (rotation)
          U.linear() = T.linear() * Eigen::AngleAxisd(sign * turn[k], Vec3::Unit(2 - k)).toRotationMatrix();
        else
          U.translation() += sign * step[k] * R_board_camera.col(k);
        const Probe p = eval(U);
        if (p.cost < best.cost) {
          best = p, T = U, moved = true;
          break;
        }
      }
    }
    if (!moved) step /= 2.0, turn /= 2.0;
  }
  return best;
}

}  // namespace

OptionProblems OutlineSearchOptions::Check() const {
  OptionProblems p;
  p.require(map_width_px >= 4, "map_width_px", "at least 4");
  p.require(yaw_step_deg > 0 && yaw_step_deg <= 90, "yaw_step_deg", "in (0, 90]");
  p.require(!tilt_deg.empty() && !roll_deg.empty(), "tilt_deg, roll_deg", "at least one value each");
  p.require(truncation_px > 0, "truncation_px", "positive");
  p.require(min_measured_share > 0 && min_measured_share <= 1, "min_measured_share", "in (0, 1]");
  p.require(min_views >= 1, "min_views", "at least 1");
  p.require(separation_deg >= 0, "separation_deg", "≥ 0");
  p.require(max_candidates >= 1, "max_candidates", "at least 1");
  p.require(max_depth_starts >= 1, "max_depth_starts", "at least 1");
  p.require(min_step_map_px > 0 && min_turn_deg > 0, "min_step_map_px, min_turn_deg", "positive");
  p.nest("edges", edges.Check());
  return p;
}

BoxOutlineCost::BoxOutlineCost(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                               const OutlineSearchOptions& options)
    : input_(input), intrinsics_(intrinsics), options_(options) {
  if (!input.views || input.views->empty()) throw std::invalid_argument("search_box_outline: no views");
  if (!(input.box_size_m.array() > 0).all()) throw std::invalid_argument("search_box_outline: a non-positive box");
  if (input.areas.size() != input.views->size())
    throw std::invalid_argument("search_box_outline: one area per view expected");
  scale_ = std::min(1.0, options.map_width_px / std::max(1.0, input.expected_width_px));
  maps_.resize(input.views->size(), EdgeDistance(cv::Mat(), {}, 1.0, {}, options.edges));
  cv::parallel_for_(cv::Range(0, static_cast<int>(maps_.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto& v = (*input.views)[static_cast<std::size_t>(i)];
      if (const auto& area = input.areas[static_cast<std::size_t>(i)])
        maps_[static_cast<std::size_t>(i)] = EdgeDistance(v.image, *area, scale_, v.occluders, options.edges);
    }
  });
}

double BoxOutlineCost::view_cost(std::size_t v, const std::array<Vec3, 8>& corners_board, bool& counted) const {
  counted = false;
  const auto& view = (*input_.views)[v];
  const EdgeDistance& map = maps_[v];
  std::vector<cv::Point2f> projected;
  for (const Vec3& c : corners_board) {
    const auto uv = intrinsics_.project(view.R_camera_board * c + view.t_camera_board);
    if (!uv) return 1.0;
    projected.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(projected, hull, true);  // clockwise in image coordinates (y down)
  const double spacing = 1.0 / map.scale();
  const double tau2 = options_.truncation_px * options_.truncation_px;
  double sum = 0.0;
  std::size_t measured = 0, samples = 0;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const Vec2 a(hull[k].x, hull[k].y), b(hull[(k + 1) % hull.size()].x, hull[(k + 1) % hull.size()].y);
    const double length = (b - a).norm();
    if (length < 1e-9) continue;
    const Vec2 along = (b - a) / length, normal(-along.y(), along.x());
    const int n = std::max(1, static_cast<int>(length / spacing));
    const int bin = map.bin(normal);
    for (int j = 0; j < n; ++j) {
      ++samples;
      EdgeLookup status;
      const double d = map.distance(a + (j + 0.5) / n * (b - a), bin, status);
      if (status == EdgeLookup::kMasked) continue;
      ++measured;
      sum += status == EdgeLookup::kOutside ? 1.0 : std::min(d * d, tau2) / tau2;
    }
  }
  counted = samples > 0 && measured >= options_.min_measured_share * static_cast<double>(samples);
  return measured ? sum / static_cast<double>(measured) : 1.0;
}

bool BoxOutlineCost::fits_rectangle(const Iso3& T_board_antenna) const {
  if (!input_.roi) return true;
  const auto fit =
      roi_span(input_.box_size_m, T_board_antenna, (*input_.views)[input_.region_view], intrinsics_, *input_.roi);
  return fit.centred && fit.span >= input_.min_roi_span;
}

std::pair<double, std::size_t> BoxOutlineCost::operator()(const Iso3& T_board_antenna) const {
  if (!fits_rectangle(T_board_antenna)) return {1.0, 0};
  const auto c = corners(input_.box_size_m, T_board_antenna.linear(), T_board_antenna.translation());
  double sum = 0.0;
  std::size_t views = 0;
  for (std::size_t v = 0; v < maps_.size(); ++v) {
    if (!input_.areas[v]) continue;
    bool counted = false;
    const double cost = view_cost(v, c, counted);
    if (counted) sum += cost, ++views;
  }
  if (views < options_.min_views) return {1.0, views};
  return {sum / static_cast<double>(views), views};
}

namespace {

// Steps as image motion in the region photo's maps: a few map pixels laterally to start; along the
// line of sight the same motion of the box's edges takes depth/width times more.
Probe place_from(const BoxOutlineCost& cost, const OutlineSearchInput& in, const Mat3& R, const Vec3& start,
                 const OutlineSearchOptions& o, std::size_t& evaluations) {
  const auto& region = (*in.views)[in.region_view];
  const double map_px_m = in.box_size_m.x() / o.map_width_px;  // metres per map pixel at the box
  const double depth = std::max(0.5, (region.R_camera_board * start + region.t_camera_board).z());
  const double depth_per_width = depth / in.box_size_m.x();
  const Vec3 step0(4 * map_px_m, 4 * map_px_m, 0.1 * depth);
  const Vec3 step_min(o.min_step_map_px * map_px_m, o.min_step_map_px * map_px_m,
                      std::min(0.05 * depth, o.min_step_map_px * map_px_m * depth_per_width));
  return place_box(cost, R, start, region.R_camera_board.transpose(), step0, step_min, evaluations);
}

// Between the grid's orientations: each candidate polished over all six degrees of freedom, from
// half a grid step down to `min_turn_deg`; best first.
void polish_all(const BoxOutlineCost& cost, const OutlineSearchInput& in, const OutlineSearchOptions& o,
                OutlineSearchResult& out) {
  const auto& region = (*in.views)[in.region_view];
  const double map_px = in.box_size_m.x() / o.map_width_px;
  std::vector<std::size_t> evaluations(out.candidates.size(), 0);
  cv::parallel_for_(cv::Range(0, static_cast<int>(out.candidates.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      auto& c = out.candidates[static_cast<std::size_t>(i)];
      const double depth =
          std::max(0.5, (region.R_camera_board * c.T_board_antenna.translation() + region.t_camera_board).z());
      const Probe p = polish_box(cost, c.T_board_antenna, region.R_camera_board.transpose(),
                                 Vec3(map_px, map_px, 0.02 * depth), Vec3::Constant(o.min_step_map_px * map_px),
                                 deg2rad(o.yaw_step_deg / 2), deg2rad(o.min_turn_deg),
                                 evaluations[static_cast<std::size_t>(i)]);
      c.cost = p.cost, c.views = p.views;
    }
  });
  for (const auto e : evaluations) out.evaluations += e;
  std::stable_sort(out.candidates.begin(), out.candidates.end(),
                   [](const OutlineCandidate& a, const OutlineCandidate& b) { return a.cost < b.cost; });
}

void check_input(const OutlineSearchInput& input, const OutlineSearchOptions& options, const char* caller) {
  throw_unless_ok(options.Check(), "OutlineSearchOptions");
  if (input.views && input.region_view >= input.views->size())
    throw std::invalid_argument(std::string(caller) + ": the region view is out of range");
  if (input.roi && !(input.min_roi_span > 0 && input.min_roi_span <= 1))
    throw std::invalid_argument(std::string(caller) + ": min_roi_span must lie in (0, 1]");
}

}  // namespace

RectangleFit rectangle_fit(const Eigen::AlignedBox2d& projected_px, const cv::Rect& roi) {
  const Eigen::AlignedBox2d rect(Vec2(roi.x - 0.5, roi.y - 0.5),
                                 Vec2(roi.x + roi.width - 0.5, roi.y + roi.height - 0.5));
  const Eigen::AlignedBox2d cut = projected_px.intersection(rect);
  if (cut.isEmpty()) return {0.0, false};
  const int along = roi.width >= roi.height ? 0 : 1;
  return {cut.sizes()[along] / rect.sizes()[along], rect.contains(projected_px.center())};
}

RectangleFit roi_span(const Vec3& size_m, const Iso3& T_board_antenna, const SilhouetteView& view,
                      const camera::CameraIntrinsics& K, const cv::Rect& roi) {
  Eigen::AlignedBox2d box;
  for (const Vec3& c : corners(size_m, T_board_antenna.linear(), T_board_antenna.translation())) {
    const auto uv = K.project(view.R_camera_board * c + view.t_camera_board);
    if (!uv) return {};
    box.extend(*uv);
  }
  return rectangle_fit(box, roi);
}

OutlineSearchResult search_box_outline(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                                       const OutlineSearchOptions& options) {
  check_input(input, options, "search_box_outline");
  const BoxOutlineCost cost(input, intrinsics, options);
  const auto orientations = hanging_orientations(input.up_board, options);
  // Every orientation from every start: the given ones, and the one swept along the rectangle's
  // centre ray (nullopt here).
  std::vector<std::pair<std::size_t, std::optional<Vec3>>> tasks;
  for (std::size_t o = 0; o < orientations.size(); ++o) {
    for (const Vec3& start : input.starts_board) tasks.emplace_back(o, start);
    if (input.roi) tasks.emplace_back(o, std::nullopt);
  }
  std::vector<Probe> best(tasks.size());
  std::vector<std::size_t> evaluations(tasks.size(), 0);
  cv::parallel_for_(cv::Range(0, static_cast<int>(tasks.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Mat3& R = orientations[tasks[k].first];
      const auto start =
          tasks[k].second ? tasks[k].second : swept_start(cost, input, intrinsics, R, options, evaluations[k]);
      if (start) best[k] = place_from(cost, input, R, *start, options, evaluations[k]);
    }
  });
  OutlineSearchResult out;
  for (const auto e : evaluations) out.evaluations += e;
  std::vector<std::size_t> order(best.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return best[a].cost < best[b].cost; });
  for (const std::size_t i : order) {
    if (out.candidates.size() >= options.max_candidates || best[i].views < options.min_views) break;
    const Mat3& R = orientations[tasks[i].first];
    // Apart: at another orientation, or elsewhere (another object the search settled on).
    const double elsewhere_m = input.box_size_m.head<2>().maxCoeff();
    const bool apart = std::all_of(out.candidates.begin(), out.candidates.end(), [&](const OutlineCandidate& c) {
      return rad2deg(box_angle(c.T_board_antenna.linear(), R)) >= options.separation_deg ||
             (c.T_board_antenna.translation() - best[i].p_board).norm() >= elsewhere_m;
    });
    if (!apart) continue;
    OutlineCandidate c;
    c.T_board_antenna.linear() = R;
    c.T_board_antenna.translation() = best[i].p_board;
    c.cost = best[i].cost, c.views = best[i].views;
    out.candidates.push_back(c);
  }
  polish_all(cost, input, options, out);
  return out;
}

OutlineSearchResult place_box_outlines(const OutlineSearchInput& input, const camera::CameraIntrinsics& intrinsics,
                                       const OutlineSearchOptions& options, const std::vector<Iso3>& starts) {
  check_input(input, options, "place_box_outlines");
  const BoxOutlineCost cost(input, intrinsics, options);
  OutlineSearchResult out;
  out.candidates.resize(starts.size());
  std::vector<std::size_t> evaluations(starts.size(), 0);
  cv::parallel_for_(cv::Range(0, static_cast<int>(starts.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Mat3 R = starts[k].linear();
      const Probe p = place_from(cost, input, R, starts[k].translation(), options, evaluations[k]);
      out.candidates[k].T_board_antenna.linear() = R;
      out.candidates[k].T_board_antenna.translation() = p.p_board;
      out.candidates[k].cost = p.cost, out.candidates[k].views = p.views;
    }
  });
  for (const auto e : evaluations) out.evaluations += e;
  polish_all(cost, input, options, out);
  return out;
}

}  // namespace antpose::registration
