#include "antpose/measure/antenna_measurement.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/model/sampling.hpp"
#include "antpose/reconstruction/mast_search.hpp"

namespace antpose::measure {
namespace {

std::pair<Vec3, Vec3> board_box(const camera::BoardSpec& board, const AntennaOptions& o) {
  const auto [lo, hi] = board.extent();
  const double m = o.board_margin_squares * board.square_m;
  const Vec3 margin(m, m, o.board_thickness_m);
  return {lo - margin, hi + margin};
}

cv::Rect rect_of(const reconstruction::Roi& r) { return {r.x, r.y, r.width, r.height}; }

// The mast the antenna hangs on (reconstruction/mast.hpp), from the region's points off the
// registered panel turned any way about its axis, its outline sought below the panel where it
// stands alone.
std::optional<reconstruction::Mast> find_mast(const PointCloud& cloud_board, const Iso3& T_board_antenna,
                                              const Vec3& size_m, const CaptureContext& capture,
                                              const AntennaOptions& o) {
  const Iso3 T_antenna_board = T_board_antenna.inverse();
  const double across = 0.5 * size_m.head<2>().norm() + o.mast_clearance_m;
  const double along = 0.5 * size_m.z() + o.mast_clearance_m;
  PointCloud beyond;
  for (const Vec3& p : cloud_board.points) {
    const Vec3 a = T_antenna_board * p;
    if (a.head<2>().norm() > across || std::abs(a.z()) > along) beyond.points.push_back(p);
  }
  const double bottom = capture.up_board.dot(T_board_antenna.translation()) - along;
  return reconstruction::fit_mast(beyond, capture.up_board, capture.poses->views, capture.poses->intrinsics,
                                  bottom - o.mast_outline_below_m, bottom, o.mast_options);
}

// The mast by its outline alone (reconstruction/mast_search.hpp), the panel as registered, the
// board and the neighbours masked in every photo.
std::optional<reconstruction::Mast> find_mast_outline(const Iso3& T_board_antenna, const Vec3& size_m,
                                                      const CaptureContext& c, const SceneObjects& objects,
                                                      const AntennaOptions& o) {
  std::vector<std::vector<std::vector<cv::Point2f>>> occluders;
  std::vector<KnownBox> boxes = objects.neighbours;
  boxes.push_back({T_board_antenna, size_m});
  for (const auto& v : c.poses->views) {
    auto& here = occluders.emplace_back();
    here.push_back(board_outline(objects.board_box, c.poses->intrinsics, v.R_camera_board, v.t_camera_board));
    for (const auto& b : boxes) here.push_back(box_hull(b, c.poses->intrinsics, v.R_camera_board, v.t_camera_board));
  }
  return reconstruction::find_mast_by_outline(c.poses->views, c.poses->intrinsics, c.up_board, T_board_antenna, size_m,
                                              occluders, o.mast_search);
}

// The mast from the region's points, else by its outline alone.
std::optional<reconstruction::Mast> find_any_mast(const PointCloud& cloud_board, const Iso3& T_board_antenna,
                                                  const Vec3& size_m, const CaptureContext& c,
                                                  const SceneObjects& objects, const AntennaOptions& o) {
  if (auto mast = find_mast(cloud_board, T_board_antenna, size_m, c, o)) return mast;
  return find_mast_outline(T_board_antenna, size_m, c, objects, o);
}

// The share of the region's points the model at the pose explains, and their RMS distance.
std::pair<double, double> points_fit(const PointCloud& cloud, const PointCloud& model_board, double reach) {
  if (cloud.empty() || model_board.empty()) return {0.0, 0.0};
  const registration::KdTree tree(model_board.points);
  double ss = 0.0;
  std::size_t near = 0;
  for (const auto& p : cloud.points) {
    std::size_t index = 0;
    double d2 = 0.0;
    if (tree.nearest(p, index, d2, reach * reach)) ss += d2, ++near;
  }
  return {static_cast<double>(near) / static_cast<double>(cloud.size()),
          near ? std::sqrt(ss / static_cast<double>(near)) : 0.0};
}

// The world azimuth (deg, magnetic) from which a photo would show the panel's side.
double side_view_azimuth_deg(const Mat3& R_board_antenna, const BoardWorldAttitude& board) {
  const Vec3 x = board.R_world_board * R_board_antenna.col(0);
  return std::fmod(rad2deg(std::atan2(x.x(), x.y())) + 360.0, 360.0);
}

// The measurement's verdict in words: ambiguous poses widen the σ; front and back left open
// refuse the antenna, naming both answers and the photo that would settle them.
void explain_verdict(AntennaMeasurement& m, const registration::AntennaRegistration& r, const CaptureContext& c) {
  if (r.verdict == registration::RegistrationVerdict::kFrontBackOpen) {
    const auto a = attitude_from_rotation(c.board->R_world_board * m.R_board_antenna);
    const double az = rad2deg(a.azimuth.value_or(0.0));
    m.error = fmt::format(
        "front and back cannot be told apart in these photos (no mast was found behind either face, and neither "
        "the structure on its sides nor the mount's points decide): the magnetic azimuth is {:.1f}° with downtilt "
        "{:+.1f}°, or {:.1f}° with downtilt {:+.1f}°; "
        "add photos from the antenna's side (from a magnetic azimuth near {:.0f}°, seen from the mast) where its "
        "brackets and mount show",
        az, rad2deg(a.downtilt), std::fmod(az + 180.0, 360.0), -rad2deg(a.downtilt),
        side_view_azimuth_deg(m.R_board_antenna, *c.board));
    return;
  }
  if (const auto& rival = r.selection.mast_rival; rival && m.mast) {
    const Iso3& T = r.candidates[*rival].T_board_antenna;
    const bool away = T.linear().col(1).dot(T.translation() - m.mast->axis_point_board) >= 0.0;
    const auto a =
        attitude_from_rotation(c.board->R_world_board * (away ? T.linear() : registration::turned_round(T.linear())));
    const auto& v = r.selection.versus_mast_rival;
    m.warnings.push_back(fmt::format(
        "the registration is ambiguous: the pose whose outline fits the photos best turns a side face to the mast "
        "found {:.1f} m away, and a panel hangs with its back to its mount; with its back to the mast it would face "
        "magnetic azimuth {:.1f}° (downtilt {:+.1f}°), scored {:+.3f} ± {:.3f} against the first over {} units; "
        "the σ of each angle covers both; photos from the antenna's side, where its brackets and mount show, would "
        "settle it",
        reconstruction::distance_from_axis(*m.mast, m.p_board_antenna), rad2deg(a.azimuth.value_or(0.0)),
        rad2deg(a.downtilt), v.difference, v.standard_error, v.units));
    return;
  }
  if (r.verdict == registration::RegistrationVerdict::kAmbiguousShape && !r.rivals.empty() && r.selection.runner_up) {
    const auto& v = *r.selection.runner_up;
    m.warnings.push_back(fmt::format(
        "the registration is ambiguous: {} other pose(s) fit the photos and points about as well (score difference "
        "{:.3f} ± {:.3f} over {} units); the σ of each angle covers them; photos over a wider arc round the antenna "
        "would settle it",
        r.rivals.size(), v.difference, v.standard_error, v.units));
  }
}

void apply_registration(AntennaMeasurement& m, const model::AntennaModel& model,
                        const registration::AntennaRegistration& r, const CaptureContext& c, const AntennaOptions& o) {
  m.R_board_antenna = r.T_board_antenna.linear();
  m.p_board_antenna = r.T_board_antenna.translation();
  m.cov_board = r.rotation_covariance_sources;
  m.cov_board.push_back({"camera poses", c.cov_poses_board});
  for (const auto& rival : r.rivals) m.rivals_board.push_back(rival.linear());
  for (const auto& rival : r.near_rivals) m.rivals_board.push_back(rival.linear());
  for (const auto& rival : r.face_rivals) m.face_rivals_board.push_back(rival.linear());
  m.face_planes = r.face_planes;
  m.long_edges_left_out = r.long_edges_left_out;
  m.verdict = r.verdict;
  m.runner_up = r.selection.runner_up;
  if (r.selection.mast_rival) m.mast_rival = r.selection.versus_mast_rival;
  m.front_back = r.selection.front_back;
  m.front_back_cue = r.selection.front_back_cue;
  m.silhouette_rms_px = r.outline_rms_px;
  m.model_shape_sigma_m = r.outline_shape_sigma_m;
  m.candidates = r.proposed;
  m.registration_candidates = r.candidates;
  m.method = fmt::format("model {}, outline in {} photos + points", model.name, r.outline_views);
  m.warnings.insert(m.warnings.end(), r.warnings.begin(), r.warnings.end());
  const model::AntennaModel& fitted = r.panel_shape ? r.panel_shape->model : model;
  if (const auto& f = r.panel_shape) {
    m.edge_radius_m = f->radius_m, m.end_cap_rim_m = f->rim_m;
    for (const std::size_t k : f->within) m.shapes_within_m.push_back({f->radii_m[k], f->rims_m[k]});
  }
  m.model_board = transformed(model::sample_surface(fitted.mesh_antenna, 0.01, 1), r.T_board_antenna);
  std::tie(m.fitness, m.fit_rmse_m) = points_fit(m.region.cloud_board, m.model_board, o.reach_m);
  if (m.fit_rmse_m > o.warn_rmse_m)
    m.warnings.push_back(fmt::format("poor registration fit: RMS {:.1f} mm (more than {:.0f} mm)", 1e3 * m.fit_rmse_m,
                                     1e3 * o.warn_rmse_m));
  if (m.fitness < o.warn_fitness)
    m.warnings.push_back(fmt::format(
        "only {:.0f} % of the region's points lie near the registered model: the region holds other objects (mast, "
        "arms, other panels) or its points are sparse (a plain radome)",
        100 * m.fitness));
  // Without texture the angles rest on the outline, and the downtilt on where the panel's ends lie
  // along the lines of sight. An end face as dark or as bright as what lies behind it leaves the
  // end's outline without an edge, and a pose that lays it on the crease with the next face
  // instead meets an edge in every photo: no photo of that arc tells the two apart.
  if (m.region.region_coverage < o.region.min_coverage)
    m.warnings.push_back(
        "the radome shows little texture, so the angles rest on its outline and the downtilt on where the panel's "
        "ends lie in the photos: an end face as dark or as bright as what lies behind it can move the downtilt by "
        "more than its σ (check the ends in the report's overlays); photos from the antenna's side, where its long "
        "edges show the downtilt, settle it");
  if (rad2deg(r.dilation_yaw_sigma_rad) > o.warn_dilation_yaw_sigma_deg)
    m.warnings.push_back(fmt::format(
        "the outline's width barely changes with yaw in these photos (a tenth of a pixel of blur would turn the yaw "
        "by {:.1f}°): the yaw rests on where the long edges lie, and the azimuth σ says how well they fix it; "
        "photograph the antenna over a wider arc or from nearer",
        rad2deg(r.dilation_yaw_sigma_rad)));
  explain_verdict(m, r, c);
}

// The source of the budget that limits one angle most (`angle` reads its σ from a share).
template <class Angle>
const SigmaShare* largest_share(const AntennaAttitudeResult& a, const Angle& angle) {
  const SigmaShare* best = nullptr;
  for (const auto& s : a.budget)
    if (!best || angle(s.sigma) > angle(best->sigma)) best = &s;
  return best;
}

}  // namespace

std::optional<std::string> imprecision_warning(const AntennaAttitudeResult& a, const AntennaOptions& o) {
  const auto azimuth = [](const AttitudeSigma& s) { return s.azimuth.value_or(0.0); };
  const auto downtilt = [](const AttitudeSigma& s) { return s.downtilt; };
  std::string wide;
  const SigmaShare* limit = nullptr;
  if (a.sigma.azimuth && rad2deg(*a.sigma.azimuth) > o.warn_sigma_azimuth_deg)
    wide = fmt::format("the azimuth to ±{:.1f}°", rad2deg(*a.sigma.azimuth)), limit = largest_share(a, azimuth);
  if (rad2deg(a.sigma.downtilt) > o.warn_sigma_downtilt_deg) {
    wide += fmt::format("{}the downtilt to ±{:.1f}°", wide.empty() ? "" : " and ", rad2deg(a.sigma.downtilt));
    if (!limit) limit = largest_share(a, downtilt);
  }
  if (wide.empty() || !limit) return std::nullopt;
  const bool compass = limit->source == kBoardAttitudeSource;
  return fmt::format(
      "these photos fix {} (1σ, mostly from the {}): too wide to tell a right antenna from a wrong one; {}", wide,
      limit->source,
      compass ? "take the photos where the compass agrees along the walk, away from steel"
              : "photograph the antenna from nearer, at a higher resolution or over a wider arc");
}

namespace {

void measure_model_free(AntennaMeasurement& m, const CaptureContext& c, const AntennaOptions& o) {
  std::vector<Vec3> viewpoints;
  for (const auto& v : c.poses->views) viewpoints.push_back(camera::camera_centre(v.R_camera_board, v.t_camera_board));
  const FaceFit fit = fit_front_face(m.region.cloud_board, viewpoints, c.up_board, o.model_free);
  m.method = "model-free (front face + long axis)";
  m.R_board_antenna = fit.R_scene_antenna;
  m.p_board_antenna = fit.centre_scene;
  m.cov_board = {{"front face fit", fit.covariance}, {"camera poses", c.cov_poses_board}};
  m.fit_rmse_m = fit.rmse_m;
  m.fitness = fit.inlier_share;
  m.warnings.insert(m.warnings.end(), fit.warnings.begin(), fit.warnings.end());
}

// The largest angle between two photos' lines of sight to `p_board` (rad).
double viewing_span(const std::vector<reconstruction::PosedView>& views, const Vec3& p_board) {
  double span = 0.0;
  for (std::size_t a = 0; a < views.size(); ++a)
    for (std::size_t b = a + 1; b < views.size(); ++b)
      span = std::max(span,
                      angle_between(camera::camera_centre(views[a].R_camera_board, views[a].t_camera_board) - p_board,
                                    camera::camera_centre(views[b].R_camera_board, views[b].t_camera_board) - p_board));
  return span;
}

// Where the antenna is before it is registered: its points' centroid, else the middle of the
// depths where the model fills the rectangle, on the rectangle's central ray.
Vec3 rough_centre(const AntennaMeasurement& m, const model::AntennaModel* model, const CaptureContext& c) {
  if (!m.region.cloud_board.empty() || !model) return centroid(m.region.cloud_board.points);
  const auto& K = c.poses->intrinsics;
  const auto& v = c.poses->views[m.region_view];
  const auto [near, far] = depths_filling(model->size_m, rect_of(m.roi.roi), K);
  const Vec3 ray = K.ray(Vec2(m.roi.roi.x + 0.5 * m.roi.roi.width, m.roi.roi.y + 0.5 * m.roi.roi.height));
  return v.R_camera_board.transpose() * (ray / ray.z() * (0.5 * (near + far)) - v.t_camera_board);
}

}  // namespace

OptionProblems AntennaOptions::Check() const {
  OptionProblems p;
  p.nest("registration", registration.Check());
  p.require(board_margin_squares >= 0 && board_thickness_m >= 0, "board_margin_squares, board_thickness_m", "≥ 0");
  p.require(mast_clearance_m >= 0 && mast_outline_below_m > 0, "mast_clearance_m, mast_outline_below_m",
            "clearance ≥ 0, stretch > 0");
  p.require(mast_points_share > 0 && mast_points_share <= 1, "mast_points_share", "in (0, 1]");
  p.require(same_mast_m >= 0, "same_mast_m", "≥ 0");
  p.require(reach_m > 0, "reach_m", "positive");
  p.require(warn_sigma_azimuth_deg > 0 && warn_sigma_downtilt_deg > 0,
            "warn_sigma_azimuth_deg, warn_sigma_downtilt_deg", "positive");
  p.require(min_viewing_span_deg >= 0 && warn_viewing_span_deg >= min_viewing_span_deg,
            "min_viewing_span_deg, warn_viewing_span_deg", "0 ≤ refusal ≤ warning");
  p.require(region.min_points >= 1, "region.min_points", "at least 1");
  return p;
}

AntennaRoi parse_roi(const std::string& text) {
  const auto colon = text.rfind(':');
  const auto malformed = [&] {
    return InputError("--roi", fmt::format("'{}' is not IMAGE:x,y,w,h (e.g. images/img_003.jpg:1200,300,400,1500, "
                                           "pixels of that photo)",
                                           text));
  };
  if (colon == std::string::npos || colon == 0) throw malformed();
  // std::from_chars, unlike sscanf's %d, says when a number does not fit an int.
  std::array<int, 4> v{};
  const char* p = text.data() + colon + 1;
  const char* end = text.data() + text.size();
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (k > 0 && (p == end || *p++ != ',')) throw malformed();
    const auto [next, ec] = std::from_chars(p, end, v[k]);
    if (ec == std::errc::result_out_of_range)
      throw InputError("--roi", fmt::format("'{}': {} is far beyond any photo's pixels", text,
                                            std::string_view(p, static_cast<std::size_t>(next - p))));
    if (ec != std::errc()) throw malformed();
    p = next;
  }
  if (p != end) throw malformed();
  const auto [x, y, w, h] = v;
  if (x < 0 || y < 0 || w < 8 || h < 8)
    throw InputError("--roi", fmt::format("'{}': x and y must be ≥ 0 and the width and height at least 8 px", text));
  AntennaRoi r;
  r.image = text.substr(0, colon);
  r.roi = r.drawn = {x, y, w, h};
  return r;
}

