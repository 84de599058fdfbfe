#include "antpose/measure/non_contact.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <tuple>

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/board_pose.hpp"
#include "antpose/io/report_text.hpp"
#include "antpose/measure/long_axis.hpp"
#include "antpose/model/box_file.hpp"
#include "antpose/model/sampling.hpp"
#include "antpose/reconstruction/mast.hpp"

namespace antpose::measure {
namespace {
namespace fs = std::filesystem;
using reconstruction::PosedView;

void report(const NonContactOptions& options, const std::string& stage, int done, int total) {
  if (options.progress) options.progress(stage, done, total);
}

// The shot an ROI names: its shots.csv path, or just the file name when that is unique.
std::size_t roi_shot(const Capture& capture, const AntennaRoi& roi) {
  std::vector<std::size_t> by_name;
  for (std::size_t i = 0; i < capture.shots.size(); ++i) {
    if (capture.shots[i].image == roi.image) return i;
    if (fs::path(capture.shots[i].image).filename() == roi.image) by_name.push_back(i);
  }
  if (by_name.size() == 1) return by_name.front();
  std::string known;
  for (std::size_t i = 0; i < capture.shots.size() && i < 4; ++i) known += (i ? ", " : "") + capture.shots[i].image;
  if (capture.shots.size() > 4) known += ", ...";
  throw InputError("--roi", fmt::format("'{}' {} (photos: {})", roi.image,
                                        by_name.empty() ? "is no photo of the capture" : "names several photos",
                                        known.empty() ? "none" : known));
}

// The reconstruction's rotation uncertainty from the camera poses (board frame, rad²): each
// pose's rotation covariance carried into the board frame, averaged, over the number of views
// (their errors are independent between photos and average in the triangulation).
Mat3 pose_rotation_covariance(const reconstruction::RefinedPoses& poses) {
  Mat3 sum = Mat3::Zero();
  const auto n = poses.R_camera_board.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Mat3 R_bc = poses.R_camera_board[i].transpose();
    sum += R_bc * poses.covariance[i].topLeftCorner<3, 3>() * R_bc.transpose();
  }
  return n ? Mat3(sum / static_cast<double>(n * n)) : Mat3(Mat3::Zero());
}

// Spatial block bootstrap of the fine registration (file comment of non_contact.hpp): rotation
// covariance of T_antenna_board as a left perturbation in the antenna frame, rad².
Mat3 bootstrap_covariance(const PointCloud& scene, const registration::PreparedCloud& model, const Iso3& T_model_scene,
                          const NonContactOptions& options) {
  std::map<std::tuple<long, long, long>, std::vector<std::size_t>> blocks;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const Vec3 k = (scene.points[i] / options.bootstrap_block_m).array().floor();
    blocks[{static_cast<long>(k.x()), static_cast<long>(k.y()), static_cast<long>(k.z())}].push_back(i);
  }
  std::vector<const std::vector<std::size_t>*> list;
  for (const auto& [key, idx] : blocks) list.push_back(&idx);
  if (list.size() < 3 || options.bootstrap_replicas < 2) return Mat3::Zero();
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, list.size() - 1);
  registration::IcpOptions icp = options.registration.fine;
  icp.max_iterations = 20;
  Mat3 sum = Mat3::Zero();
  for (int r = 0; r < options.bootstrap_replicas; ++r) {
    PointCloud sample;
    for (std::size_t b = 0; b < list.size(); ++b)
      for (const auto i : *list[pick(rng)]) sample.points.push_back(scene.points[i]);
    const auto prepared = registration::prepare(std::move(sample), icp);
    const auto fit = registration::align(prepared, model, T_model_scene, icp);
    const Vec3 d = log_so3(fit.T_target_source.rotation() * T_model_scene.rotation().transpose());
    sum += d * d.transpose();
  }
  return sum / static_cast<double>(options.bootstrap_replicas);
}

double extent_along(const PointCloud& cloud, const Vec3& axis) {
  double lo = 1e300, hi = -1e300;
  for (const auto& p : cloud.points) lo = std::min(lo, p.dot(axis)), hi = std::max(hi, p.dot(axis));
  return cloud.empty() ? 0.0 : hi - lo;
}

// The outline fitted from no start: the antenna may be tried again once its neighbours are known.
class OutlineNotFound : public MeasurementError {
 public:
  using MeasurementError::MeasurementError;
};

// What the registration of every antenna shares.
struct Scene {
  const std::vector<PosedView>& views;
  const camera::CameraIntrinsics& intrinsics;
  std::vector<Vec3> viewpoints;  // camera centres, board frame
  Vec3 up_board;
  /// The photos as the outline sees them: no ROI (each start's crop follows its projection; a
  /// carried ROI may cut the outline), the board as an occluder.
  std::vector<registration::SilhouetteView> outline_views;
};

// The board as an obstacle (board frame, min and max corner): its printed extent plus the white
// margin, and a thickness about its plane.
std::pair<Vec3, Vec3> board_box(const camera::BoardSpec& board, const NonContactOptions& options) {
  const auto [lo, hi] = board.extent();
  const Vec3 margin(options.board_margin_squares * board.square_m, options.board_margin_squares * board.square_m,
                    options.board_thickness_m);
  return {lo - margin, hi + margin};
}

// The board's outline in a photo (px, as taken), empty when a corner is behind the camera.
std::vector<cv::Point2f> board_outline(const std::pair<Vec3, Vec3>& box, const camera::CameraIntrinsics& K,
                                       const Mat3& R_camera_board, const Vec3& t_camera_board) {
  const auto& [lo, hi] = box;
  std::vector<cv::Point2f> poly;
  for (const Vec2& c : {Vec2(lo.x(), lo.y()), Vec2(hi.x(), lo.y()), Vec2(hi.x(), hi.y()), Vec2(lo.x(), hi.y())}) {
    const auto uv = K.project(R_camera_board * Vec3(c.x(), c.y(), 0.0) + t_camera_board);
    if (!uv) return {};
    poly.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
  }
  return poly;
}

// Share of the rectangle in its photo that the registered antenna's box covers: the bounding box
// of the box's projected corners, cut to the rectangle. 0 when a corner is behind the camera.
double roi_fill(const AntennaMeasurement& m, const Vec3& size_m, const PosedView& view,
                const camera::CameraIntrinsics& K) {
  Eigen::AlignedBox2d box;
  for (const Vec3& corner_antenna : model::box_corners(size_m)) {
    const auto uv =
        K.project(view.R_camera_board * (m.R_board_antenna * corner_antenna + m.p_board_antenna) + view.t_camera_board);
    if (!uv) return 0.0;
    box.extend(*uv);
  }
  const auto& r = m.roi.roi;
  const Eigen::AlignedBox2d rect(Vec2(r.x - 0.5, r.y - 0.5), Vec2(r.x + r.width - 0.5, r.y + r.height - 0.5));
  const Eigen::AlignedBox2d cut = box.intersection(rect);
  return cut.isEmpty() ? 0.0 : cut.volume() / rect.volume();
}

// R diag(variance, variance, 0) Rᵀ: a covariance (or information) on the two rotations that move
// the antenna's long axis, none about it (R = R_board_antenna).
Mat3 across_long_axis(const Mat3& R_board_antenna, double variance) {
  return R_board_antenna * Vec3(variance, variance, 0.0).asDiagonal() * R_board_antenna.transpose();
}

// R_board_antenna turned the shortest way to put its long axis on `axis_board`.
Mat3 with_long_axis(const Mat3& R_board_antenna, const Vec3& axis_board) {
  return Eigen::Quaterniond::FromTwoVectors(R_board_antenna.col(2), axis_board).toRotationMatrix() * R_board_antenna;
}

// The mean line of sight from the camera centres to `p_board` (board frame, not normalised).
Vec3 mean_line_of_sight(const Scene& scene, const Vec3& p_board) {
  Vec3 sight = p_board;
  for (const Vec3& c : scene.viewpoints) sight -= c / static_cast<double>(scene.viewpoints.size());
  return sight;
}

// R_board_antenna turned by 180° about the antenna's own long axis: front and back swapped, the
// same line in the photos.
Mat3 turned_round(const Mat3& R_board_antenna) { return R_board_antenna * Vec3(-1.0, -1.0, 1.0).asDiagonal(); }

// The angle between two poses' boresights (y_a), degrees.
double boresight_angle_deg(const Mat3& R_board_a, const Mat3& R_board_b) {
  return rad2deg(angle_between(R_board_a.col(1), R_board_b.col(1)));
}

// The outline's options for the descents with the long axis held: monotone steps
// (SilhouetteOptions::max_step_halvings), and twice as many of them, since monotone steps are
// short where the score is flat and none of them can raise it.
registration::SilhouetteOptions held_axis_descent(const NonContactOptions& options) {
  auto o = options.silhouette_options;
  o.max_step_halvings = options.held_axis_step_halvings;
  o.max_iterations_per_level *= 2;
  return o;
}

// The outline's refinement with the long axis held to `axis_board`: a prior far tighter than
// either measurement on the two rotations that move it.
registration::SilhouetteResult refine_holding_axis(const model::AntennaModel& model, const Iso3& start,
                                                   const Vec3& axis_board, const Scene& scene,
                                                   const registration::SilhouetteOptions& options) {
  const double held = deg2rad(0.01);
  const Mat3 R = with_long_axis(start.linear(), axis_board);
  const registration::RotationPrior prior{R, across_long_axis(R, 1 / (held * held))};
  return registration::refine_by_silhouette(model.mesh_antenna, start, scene.outline_views, scene.intrinsics, options,
                                            prior);
}

// One descent of the outline from `start` with the edge search `line_ends_at_middle`
// (SilhouetteOptions), the long axis free or held to `held_axis` (held_axis_descent's steps).
// `polish`: a start already at an outline's minimum is refined at full resolution with the fine
// search only, without the coarse levels' wide search and the rivals' restarts.
registration::SilhouetteResult refine_outline(const model::AntennaModel& model, const Iso3& start, const Scene& scene,
                                              const NonContactOptions& options, bool line_ends_at_middle,
                                              const std::optional<Vec3>& held_axis = std::nullopt,
                                              bool polish = false) {
  auto o = held_axis ? held_axis_descent(options) : options.silhouette_options;
  o.line_ends_at_middle = line_ends_at_middle;
  if (polish) {
    o.max_level = 0;
    o.search_range_px = o.fine_search_px;
    o.rival_yaw_offsets_rad.clear();
  }
  return held_axis
             ? refine_holding_axis(model, start, *held_axis, scene, o)
             : registration::refine_by_silhouette(model.mesh_antenna, start, scene.outline_views, scene.intrinsics, o);
}

// The descents `descend(line_ends_at_middle)` with both edge searches (SilhouetteOptions): the
// one ending its lines at the middle only where some line of the other reached it; elsewhere (a
// panel wider than twice the search range, as on rooftops) the two are the same descent.
template <typename Descend>
std::vector<registration::SilhouetteResult> both_edge_searches(Descend&& descend) {
  std::vector<registration::SilhouetteResult> out;
  out.push_back(descend(false));
  if (out.front().search_reached_middle) out.push_back(descend(true));
  return out;
}

// How much worse than the best a pose at another yaw may score and still be a rival: where the
// outline fits poorly (part hidden, clutter beside it), the score's differences between poses
// mean less (options.silhouette_rival_share).
double other_yaw_margin(const NonContactOptions& options, double best_score) {
  return std::max(options.silhouette_rival_margin, options.silhouette_rival_share * best_score);
}

