#include "antpose/reconstruction/mast_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <opencv2/core/utility.hpp>

#include "antpose/camera/board_pose.hpp"

namespace antpose::reconstruction {
namespace {

// The frame of the search: the vertical through the panel's centre, with a horizontal basis.
struct Vertical {
  Vec3 up, e1, e2, centre;
  Vec3 point(double x, double y, double height) const { return centre + x * e1 + y * e2 + height * up; }
};

struct Cylinder {
  double x = 0, y = 0, radius = 0;  // axis offset from the panel's centre (e1, e2), m
  double cost = 1.0;
  std::vector<double> view_costs;  // NaN where a photo shows too little of its outline
};

// The outline lines of a vertical cylinder seen from `camera` (board frame): where the horizontal
// lines of sight graze its circle; nullopt with the camera inside it.
std::optional<std::array<Vec2, 2>> grazing(const Vec2& axis, double radius, const Vec2& camera) {
  const Vec2 v = camera - axis;
  const double d = v.norm();
  if (!(d > radius * 1.001)) return std::nullopt;
  const Vec2 w = v / d, across(-w.y(), w.x());
  const double c = radius / d, s = std::sqrt(1.0 - c * c);
  return std::array<Vec2, 2>{axis + radius * (c * w + s * across), axis + radius * (c * w - s * across)};
}

class CylinderCost {
 public:
  CylinderCost(const std::vector<PosedView>& views, const camera::CameraIntrinsics& K, const Vertical& frame,
               const std::array<std::pair<double, double>, 2>& stretches, std::vector<registration::EdgeDistance> maps,
               const MastSearchOptions& o)
      : views_(views), K_(K), frame_(frame), stretches_(stretches), maps_(std::move(maps)), o_(o) {
    for (const auto& v : views) {
      const Vec3 c = camera::camera_centre(v.R_camera_board, v.t_camera_board) - frame.centre;
      cameras_.emplace_back(c.dot(frame.e1), c.dot(frame.e2));
    }
  }

  // The mean truncated chamfer cost of the outline lines in each photo that shows enough of them,
  // and over those photos (1 where fewer than min_views do).
  void operator()(Cylinder& c) const {
    double sum = 0.0;
    std::size_t views = 0;
    c.view_costs.assign(views_.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < views_.size(); ++i) {
      double view_sum = 0.0;
      std::size_t measured = 0;
      if (const auto lines = grazing(Vec2(c.x, c.y), c.radius, cameras_[i]))
        for (const Vec2& g : *lines)
          for (const auto& [low, high] : stretches_) add_line(i, g, low, high, view_sum, measured);
      if (measured < 8) continue;
      c.view_costs[i] = view_sum / static_cast<double>(measured);
      sum += c.view_costs[i], ++views;
    }
    c.cost = views >= o_.min_views ? sum / static_cast<double>(views) : 1.0;
  }

 private:
  void add_line(std::size_t i, const Vec2& g, double low, double high, double& sum, std::size_t& measured) const {
    if (!(high > low)) return;  // an empty stretch (none below the panel above the ground)
    const auto& v = views_[i];
    const auto a = K_.project(v.R_camera_board * frame_.point(g.x(), g.y(), low) + v.t_camera_board);
    const auto b = K_.project(v.R_camera_board * frame_.point(g.x(), g.y(), high) + v.t_camera_board);
    if (!a || !b) return;
    const auto& map = maps_[i];
    const double length = (*b - *a).norm();
    const int n = std::max(2, static_cast<int>(length * map.scale()));
    const Vec2 along = (*b - *a) / std::max(length, 1e-9);
    const int bin = map.bin(Vec2(-along.y(), along.x()));
    const double tau2 = o_.truncation_px * o_.truncation_px;
    for (int j = 0; j < n; ++j) {
      registration::EdgeLookup status;
      const double d = map.distance(*a + (*b - *a) * ((j + 0.5) / n), bin, status);
      if (status != registration::EdgeLookup::kMeasured) continue;
      sum += std::min(d * d, tau2) / tau2, ++measured;
    }
  }