reconstruction::RegionReconstruction antenna_region(const CaptureContext& c, std::size_t region_view,
                                                    const AntennaRoi& roi, const model::AntennaModel* model,
                                                    const AntennaOptions& o, const reconstruction::Progress& progress) {
  auto region_options = o.region;
  region_options.exclude_board = board_box(c.board_spec, o);
  if (model) {
    region_options.allow_few_points = true;
    region_options.expected_depth_m = depths_filling(model->size_m, rect_of(roi.roi), c.poses->intrinsics);
  }
  return reconstruction::reconstruct_region(c.poses->views, c.poses->refined, region_view, roi.roi, c.poses->intrinsics,
                                            region_options, progress);
}

// A second registration with the mast known (registration_scene.hpp) from the first one's
// candidates, which have their turns among them; where the mast held a share of the region's
// points (AntennaOptions::mast_points_share), also from fresh starts without them.
registration::AntennaRegistration register_with_mast(const model::AntennaModel& model, std::size_t points_before,
                                                     std::vector<registration::PoseCandidate> starts,
                                                     const AntennaMeasurement& m, const CaptureContext& c,
                                                     const SceneObjects& objects, const AntennaOptions& o) {
  const auto scene = registration_scene(*c.poses, c.up_board, m.region, m.region_view, rect_of(m.roi.roi), objects);
  const double held = 1.0 - static_cast<double>(scene.points_board.size()) / std::max<std::size_t>(1, points_before);
  if (held < o.mast_points_share)
    return registration::register_antenna(model, scene, registration::continuing(o.registration), starts);
  const auto fresh = registration::propose_poses(model, scene, o.registration);
  starts.insert(starts.end(), fresh.begin(), fresh.end());
  return registration::register_antenna(model, scene, o.registration, starts);
}