// The silhouette stage: starts turned about the vertical from the points' pose by each start
// angle, refined by the outline in every photo, the best of them again from tilted along the line
// of sight; the converged result with the lowest score (the outline's mean truncated edge cost)
// wins. `rivals`: other converged results scoring within
// options.silhouette_rival_margin of the winner whose boresight is more than rival_min_deg away
// (the winner turned by 180° included): the attitude's σ covers them.
struct SilhouettePick {
  std::optional<registration::SilhouetteResult> best;
  std::vector<Mat3> rivals;         // R_board_antenna of each rival
  bool flipped_by_outline = false;  // the outline turned the points' front/back decision
  bool rival_yaw = false;           // a converged start at another yaw is a rival
  /// The winner turned by 180° about its own long axis (front and back swapped: the same outline
  /// but for the brackets), refined where that converged: the mount's side may choose it.
  std::optional<registration::SilhouetteResult> turned;
  int tried = 0;
  std::vector<std::string> closest_failure;  // the best-scoring rejected start's reasons, when none converged
};

// Where a search's starts stand and what its descents keep.
struct SearchStarts {
  std::optional<Vec3> axis;  // the starts' long axis (board frame); none: upright, the board's up
  bool hold_axis = false;    // every descent keeps `axis` (refine_holding_axis)
  bool placed = false;       // each start first moved onto the outline with its rotation held
  /// The starts' yaws (degrees from the points' boresight; empty: options.silhouette_yaw_starts_deg),
  /// each also turned about the mean line of sight by each of `sight_turns_deg`.
  std::vector<double> yaws_deg;
  std::vector<double> sight_turns_deg{0.0};

  static SearchStarts held_on(const Vec3& axis) {
    SearchStarts s;
    s.axis = axis, s.hold_axis = true;
    return s;
  }
  static SearchStarts placed_on(const std::optional<Vec3>& axis) {
    SearchStarts s;
    s.axis = axis, s.placed = true;
    return s;
  }
};

SilhouettePick silhouette_search(const model::AntennaModel& model, const Iso3& T_board_antenna, const Scene& scene,
                                 const NonContactOptions& options, const SearchStarts& starts = {}) {
  SilhouettePick pick;
  const std::optional<Vec3> held_axis = starts.hold_axis ? starts.axis : std::nullopt;
  std::vector<registration::SilhouetteResult> done;
  double failed_score = 2.0;
  // Starts upright (the long axis along the board frame's up: panels hang within ~15° of it),
  // turned about it from the points' boresight, at the points' position. The points' own tilt
  // is not kept: on a cluttered region it can be the wrong basin for the outline. Given an axis
  // (SearchStarts) the starts lie on it, and where it is held every descent keeps it
  // (refine_holding_axis).
  const Vec3 up = starts.axis ? starts.axis->normalized() : Vec3(scene.up_board.normalized());
  // Every start descends with both edge searches (SilhouetteOptions::line_ends_at_middle) where
  // they differ (descend_both), and the scores, on the same fine search, choose: on a panel
  // narrower than the search range its far side is often the stronger edge and lures the descents
  // across it (2902-1, refused; 610-1, its downtilt 1.4° off), while a line ending at the middle
  // lacks the reach to turn a 2 m panel's axis by 9° from upright (1302-1) or to find a thesis
  // panel's outline 15 cm from the points' place (3206-3).
  const auto refine = [&](const Iso3& start, bool line_ends_at_middle, bool polish) {
    return refine_outline(model, start, scene, options, line_ends_at_middle, held_axis, polish);
  };
  // One descent from `start`; where it left its start's basin, or was stopped by the iteration
  // limit while still moving, descended again from where it ended up to `redescents` times: it
  // is kept if it stays put (then it is a minimum like any other, and the score chooses among
  // them). Few starts sit in the right basin of a narrow panel seen face-on, and a panel partly
  // hidden by its mast may take more than one such step to settle (1702-1); 2912-2's right basin
  // (turned round) was reached by a single start, which then ran out of steps and so never
  // competed.
  // Its search_reached_middle covers every refine it made, the ones it discarded too.
  const auto descend = [&](const Iso3& start, bool line_ends_at_middle, int redescents, bool polish) {
    ++pick.tried;
    auto r = refine(start, line_ends_at_middle, polish);
    bool reached_middle = r.search_reached_middle;
    for (int k = 0; k < redescents && !r.converged; ++k) {
      if (!r.left_start && !r.stopped_at_iteration_limit) break;
      ++pick.tried;
      auto again = refine(r.left_start ? *r.left_start : r.T_board_antenna, line_ends_at_middle, polish);
      reached_middle = reached_middle || again.search_reached_middle;
      if (!again.converged && again.score >= r.score) break;
      r = std::move(again);
    }
    r.search_reached_middle = reached_middle;
    return r;
  };
  const auto descend_both = [&](const Iso3& start, int redescents, bool polish = false) {
    return both_edge_searches(
        [&](bool line_ends_at_middle) { return descend(start, line_ends_at_middle, redescents, polish); });
  };
  Vec3 ahead = T_board_antenna.linear().col(1) - T_board_antenna.linear().col(1).dot(up) * up;
  if (ahead.norm() < 1e-6) ahead = up.unitOrthogonal();
  ahead.normalize();
  const auto upright_at = [&](double yaw_deg) {
    Iso3 start = T_board_antenna;
    const Vec3 y = Eigen::AngleAxisd(deg2rad(yaw_deg), up) * ahead;
    start.linear().col(0) = y.cross(up);
    start.linear().col(1) = y;
    start.linear().col(2) = up;
    return start;
  };
  // A placed start keeps its rotation and takes its position from the outline first: from a
  // place well off the panel across the line of sight, a free descent trades the rotation for the
  // position and settles on the mast's and the arms' edges beside it (4502-1, a 2 m panel 25 m
  // away seen from its side beside the mast: the points' box 7 cm to the side, and every start
  // from there ended 30-80° off at 0.48-0.51, where the same starts placed first reached the
  // truth's basin, 0.2° from it).
  std::optional<NonContactOptions> placing;
  if (starts.placed) {
    placing = options;
    placing->silhouette_options.free = {false, false, false, true, true, true};
    placing->silhouette_options.rival_yaw_offsets_rad.clear();
  }
  const auto start_at = [&](double yaw_deg, double sight_turn_deg) {
    Iso3 start = upright_at(yaw_deg);
    if (sight_turn_deg != 0.0)
      start.linear() =
          Eigen::AngleAxisd(deg2rad(sight_turn_deg), mean_line_of_sight(scene, start.translation()).normalized()) *
          start.linear();
    if (placing)
      start.translation() = refine_outline(model, start, scene, *placing, false).T_board_antenna.translation();
    return start;
  };
  const auto& yaws = starts.yaws_deg.empty() ? options.silhouette_yaw_starts_deg : starts.yaws_deg;
  for (const double yaw : yaws)
    for (const double turn : starts.sight_turns_deg) {
      for (auto& r : descend_both(start_at(yaw, turn), options.silhouette_redescents)) {
        if (r.converged && r.score > options.silhouette_max_score) {
          r.converged = false;
          r.warnings.push_back(fmt::format("the outline fits poorly: score {:.2f} (at most {:.2f})", r.score,
                                           options.silhouette_max_score));
        }
        if (r.converged)
          done.push_back(std::move(r));
        else if (failed_score > r.score)
          failed_score = r.score, pick.closest_failure = r.warnings;
      }
    }
  if (done.empty()) return pick;
  // The later descents (polish, tilt probe) join the starts' converged ones where they fit as well.
  const auto keep_if_fits = [&](registration::SilhouetteResult& r) {
    if (r.converged && r.score <= options.silhouette_max_score) done.push_back(std::move(r));
  };
  // The start at the points' own boresight is also polished where it stands: the coarse levels'
  // wide search can leave a narrow panel's basin for a worse one at full resolution. On 3711-2
  // (a thesis panel between two wider ones on a rooftop, its outline crossing theirs) every
  // descent settled 12° off at 0.23, where the polish found 0.12 at 0.5° from the truth. It
  // competes only where a descent converged: alone, it settles on whatever edges lie within its
  // ±4 px, and it won confidently wrong where the held-axis search was needed (1304-2, 45° off
  // with σ 1.6°; 604-1 and 1706-2).
  for (auto& r : descend_both(start_at(0.0, 0.0), 0, true)) keep_if_fits(r);
  const auto by_score = [](const auto& a, const auto& b) { return a.score < b.score; };
  std::sort(done.begin(), done.end(), by_score);
  // Seen from below, a downtilt tilts the panel's axis along the line of sight, which hardly moves
  // its outline, and the descents from upright may stop short of it (3312-2, 8.3°: all eleven
  // converged starts 3.4° short, scoring 0.082, where a start at the truth settles 0.1° from it
  // at 0.066). The winner tilted both ways about the axis across its long axis and the mean line
  // of sight is refined again, and the scores choose. A held axis holds the tilt.
  if (!held_axis && options.silhouette_tilt_probe_deg > 0.0) {
    const Iso3 winner = done.front().T_board_antenna;
    const Vec3 across = winner.linear().col(2).cross(mean_line_of_sight(scene, winner.translation()));
    if (across.norm() > 1e-9)
      for (const double sign : {-1.0, 1.0}) {
        Iso3 start = winner;
        start.linear() =
            Eigen::AngleAxisd(sign * deg2rad(options.silhouette_tilt_probe_deg), across.normalized()) * winner.linear();
        for (auto& r : descend_both(start, 0)) keep_if_fits(r);
      }
    std::sort(done.begin(), done.end(), by_score);
  }
  // A converged start is a rival when it scores about as well at a boresight more than
  // rival_min_deg away. Turned round (the same outline but for the brackets), within
  // options.silhouette_rival_margin with the brackets' outline counted; at another yaw, within a
  // margin that grows with the winner's score (options.silhouette_rival_share): where the
  // outline fits poorly (part hidden, clutter beside it), the score's differences between poses
  // mean less.
  enum class Rival { kNone, kTurnedRound, kOtherYaw };
  const auto rival = [&](const registration::SilhouetteResult& r, const registration::SilhouetteResult& best) {
    const double angle = boresight_angle_deg(r.T_board_antenna.linear(), best.T_board_antenna.linear());
    if (angle <= options.rival_min_deg) return Rival::kNone;
    if (angle >= 180.0 - options.rival_min_deg)
      return r.score_with_attachments < best.score_with_attachments + options.silhouette_rival_margin
                 ? Rival::kTurnedRound
                 : Rival::kNone;
    return r.score < best.score + other_yaw_margin(options, best.score) ? Rival::kOtherYaw : Rival::kNone;
  };
  for (std::size_t i = 1; i < done.size(); ++i)
    if (const Rival kind = rival(done[i], done.front()); kind != Rival::kNone) {
      pick.rivals.push_back(done[i].T_board_antenna.linear());
      pick.rival_yaw = pick.rival_yaw || kind == Rival::kOtherYaw;
    }
  pick.best = std::move(done.front());
  // Front and back by the outline too: the brackets show in it from the side. The winner turned
  // by 180° about its own long axis (the same line in the photos, the boresight reversed and the
  // downtilt's sign with it) is refined; clearly better by the brackets' outline
  // (attachments_turn_round), it wins; about as good, it is a rival.
  Iso3 turned = pick.best->T_board_antenna;
  turned.linear() = turned_round(turned.linear());
  // Its box's outline is the winner's, at its minimum already, so it is only polished
  // (refine_outline): searched again from the coarse level, the mast's edges beside a narrow panel
  // lured it 0.31 m and 52° away (a wide ground walk, seed 4102, antenna 2), and the winner, the
  // panel turned round, was kept with σ 1.1°.
  auto both = descend_both(turned, 0, true);
  auto flipped = std::move(both.front());
  if (both.size() > 1 && both.back().converged &&
      (!flipped.converged || both.back().score_with_attachments < flipped.score_with_attachments))
    flipped = std::move(both.back());
  if (!flipped.converged) {
    flipped = *pick.best;
    flipped.T_board_antenna = turned;
  } else if (attachments_turn_round({pick.best->score, pick.best->score_with_attachments},
                                    {flipped.score, flipped.score_with_attachments}, options.silhouette_rival_margin)) {
    pick.rivals.clear();
    std::swap(flipped, *pick.best);
    pick.flipped_by_outline = true;
  } else if (rival(flipped, *pick.best) != Rival::kNone) {
    pick.rivals.push_back(flipped.T_board_antenna.linear());
  }
  pick.turned = std::move(flipped);
  return pick;
}