  const std::vector<PosedView>& views_;
  const camera::CameraIntrinsics& K_;
  Vertical frame_;
  std::array<std::pair<double, double>, 2> stretches_;
  std::vector<registration::EdgeDistance> maps_;
  const MastSearchOptions& o_;
  std::vector<Vec2> cameras_;
};

// The maps of the region the search looks at in each photo: the disk of axes over both stretches.
std::vector<registration::EdgeDistance> search_maps(const std::vector<PosedView>& views,
                                                    const camera::CameraIntrinsics& K, const Vertical& f, double low,
                                                    double high,
                                                    const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                                                    const MastSearchOptions& o) {
  std::vector<registration::EdgeDistance> maps(views.size(),
                                               registration::EdgeDistance(cv::Mat(), {}, 1.0, {}, o.edges));
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      const auto& v = views[static_cast<std::size_t>(i)];
      Eigen::AlignedBox2d box;
      for (const double x : {-o.reach_m, o.reach_m})
        for (const double y : {-o.reach_m, o.reach_m})
          for (const double z : {low, high})
            if (const auto uv = K.project(v.R_camera_board * f.point(x, y, z) + v.t_camera_board)) box.extend(*uv);
      if (box.isEmpty()) continue;
      const double depth = (v.R_camera_board * f.centre + v.t_camera_board).z();
      const double thinnest_px = 2 * o.radii_m.front() * 0.5 * (K.fx + K.fy) / std::max(depth, 0.1);
      const double scale = std::clamp(o.min_diameter_map_px / thinnest_px, 0.1, 1.0);
      const cv::Rect area(static_cast<int>(box.min().x()), static_cast<int>(box.min().y()),
                          static_cast<int>(box.sizes().x()) + 1, static_cast<int>(box.sizes().y()) + 1);
      const auto& occ = static_cast<std::size_t>(i) < occluders.size() ? occluders[static_cast<std::size_t>(i)]
                                                                       : std::vector<std::vector<cv::Point2f>>{};
      maps[static_cast<std::size_t>(i)] = registration::EdgeDistance(v.image, area, scale, occ, o.edges);
    }
  });
  return maps;
}

}  // namespace

OptionProblems MastSearchOptions::Check() const {
  OptionProblems p;
  p.require(reach_m > 0 && step_m > 0 && step_m < reach_m, "reach_m, step_m", "0 < step < reach");
  p.require(!radii_m.empty() && radii_m.front() > 0, "radii_m", "positive radii, smallest first");
  p.require(below_m >= 0 && above_m >= 0 && below_m + above_m > 0, "below_m, above_m", "≥ 0, not both 0");
  p.require(hand_height_m >= 0, "hand_height_m", "≥ 0");
  p.require(truncation_px > 0 && min_diameter_map_px > 0, "truncation_px, min_diameter_map_px", "positive");
  p.require(min_views >= 2 && confirm >= 1, "min_views, confirm", "at least 2 and 1");
  p.require(refine_evaluations >= 0, "refine_evaluations", "≥ 0");
  p.nest("edges", edges.Check());
  return p;
}