void measure_antenna(AntennaMeasurement& m, const model::AntennaModel* model, const CaptureContext& c,
                     const std::vector<KnownBox>& neighbours, const AntennaOptions& o,
                     const std::vector<registration::PoseCandidate>& previous) {
  throw_unless_ok(o.Check(), "AntennaOptions");
  // From one place the photos see the antenna along one line of sight: neither its points nor
  // its outline fix its depth or its turn.
  // Over a narrow arc they see it along nearly one line of sight: its points have little depth,
  // and its attitude rests on the sub-pixel detail of one outline, where whatever the model lacks
  // (end caps, mounts, shading) turns it.
  const double span = viewing_span(c.poses->views, rough_centre(m, model, c));
  if (span < deg2rad(o.min_viewing_span_deg)) {
    m.error = fmt::format(
        "the photos see the antenna from nearly one place (their lines of sight to it span {:.1f}°, "
        "at least {:.0f}° needed): take the photos while walking a few metres round it",
        rad2deg(span), o.min_viewing_span_deg);
    return;
  }
  if (span < deg2rad(o.warn_viewing_span_deg))
    m.warnings.push_back(fmt::format(
        "the photos see the antenna over only {:.1f}° (less than {:.0f}°): its attitude rests on nearly one "
        "outline and its points have little depth, so the angles may be off by more than their σ; photograph it "
        "over a wider arc (walking sideways a third of the distance to it gives about 20°)",
        rad2deg(span), o.warn_viewing_span_deg));
  if (!model) {
    measure_model_free(m, c, o);
  } else {
    SceneObjects objects;
    objects.board_box = board_box(c.board_spec, o);
    objects.neighbours = neighbours;
    objects.mast = m.mast;  // known from an earlier registration of this antenna
    objects.antenna_depth_m = depths_filling(model->size_m, rect_of(m.roi.roi), c.poses->intrinsics);
    auto scene = registration_scene(*c.poses, c.up_board, m.region, m.region_view, rect_of(m.roi.roi), objects);
    // A later registration's earlier candidates hold the points' starts: the outline search alone
    // adds what the scene now known shows.
    auto proposing = o.registration;
    proposing.points_start = previous.empty();
    auto proposals = registration::propose_poses(*model, scene, proposing);
    proposals.insert(proposals.end(), previous.begin(), previous.end());
    auto r = registration::register_antenna(
        *model, scene, previous.empty() ? o.registration : registration::continuing(o.registration), proposals);
    const auto known = [&](const reconstruction::Mast& mast) {
      return objects.mast &&
             reconstruction::same_mast(*objects.mast, mast, r.T_board_antenna.translation(), o.same_mast_m);
    };
    if (r.found && o.mast)
      if (auto mast = find_any_mast(m.region.cloud_board, r.T_board_antenna, model->size_m, c, objects, o);
          mast && !known(*mast)) {
        objects.mast = m.mast = std::move(mast);
        auto with_mast = register_with_mast(*model, scene.points_board.size(), r.candidates, m, c, objects, o);
        // With the mast known, every pose that fits hangs against it, or none fits and the first
        // answer does: either way the first registration found the mast, not the panel.
        const auto& answer_model = r.panel_shape ? r.panel_shape->model : *model;
        if (!with_mast.found && !with_mast.against_mast &&
            registration::mast_gap(answer_model, r.T_board_antenna, *m.mast) < o.registration.min_mast_gap_m)
          with_mast = registration::found_only_the_mast(*model, with_mast.proposed);
        if (with_mast.found || with_mast.against_mast) r = std::move(with_mast);
      }
    if (!r.found) {
      m.error = r.why_not;
      return;
    }
    apply_registration(m, *model, r, c, o);
    if (m.error) return;
  }
  m.attitude = antenna_attitude(*c.board, m.R_board_antenna, m.cov_board, *c.site);
  if (!m.rivals_board.empty()) widen_for_rivals(m.attitude, m.R_board_antenna, m.rivals_board, *c.board);
  if (!m.face_rivals_board.empty())
    widen_for_rivals(m.attitude, m.R_board_antenna, m.face_rivals_board, *c.board, "face points against the outline");
  std::vector<Mat3> edge_rivals_board;  // the result without a long edge that decides it against the others
  for (const auto& e : m.long_edges_left_out)
    if (e.disagrees) edge_rivals_board.push_back(e.T_board_antenna.linear());
  if (!edge_rivals_board.empty())
    widen_for_rivals(m.attitude, m.R_board_antenna, edge_rivals_board, *c.board, "one long edge against the rest");
  if (auto w = imprecision_warning(m.attitude, o)) m.warnings.push_back(std::move(*w));
}

}  // namespace antpose::measure