// The long axis (board frame) of a fitted T_antenna_board, pointing as `reference`'s z.
Vec3 long_axis_board(const Iso3& T_antenna_board, const Iso3& reference) {
  const Vec3 axis = T_antenna_board.rotation().transpose().col(2);
  return axis.dot(reference.rotation().row(2).transpose()) < 0.0 ? Vec3(-axis) : axis;
}

// The region's points against the part of the model the photos can have seen from
// T_antenna_board (model::visible_surface from the scene's camera centres), by ICP with the yaw
// about the long axis held. The back plate and the brackets, which no photo of the front sees,
// pair with the mast and arms behind the panel and lean the axis towards them: on 4906-1 (a
// thesis panel seen face-on from 23 m) the whole model leant 0.80° along the line of sight from
// the true pose, its seen part 0.26°; on 4710-1 1.35° and 0.68°. And a face-on panel's front is
// too narrow for its points to fix the yaw: free, the whole model slid 32° from the truth.
struct SeenFit {
  Vec3 axis_board = Vec3::UnitZ();  // the long axis, pointing as T_antenna_board's z
  double fitness = 0.0;             // share of the region's points within reach of the seen part
};

SeenFit fit_seen_surface(const registration::PreparedCloud& cloud, const model::AntennaModel& model,
                         const Iso3& T_antenna_board, const Scene& scene, const NonContactOptions& options) {
  std::vector<Vec3> viewpoints_antenna;
  for (const Vec3& c : scene.viewpoints) viewpoints_antenna.push_back(T_antenna_board * c);
  auto o = options.registration.fine;
  o.held_rotation_axis = Vec3::UnitZ();
  auto seen = model::visible_surface(model.mesh_antenna, viewpoints_antenna, options.model_spacing_m, options.seed);
  if (seen.empty()) throw MeasurementError("no camera sees the model's surface from the registered pose");
  const auto icp = registration::align(cloud, registration::prepare(std::move(seen), o), T_antenna_board, o);
  return {long_axis_board(icp.T_target_source, T_antenna_board), icp.fitness};
}

// The points' long axis (board frame, pointing as R_board_antenna's z) where the outline has
// fixed the yaw: fit_seen_surface's. Thousands of points along 1.3–2 m fix it where the outline
// may slide (hold_axis_to_points).
Vec3 points_long_axis(const registration::PreparedCloud& cloud, const model::AntennaModel& model,
                      const Iso3& T_antenna_board, const Scene& scene, const NonContactOptions& options) {
  return fit_seen_surface(cloud, model, T_antenna_board, scene, options).axis_board;
}

// The same from the points' own pose, whose yaw may be tens of degrees off (then the part of the
// model the photos see is another part): ICP with the whole model.
Vec3 whole_model_long_axis(const registration::PreparedCloud& cloud, const registration::PreparedCloud& model_prepared,
                           const Iso3& T_antenna_board, const NonContactOptions& options) {
  return long_axis_board(
      registration::align(cloud, model_prepared, T_antenna_board, options.registration.fine).T_target_source,
      T_antenna_board);
}

// The mount decides front and back where the outline cannot (mount_side.hpp: the mast where one
// was fitted, else the points counted behind and before the panel), and the downtilt's sign
// where the mount cannot (options.max_uptilt_deg): as registered, the rivals
// facing the other way go; turned, the turned pose wins. Where the mount's choice would tilt the
// panel up beyond that limit the two disagree, and the other way round stays a rival. The
// downtilt is read with the long axis the measurement keeps (keep_axis).
void decide_front_by_mount(AntennaMeasurement& m, SilhouettePick& pick, const model::AntennaModel& model,
                           const registration::PreparedCloud& model_prepared, const Vec3& axis_points, double reach,
                           const Scene& scene, const NonContactOptions& options) {
  const Vec3& up_board = scene.up_board;
  const Vec3 sight = mean_line_of_sight(scene, pick.best->T_board_antenna.translation());
  const auto count = [&](const Mat3& R_board_antenna) {
    Iso3 T_board_antenna = pick.best->T_board_antenna;
    T_board_antenna.linear() = R_board_antenna;
    return count_mount_side(m.region.cloud_board, T_board_antenna.inverse(), model_prepared.tree, model.size_m, reach,
                            -sight, options.mount);
  };
  const auto downtilt = [&](const Mat3& R) {
    const KeptAxis kept = keep_axis(R.col(2), axis_points, sight, deg2rad(options.axis_gate_deg));
    return boresight_downtilt(with_long_axis(R, kept.axis), up_board);
  };
  // The mast, where one was fitted, before the counts (mount_side.hpp: mast_side_verdict).
  const auto by_mast = [&](const Mat3& R_board_antenna) {
    if (!m.mast) return MountVerdict::kUndecided;
    Iso3 T_board_antenna = pick.best->T_board_antenna;
    T_board_antenna.linear() = R_board_antenna;
    return mast_side_verdict(m.mast->axis_point_board, m.mast->up_board, m.mast->radius_m, T_board_antenna,
                             deg2rad(options.mount.mast_max_angle_deg));
  };
  const auto verdict = [&](const Mat3& R_board_antenna) {
    const MountVerdict cue = by_mast(R_board_antenna);
    return cue != MountVerdict::kUndecided ? cue : mount_verdict(count(R_board_antenna), options.mount);
  };
  auto side = count(pick.best->T_board_antenna.linear());
  const double tilt = downtilt(pick.best->T_board_antenna.linear());
  const double tilt_turned = pick.turned ? downtilt(pick.turned->T_board_antenna.linear()) : -tilt;
  const MountVerdict mast = by_mast(pick.best->T_board_antenna.linear());
  const bool mast_decides = mast != MountVerdict::kUndecided;
  const MountVerdict mount = mast_decides ? mast : mount_verdict(side, options.mount);
  const FrontBack call = decide_front_back(mount, tilt, tilt_turned, deg2rad(options.max_uptilt_deg));
  const auto turn_round = [&] {
    std::swap(*pick.best, *pick.turned);
    pick.flipped_by_outline = false;
    std::swap(side.before, side.behind);
  };
  if (call.verdict == MountVerdict::kTurned && pick.turned) {
    m.warnings.push_back(
        call.by_downtilt
            ? fmt::format("front and back decided by the downtilt's sign: as registered the panel would tilt up by "
                          "{:.1f}°; turned round it tilts down by {:.1f}°",
                          -rad2deg(tilt), rad2deg(tilt_turned))
        : mast_decides
            ? std::string("the mast decided front and back: as registered the panel faced its mast, so it is turned "
                          "round (its back plate faces the mast)")
            : fmt::format("the mount decided front and back: {} points beyond the model lay before the panel as "
                          "registered and {} behind it, so the panel is turned round (its brackets and the mast are "
                          "behind it)",
                          side.before, side.behind));
    turn_round();
  }
  // In doubt the pose that tilts down is reported, the mount's the rival its σ covers.
  if (call.in_doubt && pick.turned) {
    const bool mount_turns = mount == MountVerdict::kTurned;
    m.warnings.push_back(fmt::format(
        "front and back are in doubt: {} puts the front where the panel tilts up by {:.1f}°, and mounts tilt panels "
        "down; the σ covers the panel turned round",
        mast_decides ? std::string("the mast, the back plate facing it,")
                     : fmt::format("the mount ({} points behind the panel, {} before it)",
                                   mount_turns ? side.before : side.behind, mount_turns ? side.behind : side.before),
        -rad2deg(mount_turns ? tilt_turned : tilt)));
    if (!mount_turns) turn_round();
    pick.rivals.push_back(pick.turned->T_board_antenna.linear());
  }
  // Neither cue decides and the panel turned round fits about as well (a rival): the one that
  // tilts down is reported, since mounts tilt panels down, and the σ still covers the other. As
  // registered, 2402 and 2506-3 (ground, 1.5° and 1.9° down) came out turned round, tilting up.
  const bool decided = call.verdict != MountVerdict::kUndecided;
  const auto turned_is_rival = [&] {
    return std::any_of(pick.rivals.begin(), pick.rivals.end(), [&](const Mat3& R) {
      return boresight_angle_deg(R, pick.best->T_board_antenna.linear()) > 180.0 - options.rival_min_deg;
    });
  };
  if (!decided && !call.in_doubt && pick.turned && tilt_turned > tilt && turned_is_rival()) {
    turn_round();
    m.warnings.push_back(
        fmt::format("front and back are undecided (the mount: {} points behind the panel as reported, {} before "
                    "it): of the two ways round the one with a downtilt of {:+.1f}° is reported, not the one with "
                    "{:+.1f}°",
                    side.behind, side.before, rad2deg(tilt_turned), rad2deg(tilt)));
    pick.rivals.push_back(pick.turned->T_board_antenna.linear());
  }
  m.mount_points = side;
  const Mat3& R_result = pick.best->T_board_antenna.linear();
  // Decided, a rival facing the other way within options.rival_min_deg is the result turned
  // round, which the cues ruled out. One at another yaw has its own front and back, which the
  // cues decide as they did the result's (2912-2: the result 67° from a rival that was the truth
  // turned round); where they cannot, it faces as the result does.
  if (decided)
    for (Mat3& R : pick.rivals) {
      const double angle = boresight_angle_deg(R, R_result);
      if (angle <= options.rival_min_deg || angle >= 180.0 - options.rival_min_deg) continue;
      const Mat3 turned = turned_round(R);
      const auto own = decide_front_back(verdict(R), downtilt(R), downtilt(turned), deg2rad(options.max_uptilt_deg));
      if (own.verdict == MountVerdict::kTurned || (own.verdict == MountVerdict::kUndecided && angle > 90.0)) R = turned;
    }
  std::erase_if(pick.rivals, [&](const Mat3& R) {
    const double angle = boresight_angle_deg(R, R_result);
    return (decided && angle >= 180.0 - options.rival_min_deg) || angle <= options.rival_min_deg;
  });
  // One rival per place: starts that ended together would each widen the σ again.
  std::vector<Mat3> distinct;
  for (const Mat3& R : pick.rivals)
    if (std::none_of(distinct.begin(), distinct.end(),
                     [&](const Mat3& D) { return boresight_angle_deg(R, D) <= options.rival_min_deg; }))
      distinct.push_back(R);
  pick.rivals = std::move(distinct);
}

// The points fix the panel's long axis (thousands of points along 1.3–2 m); the outline fixes the
// yaw about it. Seen from below, the outline may instead slide in tilt along the line of sight
// (the mast's and the clamps' edges beside it fit as well): beyond the gate the outline is refined
// again with its axis held to the one kept (keep_axis: its tilt along the line of sight the
// points', across it the outline's own), and only the yaw and position free. Returns the rotation
// covariance (board frame) to use and the refit's dilation σ, or nothing when the outline's own
// stands.
struct HeldToPoints {
  Mat3 cov_board;
  std::optional<double> dilation_yaw_sigma_rad;  // the refit's (SilhouetteResult's), where it is kept
};