namespace {

// The grid of the file comment, every cylinder scored, best first.
struct Grid {
  Vertical frame;
  double low = 0, high = 0;  // the stretch searched, heights along up from the panel's centre
  double footprint = 0;      // the panel's horizontal half-diagonal
  std::vector<Cylinder> cylinders;
  std::unique_ptr<const CylinderCost> cost;  // built with the maps; it holds references, so is not assignable
};

// Whether a cylinder lies where the grid's may: outside the panel's footprint, within reach, its
// radius within the grid's.
bool in_search(const Grid& g, const Cylinder& c, const MastSearchOptions& o) {
  const double d = std::hypot(c.x, c.y);
  return d <= o.reach_m && d > g.footprint + c.radius && c.radius >= o.radii_m.front() && c.radius <= o.radii_m.back();
}

// The grid scored over the stretches below and above the panel, and beside it where
// `beside_panel`; nullopt where none of them lies above the ground.
std::optional<Grid> score_grid(const std::vector<PosedView>& views, const camera::CameraIntrinsics& K,
                               const Vec3& up_board, const Iso3& T_board_panel, const Vec3& size,
                               const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders, bool beside_panel,
                               const MastSearchOptions& o) {
  Grid g;
  Vertical& f = g.frame;
  f.up = up_board.normalized(), f.e1 = f.up.unitOrthogonal(), f.e2 = f.up.cross(f.e1);
  f.centre = T_board_panel.translation();
  // The panel's ends along the vertical (its box's corners), and the stretches clear of them.
  double bottom = 1e300, top = -1e300;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(), (i & 4 ? 0.5 : -0.5) * size.z());
    const double z = f.up.dot(T_board_panel.linear() * c);
    bottom = std::min(bottom, z), top = std::max(top, z);
  }
  // Not below the ground the photographer stood on: phones are held at least `hand_height_m` above
  // it, and a mast ends where its roof or ground begins.
  double lowest_camera = 1e300;
  for (const auto& v : views)
    lowest_camera =
        std::min(lowest_camera, f.up.dot(camera::camera_centre(v.R_camera_board, v.t_camera_board) - f.centre));
  // A panel may hang with its foot near the roof the photos were taken from: then only the stretch
  // above it (and beside it) shows its mount.
  const double ground = lowest_camera - o.hand_height_m;
  const std::pair<double, double> below{std::max(bottom - o.below_m, ground), bottom - o.gap_m};
  const std::pair<double, double> upper{beside_panel ? std::max(bottom - o.gap_m, ground) : top + o.gap_m,
                                        top + o.above_m};
  const bool any_below = below.first < below.second;
  if (!any_below && !(upper.first < upper.second)) return std::nullopt;
  g.low = any_below ? below.first : upper.first, g.high = upper.second;
  const std::array<std::pair<double, double>, 2> stretches{below, upper};
  g.cost = std::make_unique<const CylinderCost>(views, K, f, stretches,
                                                search_maps(views, K, f, g.low, g.high, occluders, o), o);
  const CylinderCost& cost = *g.cost;
  // Axes outside the panel's footprint (its horizontal half-diagonal) and within reach.
  g.footprint = 0.5 * size.head<2>().norm();
  for (double x = -o.reach_m; x <= o.reach_m; x += o.step_m)
    for (double y = -o.reach_m; y <= o.reach_m; y += o.step_m)
      for (const double r : o.radii_m) {
        Cylinder c;
        c.x = x, c.y = y, c.radius = r;
        if (in_search(g, c, o)) g.cylinders.push_back(c);
      }
  cv::parallel_for_(cv::Range(0, static_cast<int>(g.cylinders.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) cost(g.cylinders[static_cast<std::size_t>(i)]);
  });
  std::sort(g.cylinders.begin(), g.cylinders.end(),
            [](const Cylinder& a, const Cylinder& b) { return a.cost < b.cost; });
  return g;
}

// A grid cylinder moved to the nearest minimum of its cost by a pattern search (Hooke & Jeeves
// 1961) over the axis' offset and the radius, from half the grid's step to a sixteenth, where
// `allowed`. The grid alone leaves an axis up to step/√2 and a radius up to half its spacing off:
// more than the chamfer's truncation at the map's scale, so a pole between the grid's nodes would
// score no better than clutter. The moves are the 26 neighbours in (x, y, radius), not the axes
// alone: a photo's two outline lines lie at the axis' offset ∓ the radius, and a line that lies
// right stays there only where the offset and the radius move together.
template <class Allowed>
Cylinder refined(Cylinder c, const CylinderCost& cost, const Allowed& allowed, const MastSearchOptions& o) {
  double step = o.step_m / 2;
  for (int evaluations = 0; step >= o.step_m / 16 && evaluations < o.refine_evaluations;) {
    Cylinder best = c;
    for (int move = 0; move < 27; ++move) {
      if (move == 13) continue;  // (0, 0, 0)
      Cylinder t = c;
      t.x += step * (move % 3 - 1), t.y += step * (move / 3 % 3 - 1), t.radius += step * (move / 9 - 1);
      if (!allowed(t)) continue;
      cost(t), ++evaluations;
      if (t.cost < best.cost) best = std::move(t);
    }
    if (best.cost < c.cost)
      c = std::move(best);
    else
      step /= 2;
  }
  return c;
}

// The grid's best cylinders at distinct places (not within two steps of a better one), at most
// `count`, in order.
template <class Where>
std::vector<const Cylinder*> distinct_best(const Grid& g, std::size_t count, const Where& where,
                                           const MastSearchOptions& o) {
  std::vector<const Cylinder*> best;
  for (const auto& c : g.cylinders) {
    if (best.size() >= count || c.cost >= 1.0) break;
    if (!where(c) || std::any_of(best.begin(), best.end(),
                                 [&](const Cylinder* t) { return std::hypot(t->x - c.x, t->y - c.y) < 2 * o.step_m; }))
      continue;
    best.push_back(&c);
  }
  return best;
}

Mast as_mast(const Grid& g, const Cylinder& c) {
  Mast m;
  m.axis_point_board = g.frame.point(c.x, c.y, 0.0);
  m.up_board = g.frame.up;
  m.radius_m = c.radius;
  m.low_m = g.low, m.high_m = g.high;
  return m;
}

}  // namespace

std::optional<Mast> find_mast_by_outline(const std::vector<PosedView>& views, const camera::CameraIntrinsics& K,
                                         const Vec3& up_board, const Iso3& T_board_panel, const Vec3& size,
                                         const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                                         const MastSearchOptions& o) {
  throw_unless_ok(o.Check(), "MastSearchOptions");
  const auto grid = score_grid(views, K, up_board, T_board_panel, size, occluders, false, o);
  if (!grid) return std::nullopt;
  // One start per place: the grid's neighbours of a tried cylinder are the same mast.
  for (const Cylinder* c : distinct_best(
           *grid, o.confirm, [](const Cylinder&) { return true; }, o)) {
    // The grid's stretch is relative to the panel's centre; confirm_mast's heights are the board's.
    const double centre = grid->frame.up.dot(grid->frame.centre);
    if (auto mast = confirm_mast(as_mast(*grid, *c), views, K, centre + grid->low, centre + grid->high, occluders,
                                 o.confirmation))
      return mast;
  }
  return std::nullopt;
}

MountSides search_mount_sides(const std::vector<PosedView>& views, const camera::CameraIntrinsics& K,
                              const Vec3& up_board, const Iso3& T_board_panel, const Vec3& size,
                              const std::vector<std::vector<std::vector<cv::Point2f>>>& occluders,
                              const MastSearchOptions& o) {
  throw_unless_ok(o.Check(), "MastSearchOptions");
  MountSides sides;
  const auto grid = score_grid(views, K, up_board, T_board_panel, size, occluders, true, o);
  if (!grid) return sides;
  // Across the vertical, the boresight's direction; a cylinder on it lies before the panel.
  const Vec3 b = T_board_panel.linear().col(1);
  const Vec2 ahead(b.dot(grid->frame.e1), b.dot(grid->frame.e2));
  if (ahead.norm() < 1e-6) return sides;
  // Each side's best places, refined without crossing to the other side.
  for (const double sign : {-1.0, 1.0}) {
    const auto on_side = [&](const Cylinder& c) { return sign * Vec2(c.x, c.y).dot(ahead) > 0.0; };
    const auto allowed = [&](const Cylinder& c) { return on_side(c) && in_search(*grid, c, o); };
    auto& side = sign < 0.0 ? sides.behind : sides.before;
    for (const Cylinder* start : distinct_best(*grid, o.confirm, on_side, o)) {
      const Cylinder c = refined(*start, *grid->cost, allowed, o);
      if (!side || c.cost < side->cost) side = MountCylinder{as_mast(*grid, c), c.cost, c.view_costs};
    }
  }
  return sides;
}

}  // namespace antpose::reconstruction