std::optional<HeldToPoints> hold_axis_to_points(AntennaMeasurement& m, Iso3& T_antenna_board, const Mat3& cov_outline,
                                                const model::AntennaModel& model, const Vec3& axis_points,
                                                const Scene& scene, const std::function<bool(const Iso3&)>& fits_points,
                                                const NonContactOptions& options) {
  const Mat3 R_outline = T_antenna_board.rotation().transpose();
  const KeptAxis kept =
      keep_axis(R_outline.col(2), axis_points, mean_line_of_sight(scene, T_antenna_board.inverse().translation()),
                deg2rad(options.axis_gate_deg));
  if (!kept.from_points) return std::nullopt;

  Iso3 start = T_antenna_board.inverse();
  start.linear() = with_long_axis(R_outline, kept.axis);
  // Held: a prior far tighter than either measurement on the two rotations that move the axis.
  // Across the line of sight the kept axis is the outline's own fit already (freed there again,
  // 4610-2 and 4710-1 came out the same within 0.1°).
  const double held = deg2rad(0.01);
  const registration::RotationPrior prior{start.linear(), across_long_axis(start.linear(), 1 / (held * held))};
  const auto r = registration::refine_by_silhouette(model.mesh_antenna, start, scene.outline_views, scene.intrinsics,
                                                    options.silhouette_options, prior);
  // The points' tilt is the likelier (the development sites: within 0.43° where the outline's
  // was 4–7° off), but not always (602-1 from the ground: the points 3.2° off, the outline's
  // right), so its σ covers both, as a two-way mixture: half the difference. Across the line of
  // sight the σ is the outline's free fit's.
  const double sa = deg2rad(options.points_axis_sigma_deg);
  const Mat3 along = (sa * sa + std::pow(kept.along_rad / 2, 2)) * kept.about * kept.about.transpose();
  const std::string disagreement = fmt::format(
      "the outline's long axis lay {:.1f}° from the points' ({:+.1f}° along the line of sight, where seen "
      "from below it can slide)",
      rad2deg(kept.disagreement_rad), rad2deg(kept.along_rad));
  if (r.converged && fits_points(r.T_board_antenna.inverse())) {
    m.warnings.push_back(disagreement +
                         ": the points' tilt along the line of sight is kept, the outline fixes the rest, and the "
                         "downtilt and roll σ cover both");
    T_antenna_board = r.T_board_antenna.inverse();
    const Mat3 across = kept.sideways.dot(cov_outline * kept.sideways) * kept.sideways * kept.sideways.transpose();
    return HeldToPoints{r.covariance.topLeftCorner<3, 3>() + along + across, r.dilation_yaw_sigma_rad};
  }
  m.warnings.push_back(disagreement +
                       ", and the outline does not fit with the points' tilt: that tilt is kept, and the downtilt "
                       "and roll σ cover both");
  T_antenna_board = start.inverse();
  return HeldToPoints{cov_outline + along, std::nullopt};
}

// The outline's score along the yaw about a held long axis, the position refit at each yaw
// (a profile, as of a likelihood). A narrow panel seen nearly face-on from below changes its
// outline little with yaw, and the mast's and the clamps' edges beside it shift the minimum:
// on the development sites the descents stopped 7° from the profile's minimum (604-1), and the
// truth scored up to 0.042 above it (1102-1, 1402-1). So the minimum is taken, and the yaws
// scoring within options.held_yaw_margin of it bound the yaw (a basin).
// A box's apparent width w|cos θ| + d|sin θ| (θ the view's angle from its front) is the same at
// θ and 2·atan(d/w) − θ, so a panel seen from one side has a second outline minimum that far
// round: on 4906-1 (thesis panel, seen 3–13° off its front from 23 m) the truth's basin, 38°
// from the profile's minimum, scored 0.0669 against 0.0653. Another basin whose minimum scores
// within options.silhouette_rival_margin, or options.silhouette_rival_share of the best score if
// more, is kept for the points to judge (fit_outline). 5611-3 (a thesis panel between two others
// on a rooftop, the mast and their brackets crossing its rectangle) had the truth's basin at
// 0.384 and one 22° away at 0.321: taken alone, that one came out 21.7° off with σ 2.0°.
struct YawBasin {
  Iso3 T_board_antenna;              // at the basin's minimum, refined between the steps
  double low_rad = 0, high_rad = 0;  // its yaws within the margin, from the minimum
  bool open = false;                 // the range reaches the profile's end: the yaw is not bounded
};

struct YawProfile {
  YawBasin best;
  std::optional<YawBasin> other;
};

YawProfile profile_yaw(const model::AntennaModel& model, const Iso3& T_board_antenna, const Scene& scene,
                       const NonContactOptions& options) {
  // At each yaw only the position is refit, with the normal number of steps.
  auto o = held_axis_descent(options);
  o.max_iterations_per_level = options.silhouette_options.max_iterations_per_level;
  o.rival_yaw_offsets_rad.clear();
  o.free = {false, false, false, true, true, true};
  const Vec3 axis = T_board_antenna.linear().col(2);
  const int n = static_cast<int>(std::round(options.held_yaw_range_deg / options.held_yaw_step_deg));
  std::vector<double> yaws, scores;
  std::vector<Iso3> poses;
  for (int k = -n; k <= n; ++k) {
    Iso3 start = T_board_antenna;
    yaws.push_back(deg2rad(k * options.held_yaw_step_deg));
    start.linear() = Eigen::AngleAxisd(yaws.back(), axis) * T_board_antenna.linear();
    auto r = registration::refine_by_silhouette(model.mesh_antenna, start, scene.outline_views, scene.intrinsics, o);
    scores.push_back(r.score);
    poses.push_back(r.T_board_antenna);
  }
  // The steps about step i scoring within the margin of it, not reaching into `other`'s.
  struct Steps {
    std::ptrdiff_t lo = 0, hi = -1;
    bool holds(std::ptrdiff_t k) const { return lo <= k && k <= hi; }
  };
  const auto last = static_cast<std::ptrdiff_t>(scores.size()) - 1;
  const auto steps_about = [&](std::ptrdiff_t i, const Steps& other) {
    const double limit = scores[i] + options.held_yaw_margin;
    Steps s{i, i};
    while (s.lo > 0 && scores[s.lo - 1] <= limit && !other.holds(s.lo - 1)) --s.lo;
    while (s.hi < last && scores[s.hi + 1] <= limit && !other.holds(s.hi + 1)) ++s.hi;
    return s;
  };
  auto between = held_axis_descent(options);
  between.rival_yaw_offsets_rad.clear();
  const auto basin = [&](std::ptrdiff_t i, const Steps& s) {
    YawBasin b{poses[i], yaws[s.lo] - yaws[i], yaws[s.hi] - yaws[i], s.lo == 0 || s.hi == last};
    // Between the steps: the yaw freed again from the basin's best step.
    const auto r = refine_holding_axis(model, poses[i], axis, scene, between);
    if (r.score <= scores[i]) b.T_board_antenna = r.T_board_antenna;
    return b;
  };
  const auto best = std::min_element(scores.begin(), scores.end()) - scores.begin();
  const Steps best_steps = steps_about(best, {});
  YawProfile profile{basin(best, best_steps), std::nullopt};
  // Another basin is as much a rival as a start converged at another yaw (silhouette_search's
  // `rival`).
  const double other_margin = other_yaw_margin(options, scores[best]);
  std::optional<std::ptrdiff_t> other;
  for (std::ptrdiff_t k = 0; k <= last; ++k) {
    const bool minimum = (k == 0 || scores[k] <= scores[k - 1]) && (k == last || scores[k] <= scores[k + 1]);
    if (!best_steps.holds(k) && minimum && scores[k] <= scores[best] + other_margin &&
        (!other || scores[k] < scores[*other]))
      other = k;
  }
  if (other) profile.other = basin(*other, steps_about(*other, best_steps));
  return profile;
}

// The mast the antenna hangs on (reconstruction/mast.hpp), from the region's points beyond the
// panel however it is turned about its axis (the points' yaw may be far off): in the photos where
// it stands in front of the antenna it hides what lies behind it, elsewhere its edges are known
// not to be the antenna's. The scene's photos for the outline carry it.
struct MastScene {
  Scene scene;
  std::optional<reconstruction::Mast> mast;  // the mast found, if any
};

MastScene with_mast(const PointCloud& cloud_board, const Scene& scene, const Iso3& T_antenna_board,
                    const model::AntennaModel& model, const NonContactOptions& options) {
  if (!options.mast) return {scene, std::nullopt};
  const double across = 0.5 * model.size_m.head<2>().norm() + options.mast_clearance_m;
  const double along = 0.5 * model.size_m.z() + options.mast_clearance_m;
  PointCloud beyond;
  for (const Vec3& p : cloud_board.points) {
    const Vec3 a = T_antenna_board * p;
    if (a.head<2>().norm() > across || std::abs(a.z()) > along) beyond.points.push_back(p);
  }
  // The mast's outline is sought below the panel, where it stands alone.
  const double bottom = scene.up_board.normalized().dot(T_antenna_board.inverse().translation()) - along;
  auto mast = reconstruction::fit_mast(beyond, scene.up_board, scene.views, scene.intrinsics,
                                       bottom - options.mast_outline_below_m, bottom, options.mast_options);
  if (!mast) return {scene, std::nullopt};
  Scene out = scene;
  const Vec3 centre = T_antenna_board.inverse().translation();
  for (std::size_t i = 0; i < out.outline_views.size(); ++i) {
    auto& v = out.outline_views[i];
    auto lines = reconstruction::mast_outline(*mast, scene.intrinsics, v.R_camera_board, v.t_camera_board);
    if (lines[0].empty()) continue;
    if (reconstruction::mast_in_front(*mast, scene.viewpoints[i], centre)) {
      auto& polygon = v.occluders.emplace_back(std::move(lines[0]));
      polygon.insert(polygon.end(), lines[1].rbegin(), lines[1].rend());
    } else {
      v.background_edges.push_back(std::move(lines[0]));
      v.background_edges.push_back(std::move(lines[1]));
    }
  }
  return {std::move(out), std::move(mast)};
}

// The region's points off the mast: those horizontally farther than options.off_mast_m from the
// surface of the vertical cylinder most of them lie on (reconstruction::mast_from_points); none
// where no cylinder holds them or too few points are left. Among clamps and arms, or scattered in
// depth, that cylinder's band is wider than the mast (on 6109-2, 0.62 m for a 0.057 m mast), and
// it takes them too. It is not confirmed by its outline (reconstruction::fit_mast): there, below
// the panel, the board on its tripod hid the mast in every photo.
std::optional<PointCloud> off_the_mast(const PointCloud& cloud_board, const Scene& scene,
                                       const NonContactOptions& options) {
  const auto mast = reconstruction::mast_from_points(cloud_board, scene.up_board, options.mast_options);
  if (!mast) return std::nullopt;
  PointCloud off;
  for (const Vec3& p : cloud_board.points)
    if (reconstruction::distance_from_surface(*mast, p) > options.off_mast_m) off.points.push_back(p);
  if (off.size() < options.region.min_points) return std::nullopt;
  return off;
}

// The other antennas already registered, as known objects in the photos of antenna k: each one's
// box, projected (the hull of its corners), is an occluder where it stands nearer the camera than
// k's points, elsewhere its outline is a masked edge. On a mast with three sectors the front
// panel's outline runs along the faces of the two behind it (1805-3, the thesis panel seen
// face-on between two wider ones).
Scene with_other_antennas(const Scene& scene, const std::vector<AntennaMeasurement>& antennas,
                          const NonContactSetup& setup, std::size_t k) {
  Scene out = scene;
  const auto& cloud = antennas[k].region.cloud_board;
  if (cloud.empty()) return out;
  const Vec3 centre = centroid(cloud.points);
  for (std::size_t j = 0; j < antennas.size(); ++j) {
    const auto* model = setup.model_for(j);
    if (j == k || antennas[j].error || !model) continue;
    const auto& other = antennas[j];
    for (std::size_t i = 0; i < out.outline_views.size(); ++i) {
      auto& v = out.outline_views[i];
      std::vector<cv::Point2f> corners;
      for (const Vec3& c : model::box_corners(model->size_m))
        if (const auto uv = scene.intrinsics.project(
                v.R_camera_board * (other.R_board_antenna * c + other.p_board_antenna) + v.t_camera_board))
          corners.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
      if (corners.size() < 8) continue;
      std::vector<cv::Point2f> hull;
      cv::convexHull(corners, hull);
      const Vec3& camera = scene.viewpoints[i];
      if ((other.p_board_antenna - camera).norm() < (centre - camera).norm()) {
        v.occluders.push_back(std::move(hull));
      } else {
        hull.push_back(hull.front());
        v.background_edges.push_back(std::move(hull));
      }
    }
  }
  return out;
}

// The share of `cloud` (board frame) within `reach` of the model at T_antenna_board, and the RMS
// distance of those points.
struct PointsFit {
  double fitness = 0.0;
  double rmse_m = std::numeric_limits<double>::infinity();
};

PointsFit points_fit(const PointCloud& cloud, const registration::KdTree& model, const Iso3& T_antenna_board,
                     double reach) {
  double ss = 0.0;
  std::size_t near = 0;
  for (const auto& p : cloud.points) {
    std::size_t index = 0;
    double d2 = 0.0;
    if (model.nearest(T_antenna_board * p, index, d2, reach * reach)) ss += d2, ++near;
  }
  PointsFit fit;
  if (!cloud.empty()) fit.fitness = static_cast<double>(near) / static_cast<double>(cloud.size());
  if (near) fit.rmse_m = std::sqrt(ss / static_cast<double>(near));
  return fit;
}

// Other places for the model (T_antenna_board), each centre more than `apart_m` from the
// winner's and from each other's: the points' best poses (global_start.hpp's hypotheses, best
// first), at most `count`; then the winner moved by the model's depth along its boresight, both
// ways; last the winner slid along its long axis by 1/16 and 1/8 of the model's length and along
// its boresight by half its depth, both ways (nearer than `apart_m`: the outline's basin is
// narrow). A region's points lie on the radome's front and on the arms and clamps behind the
// back plate, and the box can rest on either: on 3208-1 (a 2 m panel from the ground, refused)
// the points' box sat 0.14 m behind the panel, where no outline start reached the panel's basin.
// A whole depth (0.15 m) forward reached it only by a hair: a board tilt different by 1e-14 (the
// magnetometer's alignment written with other last digits) left it refused again; half a depth
// reaches it from both. Where other panels hide part of it, the points fix the box's position
// along its axis poorly: on 3811-3 (a 2 m panel behind two thesis panels on a rooftop, refused)
// it sat 0.12 m along the axis from the panel, and every start from there failed, where the same
// starts at the panel's centre converged.
std::vector<Iso3> other_positions(const registration::GlobalStartResult& start, const Vec3& size_m, double apart_m,
                                  std::size_t count) {
  const Iso3& winner = start.fit.T_target_source;
  std::vector<Vec3> centres{winner.inverse().translation()};
  std::vector<Iso3> out;
  const auto add = [&](const Iso3& T_antenna_board) {
    const Vec3 c = T_antenna_board.inverse().translation();
    if (std::none_of(centres.begin(), centres.end(), [&](const Vec3& d) { return (c - d).norm() <= apart_m; }))
      centres.push_back(c), out.push_back(T_antenna_board);
  };
  for (const auto& h : start.hypotheses) {
    if (out.size() >= count) break;
    add(h.T_model_scene);
  }
  const auto moved = [&](double distance_m, int axis) {
    Iso3 T_board_antenna = winner.inverse();
    T_board_antenna.translation() += distance_m * T_board_antenna.linear().col(axis);
    return T_board_antenna.inverse();
  };
  for (const double sign : {1.0, -1.0}) add(moved(sign * size_m.y(), 1));
  const std::pair<double, int> slides[] = {{1.0 / 16, 2}, {-1.0 / 16, 2}, {1.0 / 8, 2},
                                           {-1.0 / 8, 2}, {0.5, 1},       {-0.5, 1}};  // (share of the size, axis)
  for (const auto& [share, axis] : slides) out.push_back(moved(share * size_m(axis), axis));
  return out;
}

// Which outline searches run: all of them on the first pass; on a second pass, with more objects
// known in the photos, only the held-axis search (see search_outline for why).
enum class OutlinePass { kFirst, kHeldAxisOnly };

// The model registered to the region's points alone (registration/global_start.hpp), with the
// model's samples and both prepared clouds, which the outline stage and a second pass reuse.
struct PointsRegistration {
  PointCloud model_cloud;                    // the model's surface samples, antenna frame
  registration::PreparedCloud model, cloud;  // the samples; the region's points (board frame)
  registration::GlobalStartResult start;     // its fit: T_antenna_board
  double reach_m = 0.0;                      // the fine ICP's correspondence distance
};

// The model's prepared samples registered to `cloud_board` from the global start: the prepared
// cloud and the start's fit (T_antenna_board).
std::pair<registration::PreparedCloud, registration::GlobalStartResult> start_on(
    const PointCloud& cloud_board, const registration::PreparedCloud& model_prepared, const Scene& site,
    const NonContactOptions& options) {
  auto gopts = options.registration;
  gopts.viewpoints_scene = site.viewpoints;
  auto cloud = registration::prepare(cloud_board, gopts.fine);
  auto start = registration::global_align(cloud, model_prepared, site.up_board, gopts);
  return {std::move(cloud), std::move(start)};
}

PointsRegistration register_points(const PointCloud& cloud_board, const model::AntennaModel& model, const Scene& site,
                                   const NonContactOptions& options) {
  PointCloud model_cloud = model::sample_surface(model.mesh_antenna, options.model_spacing_m, options.seed);
  auto model_prepared = registration::prepare(model_cloud, options.registration.fine);
  auto [cloud, start] = start_on(cloud_board, model_prepared, site, options);
  return {std::move(model_cloud), std::move(model_prepared), std::move(cloud), std::move(start),
          options.registration.fine.max_correspondence_distance_m};
}

// The lower score of the descents from T_board_antenna in `scene` with both edge searches (as
// silhouette_search's starts descend), or none where neither converged.
std::optional<double> score_in(const model::AntennaModel& model, const Iso3& T_board_antenna, const Scene& scene,
                               const NonContactOptions& options) {
  std::optional<double> best;
  for (const auto& r : both_edge_searches([&](bool line_ends_at_middle) {
         return refine_outline(model, T_board_antenna, scene, options, line_ends_at_middle);
       }))
    if (r.converged && (!best || r.score < *best)) best = r.score;
  return best;
}

// The outline search's outcome: the winner, and where the held-axis search's was kept, the axis
// it held; and the scene with the mast it knew wherever the held search ran and the free
// search's winner does not stand.
struct OutlineSearch {
  SilhouettePick pick;
  std::optional<MastScene> with_the_mast;
  std::optional<Vec3> held_axis;
  /// Where the held search's winner was kept over the free search's: that one's score, and
  /// whether another yaw fitted about as well.
  std::optional<double> free_score;
  bool free_rival_yaw = false;
};

// Known objects (the mast, the other antennas) change every start's basin: in the free search
// they let poses 43–90° off win with small σ (1612-3, 2004-2, 1702-1, 610-1 with the mast; 2106-1
// with the other panels, −55° and the tilt −3.2° with σ 0.24°), so they are known only to the
// held-axis search, whose yaw the outline's profile then bounds. Where neither search converged,
// `pick` has no winner.
OutlineSearch search_outline(const PointCloud& cloud_board, const model::AntennaModel& model,
                             const PointsRegistration& points, const Scene& site, const NonContactOptions& options,
                             OutlinePass pass) {
  const Iso3& T_antenna_board = points.start.fit.T_target_source;
  OutlineSearch s;
  auto& pick = s.pick;
  std::optional<Vec3> axis_points;  // an ICP: run once, for the held search or the last fallback
  const auto points_axis = [&] {
    if (!axis_points) {
      const Vec3 axis = whole_model_long_axis(points.cloud, points.model, T_antenna_board, options);
      axis_points = axis.dot(site.up_board) < 0.0 ? Vec3(-axis) : axis;
    }
    return *axis_points;
  };
  if (pass == OutlinePass::kFirst) pick = silhouette_search(model, T_antenna_board.inverse(), site, options);
  // A narrow panel seen from below can trade yaw for tilt in its outline, and the mast's edges
  // beside it lure the descents away or the mast hides part of it: where no start converged, the
  // search is repeated with the long axis held to the points' and the mast known (with_mast). So
  // it is where the free search's winner fits the outline poorly
  // (options.silhouette_doubtful_score) or another yaw fits it about as well (a rival), and the
  // held search's wins unless the free one fits clearly better (below): 2112-3, a thesis panel a
  // third hidden by its mast, won the free search 79° off at 0.37 (its downtilt and roll swapped,
  // σ 0.2°); held, 0.16.
  const bool doubtful = pick.best && (pick.best->score > options.silhouette_doubtful_score || pick.rival_yaw);
  if ((!pick.best || doubtful) && options.held_axis_search) {
    auto with_the_mast = with_mast(cloud_board, site, T_antenna_board, model, options);
    const Vec3 axis = points_axis();
    auto held =
        silhouette_search(model, T_antenna_board.inverse(), with_the_mast.scene, options, SearchStarts::held_on(axis));
    held.tried += pick.tried;
    // The held search knows the mast, which hides part of the outline, so its scores are not the
    // free search's: the free winner is descended again in its scene and compared there. On
    // 3406-3 (a 2 m panel a third hidden by its mast) the free winner, the truth turned round,
    // scored 0.39 without the mast and 0.085 with it, and the held search's 0.23 (96° off) won.
    // It stands only where it fits clearly better: the held search also knows the points' axis
    // and bounds the yaw by its profile (610-1, 2106-1: 0.011 and 0 apart).
    std::optional<double> free_here;
    if (doubtful && held.best)
      free_here = score_in(model, pick.best->T_board_antenna, with_the_mast.scene, options).value_or(pick.best->score);
    if (held.best && (!free_here || held.best->score < *free_here + options.silhouette_rival_margin)) {
      if (pick.best) s.free_score = pick.best->score, s.free_rival_yaw = pick.rival_yaw;
      pick = std::move(held);
      s.held_axis = axis;
    } else if (doubtful) {
      return s;  // the free search's winner stands, and nothing of the held search's is used
    } else {
      pick.tried = held.tried;
      // On a second pass the free search has not run: the held search's is the closest start.
      if (pick.closest_failure.empty()) pick.closest_failure = std::move(held.closest_failure);
    }
    s.with_the_mast.emplace(std::move(with_the_mast));
  }
  // Where no start converged, the fallbacks run in turn until one finds a winner. (1) The points'
  // winner may sit on the mast beside the panel (a rooftop pipe with more points than a sparse
  // radome: 3201-1, 0.41 m off, no outline start within reach): the free search is repeated from
  // the points' best poses started elsewhere, their outline judging them. (2) The free search
  // from the points' pose again, its starts on the points' long axis and each placed first
  // (SearchStarts::placed): on 4502-1 the points' axis lay 0.2° from the truth's where upright
  // was 6.9° off, and their box 7 cm to the side of the panel. (3) The fine placed search
  // (options.fine_yaw_step_deg): where the points are far off in both place and axis, a panel
  // seen side-on has a basin too narrow for the starts 25° apart. (4) The points off the mast
  // (off_the_mast) registered again, the free search from their pose and its other_positions:
  // on 6109-2 (a 2 m panel 4.3 m away on a rooftop, refused) the mast, clamps and
  // arms held two thirds of the points, and the box on them sat 0.29 m to the side of the panel,
  // where even a start at the true rotation placed itself on the mast. All run only where all else
  // failed, so no answer found before them changes.
  const auto search_again = [&](const Iso3& T_board_start, const SearchStarts& starts) {
    auto again = silhouette_search(model, T_board_start, site, options, starts);
    again.tried += pick.tried;
    if (!again.best) {
      pick.tried = again.tried;
      return false;
    }
    s.with_the_mast.reset();
    s.held_axis.reset();
    pick = std::move(again);
    return true;
  };
  if (pick.best || pass != OutlinePass::kFirst) return s;
  const auto search_from_other_positions = [&](const registration::GlobalStartResult& start) {
    for (const Iso3& T : other_positions(start, model.size_m, options.other_position_m, options.other_positions))
      if (search_again(T.inverse(), {})) return true;
    return false;
  };
  const std::function<bool()> fallbacks[] = {
      [&] { return search_from_other_positions(points.start); },
      [&] { return search_again(T_antenna_board.inverse(), SearchStarts::placed_on(points_axis())); },
      [&] {
        if (options.fine_yaw_step_deg <= 0.0) return false;
        auto fine = SearchStarts::placed_on(std::nullopt);
        for (double yaw = -90.0; yaw < 90.0 - 1e-9; yaw += options.fine_yaw_step_deg) fine.yaws_deg.push_back(yaw);
        fine.sight_turns_deg = options.fine_sight_turns_deg;
        return search_again(T_antenna_board.inverse(), fine);
      },
      [&] {
        const auto off = options.off_mast_m > 0.0 ? off_the_mast(cloud_board, site, options) : std::nullopt;
        if (!off) return false;
        const auto again = start_on(*off, points.model, site, options).second;
        return search_again(again.fit.T_target_source.inverse(), {}) || search_from_other_positions(again);
      },
  };
  for (const auto& fallback : fallbacks)
    if (fallback()) break;
  return s;
}

// The outline stage's result: the pose, its rotation covariance and rivals.
struct OutlineFit {
  Iso3 T_antenna_board = Iso3::Identity();
  Mat3 cov_board = Mat3::Zero();  // rotation, rad², board frame
  std::vector<Mat3> rivals_board;
};

// The outline decides the yaw where the points cannot (docs/non-contact.md): the search, front
// and back by the mount, then the yaw's range about a held axis (profile_yaw) or the outline's
// axis against the points' (hold_axis_to_points). OutlineNotFound where no search converged.
// Writes its warnings, the mount's counts, the
// mast and the method into `m`.
OutlineFit fit_outline(AntennaMeasurement& m, const model::AntennaModel& model, const PointsRegistration& points,
                       const Scene& site, const NonContactOptions& options, OutlinePass pass) {
  auto [pick, with_the_mast, held_axis, free_score, free_rival_yaw] =
      search_outline(m.region.cloud_board, model, points, site, options, pass);
  if (with_the_mast) m.mast = with_the_mast->mast;
  if (!pick.best)
    // On the acceptance captures the points alone were tens of degrees off in yaw whenever the
    // outline failed: no number is better than that one.
    throw OutlineNotFound(fmt::format(
        "the model's outline matched the photos from none of {} starts, and the points alone do not fix the "
        "panel's yaw: is the whole antenna inside the photos, free of other panels in front of it, and is the "
        "model this antenna's? (closest start: {})",
        pick.tried, fmt::join(pick.closest_failure, "; ")));
  const Scene& scene = with_the_mast ? with_the_mast->scene : site;
  // With the axis held, the points' axis is the held one: ICP from the outline's pose may find
  // another (below).
  const Vec3 axis_points =
      held_axis ? *held_axis
                : points_long_axis(points.cloud, model, pick.best->T_board_antenna.inverse(), scene, options);
  decide_front_by_mount(m, pick, model, points.model, axis_points, points.reach_m, scene, options);
  OutlineFit fit{pick.best->T_board_antenna.inverse(), pick.best->covariance.topLeftCorner<3, 3>(), pick.rivals};
  if (held_axis) {
    const auto profile = profile_yaw(model, pick.best->T_board_antenna, scene, options);
    const YawBasin* basin = &profile.best;
    const auto seen_fit = [&](const YawBasin& b) {
      return fit_seen_surface(points.cloud, model, b.T_board_antenna.inverse(), scene, options);
    };
    std::optional<SeenFit> kept_seen;  // the kept basin's, where already fitted
    if (profile.other) {
      // The outline cannot tell the two basins apart: the points can, against what the photos
      // see of the model in each.
      const SeenFit best_seen = seen_fit(profile.best), other_seen = seen_fit(*profile.other);
      const double here = best_seen.fitness, there = other_seen.fitness;
      const double turn = rad2deg(
          angle_between(profile.other->T_board_antenna.linear().col(1), profile.best.T_board_antenna.linear().col(1)));
      const bool other_wins = there > (1 + options.seen_fit_margin) * here;
      const bool decided = other_wins || here > (1 + options.seen_fit_margin) * there;
      if (other_wins) basin = &*profile.other;
      kept_seen = other_wins ? other_seen : best_seen;
      if (!decided) fit.rivals_board.push_back(profile.other->T_board_antenna.linear());
      m.warnings.push_back(fmt::format(
          "the outline fits two yaws {:.0f}° apart about as well (a box's outline repeats either side of the view "
          "where it looks widest); {} ({:.0f} % of the points lie near what the photos see of the model against "
          "{:.0f} %)",
          turn,
          !decided     ? "the points do not tell them apart either, and the σ covers both"
          : other_wins ? "the points fit the outline's second best clearly better, and it is kept"
                       : "the points fit the outline's best clearly better",
          100 * std::max(here, there), 100 * std::min(here, there)));
    }
    fit.T_antenna_board = basin->T_board_antenna.inverse();
    const Mat3& R = basin->T_board_antenna.linear();
    // The points' ICP from the result's pose may settle on another axis (clutter in the region
    // pulls it differently from another start: 1604-2, 3.5° off where the held one was 0.6°; on
    // 4706-3, a 2 m panel seen from its side, keeping this one instead moved the downtilt from
    // −0.02° to −1.76°): the held axis stays, and its σ covers both, as in hold_axis_to_points.
    const Vec3 axis_again = (kept_seen ? *kept_seen : seen_fit(*basin)).axis_board;
    const double disagreement = angle_between(axis_again, R.col(2));
    const double sa = deg2rad(options.held_axis_sigma_deg);
    // The yaw's σ: a uniform spread over the bounded range (half-width h: h/√3).
    const double sy = (basin->high_rad - basin->low_rad) / 2 / std::sqrt(3.0);
    fit.cov_board +=
        across_long_axis(R, sa * sa + std::pow(disagreement / 2, 2)) + sy * sy * R.col(2) * R.col(2).transpose();
    if (rad2deg(disagreement) > options.axis_gate_deg)
      m.warnings.push_back(fmt::format(
          "the points' long axis depends on where their registration starts: {:.1f}° apart from the outline's "
          "pose and from the points' own; the downtilt and roll σ cover both",
          rad2deg(disagreement)));
    m.warnings.push_back(fmt::format(
        "the outline fitted {} with its long axis free; it fitted {}with the points' axis held, so the downtilt and "
        "roll are the points' and the outline fixes the yaw about their axis, {} (a narrow panel's outline barely "
        "changes with yaw when seen face-on from below: photograph it over a wider arc or from nearer)",
        !free_score      ? std::string("from no start")
        : free_rival_yaw ? fmt::format("ambiguously (score {:.2f}, and another yaw about as well)", *free_score)
                         : fmt::format("poorly (score {:.2f})", *free_score),
        free_score ? fmt::format("about as well or better ({:.2f}) ", pick.best->score) : std::string(),
        // Where no other step of the profile scores within the margin, the yaw is fixed to less than a step.
        basin->high_rad > basin->low_rad
            ? fmt::format("within {}{:+.0f}° to {:+.0f}° of the result", basin->open ? "more than " : "",
                          rad2deg(basin->low_rad), rad2deg(basin->high_rad))
            : fmt::format("to within its profile's {:.0f}° step", options.held_yaw_step_deg)));
  }
  m.silhouette_rms_px = pick.best->rms_px;
  double dilation_yaw_sigma_rad = pick.best->dilation_yaw_sigma_rad;
  m.method = fmt::format("model {}, points + outline in {} photos", model.name, pick.best->views_used);
  for (const auto& w : pick.best->warnings) m.warnings.push_back("outline: " + w);
  if (pick.flipped_by_outline)
    m.warnings.push_back(
        "the outline turned the points' front/back decision (the brackets' outline fits "
        "clearly better the other way round)");
  if (!held_axis) {
    // The outline has fitted something else where its pose leaves far fewer points near the
    // model than the points' own pose does (options.outline_points_fit_ratio).
    const auto fits_points = [&](const Iso3& T) {
      return points_fit(m.region.cloud_board, points.model.tree, T, points.reach_m).fitness >=
             options.outline_points_fit_ratio * points.start.fit.fitness;
    };
    if (const auto held = hold_axis_to_points(m, fit.T_antenna_board, fit.cov_board, model, axis_points, scene,
                                              fits_points, options)) {
      fit.cov_board = held->cov_board;
      dilation_yaw_sigma_rad = held->dilation_yaw_sigma_rad.value_or(dilation_yaw_sigma_rad);
    }
  }
  if (const double sy = rad2deg(dilation_yaw_sigma_rad); sy > options.warn_dilation_yaw_sigma_deg)
    m.warnings.push_back(fmt::format(
        "the outline's width barely changes with yaw in these photos: were it {:.2f} px wider all round than the "
        "model's (as blur and the shading of rounded edges make it), the yaw would turn by {:.1f}°, which the azimuth "
        "σ includes; photograph the antenna over a wider arc or from nearer",
        options.silhouette_options.outline_dilation_px, sy));
  return fit;
}

// The model registered to the region: by its points, then its outline (fit_outline); the
// pose's covariance from the outline, or else by resampling the points; the fit's checks.
void register_model(AntennaMeasurement& m, const model::AntennaModel& model, const PointsRegistration& points,
                    const Scene& site, const NonContactOptions& common, OutlinePass pass = OutlinePass::kFirst) {
  // The outline places the model by its box alone; the brackets' outline only tells front from
  // back (registration::SilhouetteOptions::outline_box_m).
  NonContactOptions options = common;
  options.silhouette_options.outline_box_m = model.size_m;
  const auto& g = points.start;
  Iso3 T_antenna_board = g.fit.T_target_source;
  m.method = "model " + model.name + ", points";
  m.front_back_margin = g.front_back_margin;
  std::optional<Mat3> cov_silhouette;
  if (options.silhouette) {
    auto outline = fit_outline(m, model, points, site, options, pass);
    T_antenna_board = outline.T_antenna_board;
    cov_silhouette = outline.cov_board;
    m.rivals_board = std::move(outline.rivals_board);
  }
  m.R_board_antenna = T_antenna_board.rotation().transpose();
  m.p_board_antenna = T_antenna_board.inverse().translation();

  // The points' agreement with the final pose.
  const PointsFit fit = points_fit(m.region.cloud_board, points.model.tree, T_antenna_board, points.reach_m);
  m.fitness = fit.fitness;
  m.fit_rmse_m = fit.rmse_m;
  // With the outline deciding the pose the points only place it, and clutter (mast, arms) may
  // outnumber them; without it they must carry the fit.
  const double fail_fitness = cov_silhouette ? options.fail_fitness_with_outline : options.fail_fitness;
  if (!(m.fitness >= fail_fitness) || !(m.fit_rmse_m <= options.fail_rmse_m))
    throw MeasurementError(fmt::format(
        "the region's {} points do not fit the model '{}': {:.0f} % of them lie within {:.0f} mm of it, RMS {:.1f} mm "
        "(at least {:.0f} % and at most {:.0f} mm expected). Is the rectangle on the antenna, and is the model this "
        "antenna's?",
        m.region.cloud_board.size(), model.name, 100 * m.fitness, 1e3 * points.reach_m, 1e3 * m.fit_rmse_m,
        100 * fail_fitness, 1e3 * options.fail_rmse_m));
  if (m.fit_rmse_m > options.warn_rmse_m)
    m.warnings.push_back(fmt::format("poor registration fit: RMS {:.1f} mm (more than {:.0f} mm)", 1e3 * m.fit_rmse_m,
                                     1e3 * options.warn_rmse_m));
  if (m.fitness < options.warn_fitness)
    m.warnings.push_back(
        fmt::format("only {:.0f} % of the region's points lie near the registered model: the region "
                    "holds other objects (mast, arms) or the reconstruction is noisy",
                    100 * m.fitness));
  if (!cov_silhouette) {
    if (g.front_back_ambiguous)
      m.warnings.push_back(fmt::format(
          "front and back are ambiguous: the model turned 180° fits nearly as well (margin {:.3f}); photograph the "
          "antenna from further round its side, or check the azimuth by eye",
          g.front_back_margin));
    // Any other yaw that fits the points nearly as well (coarse scores) is a rival.
    for (const auto& h : g.hypotheses) {
      const Mat3 R = h.T_model_scene.rotation().transpose();
      const double angle = boresight_angle_deg(R, m.R_board_antenna);
      if (angle > options.rival_min_deg && angle <= 90.0 &&
          h.score() - g.hypotheses.front().score() < options.registration.ambiguity_margin)
        m.rivals_board.push_back(R);
    }
    if (g.front_back_ambiguous)
      m.rivals_board.push_back(Eigen::AngleAxisd(M_PI, site.up_board.normalized()) * m.R_board_antenna);
  }
  const double covered = extent_along(m.region.cloud_board, m.R_board_antenna.col(2));
  if (covered < 0.6 * model.size_m.z())
    m.warnings.push_back(
        fmt::format("the points cover {:.2f} m of the {:.2f} m long panel: enlarge the rectangle to "
                    "the whole antenna",
                    covered, model.size_m.z()));
  m.cov_board = cov_silhouette
                    ? *cov_silhouette
                    : Mat3(m.R_board_antenna *
                           bootstrap_covariance(m.region.cloud_board, points.model, T_antenna_board, options) *
                           m.R_board_antenna.transpose());
  m.model_board = transformed(points.model_cloud, T_antenna_board.inverse());
}

// Rival poses widen the σ (antenna_attitude.hpp), with a warning naming the largest turn.
void widen_for_rivals(AntennaMeasurement& m, const BoardWorldAttitude& board,
                      const std::optional<geomag::SiteField>& site) {
  if (m.rivals_board.empty()) return;
  const double turn = widen_for_rivals(m.attitude, m.R_board_antenna, m.rivals_board, board, site);
  m.warnings.push_back(fmt::format(
      "the registration is ambiguous: the model turned {:.0f}° fits nearly as well; the σ of each angle covers it",
      rad2deg(turn)));
}

nlohmann::json deg_or_null(const std::optional<double>& rad) {
  return rad ? nlohmann::json(rad2deg(*rad)) : nlohmann::json(nullptr);
}

// The warning for an antenna that fills little of its rectangle (NonContactOptions::min_roi_fill).
std::string little_fill_warning(double fill, const std::string& photo) {
  return fmt::format(
      "the registered antenna covers only {:.0f} % of the rectangle in {}: another object (a nearer antenna?) may "
      "have been measured, or the rectangle is not drawn tightly around the antenna; check the model drawn over the "
      "photos",
      100 * fill, photo);
}

// The antenna registered to the object behind the one `near` measured, where that fills the
// rectangle (min_roi_fill) and clearly more of it than `near` did, and its points are centred
// within the antenna's size of `near`: one panel of several on a mount, the nearer one crossing
// its rectangle (site 5111: 24 % for the middle one of three, 52 % for the top one marked).
// Farther objects (a wall, a tower behind) are left alone: `near` stands, with its warning.
// nullopt where nothing behind registers or it does not qualify.
std::optional<std::pair<AntennaMeasurement, PointsRegistration>> measure_behind(
    const AntennaMeasurement& near, double near_fill, const model::AntennaModel& model,
    const std::function<reconstruction::RegionReconstruction(double beyond_m)>& reconstruct, const Scene& scene,
    const PosedView& view, const NonContactOptions& options) {
  AntennaMeasurement m;
  m.roi = near.roi;
  try {
    m.region = reconstruct(near.region.depth_far_m);
    // Before the registration, the costly part: points centred farther off are another object.
    if ((centroid(m.region.cloud_board.points) - near.p_board_antenna).norm() > model.size_m.norm())
      return std::nullopt;
    m.warnings = m.region.warnings;
    auto points = register_points(m.region.cloud_board, model, scene, options);
    register_model(m, model, points, scene, options);
    const double fill = roi_fill(m, model.size_m, view, scene.intrinsics);
    const double apart_m = (m.p_board_antenna - near.p_board_antenna).norm();
    // Half as much again: where both fill the rectangle about as well, it does not tell them apart.
    constexpr double kClearlyMore = 1.5;
    if (fill < options.min_roi_fill || fill < kClearlyMore * near_fill) return std::nullopt;
    m.warnings.insert(
        m.warnings.begin(),
        fmt::format("the object nearest the camera in the rectangle of {} ({:.1f}–{:.1f} m away) "
                    "registered as an antenna covering only {:.0f} % of the rectangle; the one behind it, {:.1f} m "
                    "from it, covering {:.0f} %, was measured; check the model drawn over the photos",
                    view.name, near.region.depth_near_m, near.region.depth_far_m, 100 * near_fill, apart_m,
                    100 * fill));
    return std::pair{std::move(m), std::move(points)};
  } catch (const MeasurementError&) {
    return std::nullopt;
  }
}

}  // namespace

AntennaRoi parse_roi(const std::string& text) {
  const auto colon = text.rfind(':');
  AntennaRoi r;
  int w = 0, h = 0, x = 0, y = 0;
  char tail = 0;
  if (colon == std::string::npos || colon == 0 ||
      std::sscanf(text.c_str() + colon + 1, "%d,%d,%d,%d%c", &x, &y, &w, &h, &tail) != 4)
    throw InputError("--roi", fmt::format("'{}' is not IMAGE:x,y,w,h (e.g. images/img_003.jpg:1200,300,400,1500, "
                                          "pixels of that photo)",
                                          text));
  if (x < 0 || y < 0 || w < 8 || h < 8)
    throw InputError("--roi", fmt::format("'{}': x and y must be ≥ 0 and the width and height at least 8 px", text));
  r.image = text.substr(0, colon);
  r.roi = {x, y, w, h};
  return r;
}

NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& setup,
                                     const NonContactOptions& options, Diagnostics& diagnostics) {
  if (setup.models.size() > 1 && setup.models.size() != setup.rois.size())
    throw InputError("--model", fmt::format("{} models for {} regions: give one model for all, or one per --roi in "
                                            "the same order",
                                            setup.models.size(), setup.rois.size()));
  NonContactResult result;
  std::vector<std::size_t> roi_shots;
  for (const auto& roi : setup.rois) roi_shots.push_back(roi_shot(capture, roi));
  for (std::size_t k = 0; k < setup.rois.size(); ++k) {
    const auto& r = setup.rois[k].roi;
    if (r.x + r.width > setup.intrinsics.width || r.y + r.height > setup.intrinsics.height)
      throw InputError("--roi", fmt::format("{}:{},{},{},{} reaches outside the {}×{} image", setup.rois[k].image, r.x,
                                            r.y, r.width, r.height, setup.intrinsics.width, setup.intrinsics.height));
  }
  for (const auto& s : capture.shots) result.photos.push_back(s.image);

  // Board poses, and the photos as posed views.
  report(options, "board poses", 0, 1);
  const auto board_poses = camera::board_poses(capture, setup.board, setup.intrinsics, diagnostics);
  std::vector<PosedView> views;
  for (const auto& p : board_poses) {
    if (!p.pose) {
      result.skipped.push_back(p.image + ": " + p.reason);
      continue;
    }
    PosedView v;
    v.name = fmt::format("shot {} ({})", p.shot_index, p.image);
    v.image = cv::imread((capture.root / p.image).string(), cv::IMREAD_GRAYSCALE);
    v.R_camera_board = p.pose->R_camera_board;
    v.t_camera_board = p.pose->t_camera_board;
    v.board_image_px = p.image_points_px;
    v.board_points_m = p.board_points_m;
    views.push_back(std::move(v));
    result.posed.push_back(p.shot_index);
  }
  report(options, "board poses", 1, 1);
  if (views.size() < 2) {
    std::string why;
    for (const auto& s : result.skipped) why += "\n  " + s;
    throw MeasurementError(fmt::format("the board was found in {} of {} photos; at least 2 are needed{}", views.size(),
                                       capture.shots.size(), why));
  }

  result.poses = reconstruction::refine_camera_poses(
      views, setup.intrinsics, options.poses, [&](const std::string& s, int d, int t) { report(options, s, d, t); });
  for (std::size_t i = 0; i < views.size(); ++i) {
    views[i].R_camera_board = result.poses.R_camera_board[i];
    views[i].t_camera_board = result.poses.t_camera_board[i];
  }
  for (const auto& w : result.poses.warnings) result.warnings.push_back(w);

  // The board in the world.
  report(options, "phone orientation", 0, 1);
  const auto data = orientation::imu_data_from_capture(capture, diagnostics);
  const auto track = orientation::make_estimator(options.orientation)->estimate(data, diagnostics);
  report(options, "phone orientation", 1, 1);
  std::vector<BoardPhoto> photos;
  for (std::size_t i = 0; i < views.size(); ++i)
    photos.push_back({views[i].name, capture.shots[result.posed[i]].t, result.poses.R_camera_board[i],
                      result.poses.t_camera_board[i], result.poses.covariance[i].topLeftCorner<3, 3>()});
  result.board = board_world_attitude(photos, track, setup.camera_imu, options.board_world, diagnostics);
  result.warnings.insert(result.warnings.end(), result.board.warnings.begin(), result.board.warnings.end());
  if (capture.site) result.site = geomag::site_field(geomag::MagneticModel::wmm2025(), *capture.site);
  if (data.has_magnetometer()) {
    // Each photo's attitude from the board (field_check.hpp): the board's heading shared by all.
    std::vector<double> shot_t;
    std::vector<Mat3> R_world_device;
    for (std::size_t i = 0; i < views.size(); ++i) {
      shot_t.push_back(capture.shots[result.posed[i]].t + setup.camera_imu.time_offset_s);
      R_world_device.push_back(result.board.R_world_board * views[i].R_camera_board.transpose() *
                               setup.camera_imu.R_device_camera.transpose());
    }
    const auto fields = field_at_photos(data, track, shot_t, R_world_device, options.field.half_window_s);
    std::vector<Vec3> field_world_uT;
    for (const auto& f : fields)
      if (f) field_world_uT.push_back(*f);
    if (options.heading_from_compass) {
      // The board's heading from the compass at the photos, not from the track (board_world.hpp).
      result.board = heading_from_field(std::move(result.board), field_world_uT, options.compass);
      const Mat3 R_turn = exp_so3(Vec3(0.0, 0.0, result.board.compass_turn_rad.value_or(0.0)));
      for (Vec3& b : field_world_uT) b = R_turn * b;
    }
    // Where each photo was taken: the camera centre in the board frame, turned to world axes.
    std::vector<Vec3> p_world_m;
    for (std::size_t i = 0; i < fields.size(); ++i)
      if (fields[i])
        p_world_m.push_back(result.board.R_world_board *
                            camera::camera_centre(views[i].R_camera_board, views[i].t_camera_board));
    result.field = check_field(field_world_uT, result.site, options.field, p_world_m);
    // A disturbed compass turns the board's heading, shared by every antenna.
    result.board.covariance(2, 2) += std::pow(result.field.heading_sigma_rad, 2);
    for (const auto& w : result.field.warnings) {
      result.board.warnings.push_back(w);  // carried into every antenna's attitude
      result.warnings.push_back(w);
    }
  }

  const auto board = board_box(setup.board, options);
  Scene scene{views, setup.intrinsics, {}, result.board.R_world_board.transpose() * Vec3::UnitZ(), {}};
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    scene.viewpoints.push_back(camera::camera_centre(v.R_camera_board, v.t_camera_board));
    auto& outline = scene.outline_views.emplace_back(
        registration::SilhouetteView{v.image, v.R_camera_board, v.t_camera_board, {}, {}, {}});
    if (auto poly = board_outline(board, setup.intrinsics, v.R_camera_board, v.t_camera_board); !poly.empty())
      outline.occluders.push_back(std::move(poly));
  }
  const Mat3 cov_poses = pose_rotation_covariance(result.poses);
  auto region_options = options.region;
  region_options.exclude_board = board;

  const auto finish = [&](AntennaMeasurement& m) {
    m.cov_board += cov_poses;
    m.attitude = antenna_attitude(result.board, m.R_board_antenna, m.cov_board, result.site);
    widen_for_rivals(m, result.board, result.site);
  };
  // Antennas whose outline fitted from no start, with their points' registration: tried again
  // with the others known.
  struct Retry {
    std::size_t k, view;
    PointsRegistration points;
  };
  std::vector<Retry> retry;
  for (std::size_t k = 0; k < setup.rois.size(); ++k) {
    AntennaMeasurement m;
    std::size_t view = 0;  // the rectangle's photo among the posed ones
    std::optional<PointsRegistration> points;
    m.roi = setup.rois[k];
    const auto name = fmt::format("antenna {} ({})", k + 1, m.roi.image);
    try {
      const auto at = std::find(result.posed.begin(), result.posed.end(), roi_shots[k]);
      if (at == result.posed.end())
        throw MeasurementError(
            fmt::format("the board was not found in {} ({}): mark the antenna in a photo that shows "
                        "the board",
                        m.roi.image, board_poses[roi_shots[k]].reason));
      view = static_cast<std::size_t>(at - result.posed.begin());
      const auto reconstruct = [&](double beyond_m) {
        auto o = region_options;
        o.beyond_m = beyond_m;
        return reconstruction::reconstruct_region(
            views, result.poses, view, m.roi.roi, setup.intrinsics, o,
            [&](const std::string& s, int d, int t) { report(options, name + ": " + s, d, t); });
      };
      m.region = reconstruct(0.0);
      for (const auto& w : m.region.warnings) m.warnings.push_back(w);
      report(options, name + ": registration", 0, 1);
      if (const auto* model = setup.model_for(k)) {
        points = register_points(m.region.cloud_board, *model, scene, options);
        register_model(m, *model, *points, scene, options);
        const double fill = roi_fill(m, model->size_m, views[view], setup.intrinsics);
        if (fill < options.min_roi_fill) {
          auto behind = measure_behind(m, fill, *model, reconstruct, scene, views[view], options);
          if (behind) {
            m = std::move(behind->first);
            points = std::move(behind->second);
          } else {
            m.warnings.push_back(little_fill_warning(fill, views[view].name));
          }
        }
      } else {
        const FaceFit fit = fit_front_face(m.region.cloud_board, scene.viewpoints, scene.up_board, options.model_free);
        m.method = "model-free (front face + long axis)";
        m.R_board_antenna = fit.R_scene_antenna;
        m.p_board_antenna = fit.centre_scene;
        m.cov_board = fit.covariance;
        m.fit_rmse_m = fit.rmse_m;
        m.fitness = fit.inlier_share;
        for (const auto& w : fit.warnings) m.warnings.push_back(w);
      }
      report(options, name + ": registration", 1, 1);
      finish(m);
    } catch (const OutlineNotFound& e) {
      m.error = e.what();
      retry.push_back({k, view, std::move(*points)});
    } catch (const MeasurementError& e) {
      m.error = e.what();
    }
    result.antennas.push_back(std::move(m));
  }
  // Antennas whose outline fitted from no start, again with the others registered known.
  for (const auto& [k, view, points] : retry) {
    auto& m = result.antennas[k];
    const bool others = std::any_of(result.antennas.begin(), result.antennas.end(),
                                    [&](const AntennaMeasurement& a) { return &a != &m && !a.error; });
    if (!others || !options.held_axis_search) continue;
    AntennaMeasurement again;
    again.roi = m.roi;
    again.region = m.region;
    again.warnings = m.region.warnings;
    try {
      const auto& model = *setup.model_for(k);
      register_model(again, model, points, with_other_antennas(scene, result.antennas, setup, k), options,
                     OutlinePass::kHeldAxisOnly);
      again.warnings.push_back(
          "the outline fitted only with the other antennas' registered outlines known (their edges masked)");
      if (const double fill = roi_fill(again, model.size_m, views[view], setup.intrinsics); fill < options.min_roi_fill)
        again.warnings.push_back(little_fill_warning(fill, views[view].name));
      finish(again);
      m = std::move(again);
    } catch (const MeasurementError& e) {
      m.error = fmt::format("{} (and again with the other antennas known: {})", *m.error, e.what());
    }
  }
  return result;
}

nlohmann::json to_json(const NonContactResult& r) {
  nlohmann::json j;
  j["photos"] = r.photos.size();
  j["photos_with_board"] = r.posed.size();
  j["skipped"] = r.skipped;
  j["camera_poses"] = {{"board_rms_px", r.poses.board_rms_px},
                       {"scene_rms_px", r.poses.scene_rms_px},
                       {"tracks", r.poses.tracks},
                       {"observations", r.poses.observations}};
  j["board"] = {{"R_world_board", io::matrix_rows_json(r.board.R_world_board)},
                {"photos_used", r.board.used},
                {"heading_scatter_deg", r.board.heading_scatter_deg},
                {"compass_turn_deg", r.board.compass_turn_rad ? nlohmann::json(rad2deg(*r.board.compass_turn_rad))
                                                              : nlohmann::json(nullptr)},
                {"view_spread_deg", r.board.view_spread_deg},
                {"heading_sigma_deg", rad2deg(std::sqrt(r.board.covariance(2, 2)))},
                {"tilt_sigma_deg", rad2deg(std::sqrt((r.board.covariance(0, 0) + r.board.covariance(1, 1)) / 2))}};
  {
    const auto& f = r.field;
    std::vector<double> dip_deg;
    for (const double d : f.dip_rad) dip_deg.push_back(rad2deg(d));
    nlohmann::json vectors = nlohmann::json::array(), positions = nlohmann::json::array();
    for (const Vec3& b : f.field_world_uT) vectors.push_back({b.x(), b.y(), b.z()});
    for (const Vec3& p : f.p_world_m) positions.push_back({p.x(), p.y(), p.z()});
    j["magnetic_field"] = {{"field_world_uT", vectors},
                           {"position_world_m", positions},
                           {"strength_uT", f.strength_uT},
                           {"dip_deg", dip_deg},
                           {"wmm_strength_uT", f.wmm_strength_uT ? nlohmann::json(*f.wmm_strength_uT) : nullptr},
                           {"wmm_dip_deg", deg_or_null(f.wmm_dip_rad)},
                           {"strength_spread_percent", 100 * f.strength_spread_fraction},
                           {"dip_spread_deg", rad2deg(f.dip_spread_rad)},
                           {"strength_trend_percent", 100 * f.strength_trend_fraction},
                           {"strength_gradient_uT_per_m", f.strength_gradient_uT_per_m},
                           {"trend_f_statistic", f.trend_f_statistic},
                           {"vector_trend_percent", 100 * f.vector_trend_fraction},
                           {"vector_trend_f_statistic", f.vector_trend_f_statistic},
                           {"median_dip_offset_deg",
                            f.wmm_dip_rad ? nlohmann::json(rad2deg(f.median_dip_offset_rad)) : nlohmann::json(nullptr)},
                           {"disturbed", f.disturbed},
                           {"heading_sigma_deg", rad2deg(f.heading_sigma_rad)}};
  }
  j["world"] = "enu-magnetic";
  j["declination_deg"] = r.site ? nlohmann::json(rad2deg(r.site->declination)) : nlohmann::json(nullptr);
  j["warnings"] = r.warnings;
  j["antennas"] = nlohmann::json::array();
  for (const auto& m : r.antennas) {
    nlohmann::json a;
    a["roi"] = {{"image", m.roi.image},
                {"x", m.roi.roi.x},
                {"y", m.roi.roi.y},
                {"width", m.roi.roi.width},
                {"height", m.roi.roi.height}};
    a["error"] = m.error ? nlohmann::json(*m.error) : nlohmann::json(nullptr);
    const bool ok = !m.error;
    const auto& at = m.attitude;
    a["method"] = m.method;
    a["azimuth_magnetic_deg"] = ok ? deg_or_null(at.magnetic.azimuth) : nullptr;
    a["azimuth_true_deg"] = ok ? deg_or_null(at.azimuth_true) : nullptr;
    a["downtilt_deg"] = ok ? nlohmann::json(rad2deg(at.magnetic.downtilt)) : nullptr;
    a["roll_deg"] = ok ? deg_or_null(at.magnetic.roll) : nullptr;
    a["uncertainty_deg"] = {{"azimuth", ok ? deg_or_null(at.sigma.azimuth) : nullptr},
                            {"azimuth_true", ok ? deg_or_null(at.azimuth_true_sigma) : nullptr},
                            {"downtilt", ok ? nlohmann::json(rad2deg(at.sigma.downtilt)) : nullptr},
                            {"roll", ok ? deg_or_null(at.sigma.roll) : nullptr}};
    a["fit_rmse_m"] = ok ? nlohmann::json(m.fit_rmse_m) : nullptr;
    a["fitness"] = ok ? nlohmann::json(m.fitness) : nullptr;
    a["front_back_margin"] = m.front_back_margin ? nlohmann::json(*m.front_back_margin) : nullptr;
    if (m.mount_points)
      a["mount_points"] = {{"behind", m.mount_points->behind},
                           {"before", m.mount_points->before},
                           {"depth_noise_m", m.mount_points->depth_noise_m}};
    if (m.mast)
      a["mast"] = {{"axis_point_board_m",
                    {m.mast->axis_point_board.x(), m.mast->axis_point_board.y(), m.mast->axis_point_board.z()}},
                   {"radius_m", m.mast->radius_m},
                   {"points", m.mast->points},
                   {"photos", m.mast->views},
                   {"edge_rms_px", m.mast->edge_rms_px}};
    a["outline_rms_px"] = m.silhouette_rms_px ? nlohmann::json(*m.silhouette_rms_px) : nullptr;
    a["photos_used"] = m.region.views_used;
    a["points"] = m.region.cloud_board.size();
    a["reconstruction"] = m.region.method;
    if (ok) {
      a["R_world_antenna"] = io::matrix_rows_json(at.R_world_antenna);
      a["R_board_antenna"] = io::matrix_rows_json(m.R_board_antenna);
    }
    std::vector<std::string> warnings = ok ? at.warnings : std::vector<std::string>{};
    warnings.insert(warnings.end(), m.warnings.begin(), m.warnings.end());
    a["warnings"] = warnings;
    j["antennas"].push_back(a);
  }
  return j;
}

}  // namespace antpose::measure
