#include "antpose/sim/antenna_capture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/sim/random.hpp"

namespace antpose::sim {

namespace {

constexpr std::uint32_t kWalkStreams = 0xa1c5u;  // make_rng's salt of the wide walks

std::vector<std::size_t> panel_indices(const std::vector<MeshObject>& meshes, const AntennaLayout& layout) {
  std::vector<std::size_t> out;
  for (const auto& a : layout.antennas)
    for (std::size_t m = 0; m < meshes.size(); ++m)
      if (meshes[m].name == a.name) out.push_back(m);
  if (out.size() != layout.antennas.size()) throw std::logic_error("panel_indices: a panel has no mesh");
  return out;
}

std::vector<Vec3> site_points(const AntennaLayout& layout, const camera::BoardSpec& board, const BoardPlacement& pl) {
  std::vector<Vec3> pts = antenna_points(layout);
  const auto bpts = board_points(board, pl, 0.5 * board.square_m);
  pts.insert(pts.end(), bpts.begin(), bpts.end());
  return pts;
}

// The classic walk's timing: still for 3 s (first photo in it), then each move at a hand-held
// pace (≤ 25 °/s mean turn, ≤ 0.8 m/s), a 0.7 s pause, the photo in the middle of the pause.
Trajectory classic_timing(const std::vector<Waypoint>& wp, std::vector<double>& shot_times) {
  Trajectory tr(wp.front().R_world_device, wp.front().p_world_device);
  tr.hold(3.0);
  shot_times.push_back(2.6);
  for (std::size_t k = 1; k < wp.size(); ++k) {
    const double angle = rad2deg(rotation_distance(wp[k - 1].R_world_device, wp[k].R_world_device));
    const double distance = (wp[k].p_world_device - wp[k - 1].p_world_device).norm();
    const double T = std::clamp(std::max(kMinJerkPeak * angle / 25.0, kMinJerkPeak * distance / 0.8), 1.0, 4.0);
    tr.move_to(wp[k].R_world_device, wp[k].p_world_device, T);
    shot_times.push_back(tr.duration() + 0.35);
    tr.hold(0.7);
  }
  tr.hold(1.5);
  return tr;
}

// The wide walk's timing: 2 s still, then for each photo its drawn hold (the photo at its drawn
// instant), walking between them at the drawn speed with the gait bob, turning at up to the
// drawn rate (the minimum-jerk peak), never quicker than 0.4 s.
Trajectory wide_timing(const std::vector<Waypoint>& wp, const WalkDraw& w, std::vector<double>& shot_times) {
  Trajectory tr(wp.front().R_world_device, wp.front().p_world_device);
  tr.hold(2.0);
  for (std::size_t k = 0; k < wp.size(); ++k) {
    if (k > 0) {
      const double angle = rad2deg(rotation_distance(wp[k - 1].R_world_device, wp[k].R_world_device));
      const double distance = (wp[k].p_world_device - wp[k - 1].p_world_device).norm();
      const double T = std::max({distance / w.walk_speed_m_s, kMinJerkPeak * angle / w.max_turn_deg_s, 0.4});
      // A step or more: the body bobs; a shuffle of a few centimetres does not.
      if (distance >= 0.1)
        tr.walk_to(wp[k].R_world_device, wp[k].p_world_device, T, w.bob);
      else
        tr.move_to(wp[k].R_world_device, wp[k].p_world_device, T);
    }
    shot_times.push_back(tr.duration() + w.instants[k] * w.holds_s[k]);
    tr.hold(w.holds_s[k]);
  }
  tr.hold(1.5);
  return tr;
}

// The magnetised mast: magnetic north turned by 3–8° (either way) at `p_reference`.
std::vector<MagneticDipole> draw_dipoles(const AntennaLayout& layout, const Vec3& field_world_uT,
                                         const Vec3& p_reference, std::mt19937_64& rng) {
  const double target = deg2rad(uniform(rng, 3.0, 8.0)) * (uniform(rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0);
  return mast_dipoles(layout, field_world_uT, p_reference, target, rng);
}

constexpr double kMinWidthPx = 60.0, kMaxWidthPx = 400.0;  // a panel across its axis in its region photo

// The views of a wide site: every panel at least half unoccluded in three photos and, in one of
// them, at least 70 % unoccluded and 60–400 px wide across its axis (with margins for the tremor
// the photos add), and no background object in front of any part of a panel in any photo (they
// stand behind the mast: this catches a crown or a corner that reaches round it). `foreground`
// holds the board, the mast, panels and mounts, the tripod; the background adds buildings and
// trees.
bool wide_views_admissible(const PhotoRenderer& low, const Scene& foreground, const Background& background,
                           const std::vector<std::size_t>& panel_mesh, const std::vector<CameraPose>& poses,
                           const AntennaLayout& layout, const camera::CameraIntrinsics& K) {
  Scene full = foreground;
  const auto buildings = background_patches(background);
  const auto trees = background_meshes(background);
  full.patches.insert(full.patches.end(), buildings.begin(), buildings.end());
  full.meshes.insert(full.meshes.end(), trees.begin(), trees.end());
  std::vector<std::vector<double>> fractions(panel_mesh.size());
  for (const auto& pose : poses) {
    const auto f = visible_fractions(low, full, panel_mesh, pose);
    if (background.kind != BackgroundKind::kSky && f != visible_fractions(low, foreground, panel_mesh, pose))
      return false;
    for (std::size_t k = 0; k < f.size(); ++k) fractions[k].push_back(f[k]);
  }
  for (std::size_t k = 0; k < fractions.size(); ++k) {
    const auto& per_shot = fractions[k];
    const auto half = std::count_if(per_shot.begin(), per_shot.end(), [](double f) { return f >= 0.55; });
    bool region_photo = false;
    for (std::size_t i = 0; i < poses.size() && !region_photo; ++i) {
      const double width = apparent_width_px(K, poses[i], layout.antennas[k]);
      region_photo = per_shot[i] >= 0.75 && width >= kMinWidthPx + 2 && width <= kMaxWidthPx - 10;
    }
    if (half < 3 || !region_photo) return false;
  }
  return true;
}

WideSiteOptions wide_options(const CaptureScenario& sc, const camera::CameraIntrinsics& native) {
  WideSiteOptions o;
  o.setting = sc.setting;
  o.antennas = sc.antennas;
  o.photos = sc.photos;
  o.native = native;
  o.fixes = sc.wide;
  o.fixes.radome = sc.radome;
  o.fixes.board_max_distance_m = sc.board_max_distance_m;
  o.fixes.time_offset_s = sc.device.time_offset_s;
  return o;
}

// The device as a wide site's photos show it.
void apply_site(SimulatedDevice& d, const SiteDraw& site) {
  d.native_intrinsics = d.intrinsics;
  d.intrinsics = site.photo.camera;
  d.photo_scale = site.photo.scale;
  d.time_offset_s = site.time_offset_s;
  d.sensor.jpeg_quality = site.photo.jpeg_quality;
  d.sensor.blur_sigma_px = site.photo.blur_sigma_px;
  d.sensor.noise_scale = site.photo.noise_scale;
  d.sensor.exposure_s = site.photo.exposure_s;
  d.sensor.gain = site.light.gain;
}

// This recording's accelerometer and gyroscope offsets against the phone's calibration. A MEMS
// offset moves with temperature (zero-g level about 0.1–0.5 mg/K, zero-rate level 0.01–0.05 °/s/K
// in phone IMUs' datasheets: ST LSM6DSO, LSM6DS3) and from one power-up to the next, and a site
// is photographed days and kelvins away from the phone's calibration: 1σ per axis 1.5 mg and
// 0.05 °/s. From a stream of its own, so a seed's scene and walk are not changed by it.
void shift_offsets(SimulatedDevice& d, std::uint64_t seed) {
  auto rng = make_rng(seed, 0xb1a5, kWalkStreams);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < 3; ++i) d.phone.accelerometer.bias(i) += 1.5e-3 * 9.80665 * normal(rng);
  for (int i = 0; i < 3; ++i) d.phone.gyroscope.bias(i) += deg2rad(0.05) * normal(rng);
}

}  // namespace

AntennaSitePlan plan_classic_antenna_site(const CaptureScenario& sc, const SimulatedDevice& d,
                                          const camera::BoardSpec& board, const BoardTexture& texture,
                                          const Vec3& field_world_uT, std::mt19937_64& rng) {
  AntennaSitePlan plan;
  AntennaTruth& at = plan.truth;
  at.radome = sc.radome.value_or(RadomeLook::kWeathered);
  const bool roof = sc.setting == AntennaSetting::kRooftop;
  const double board_max = sc.board_max_distance_m.value_or(4.0);
  const camera::CameraIntrinsics& K = d.intrinsics;
  const int factor = std::max(1, std::min(K.width, K.height) / 200);
  const PhotoRenderer low(scaled_intrinsics(K, factor), 1);
  const Vec3 up = Vec3::UnitZ();
  std::vector<Waypoint> waypoints;
  bool ok = false;
  double half_site = 0.0;
  // Three panels on a rooftop, each at least 60 % seen in every photo, are rare draws: one in
  // 19–139, and some seeds have none in 400. Each attempt costs ~10 ms, and the first admissible
  // one ends the loop, so more attempts change no scene found before.
  for (int attempt = 0; attempt < 4000 && !ok; ++attempt) {
    at.layout = draw_antenna_layout(sc.setting, sc.antennas, rng);
    // The walk: an arc around the mast at horizontal distance D, centred on azimuth phi0 (from
    // the mast), spanning `span` of viewing directions; the board between walk and mast.
    ArcWalk walk;
    walk.distance_m = roof ? uniform(rng, 4.0, 10.0) : uniform(rng, 15.0, 30.0);
    walk.azimuth = uniform(rng, 0.0, 2.0 * std::numbers::pi);
    walk.height_m = uniform(rng, 1.4, 1.7);
    walk.photos = sc.photos;
    walk.board_max_m = board_max;
    const Vec3 out_dir(std::sin(walk.azimuth), std::cos(walk.azimuth), 0.0);
    const Vec3 C = walk.distance_m * out_dir + walk.height_m * up;
    const double b = board_max * uniform(rng, 0.55, 0.85), lateral = uniform(rng, -0.3, 0.3);
    const double zb = roof ? uniform(rng, 1.2, 1.6) : uniform(rng, 1.5, 1.9);
    // The board stays within board_max (4 m by default) of the phone, which bounds the walk's
    // half-length to sqrt(board_max² − b²) (less a margin for the jitter) and so the span at
    // long range (ground).
    const double s_max = std::sqrt(std::pow(board_max - 0.15, 2) - b * b) - 0.35;
    walk.span_max = std::min(2.0 * std::asin(std::min(1.0, s_max / walk.distance_m)),
                             deg2rad(roof ? uniform(rng, 34.0, 40.0) : 26.0));
    walk.span_min = deg2rad(roof ? 25.0 : 10.0);
    Vec3 Bc = C - b * out_dir + lateral * out_dir.cross(up);
    Bc.z() = zb;
    walk.board_centre = Bc;
    const BoardPlacement pl = tripod_board(board, texture.face_normal_z, Bc, C);  // facing the middle of the walk
    // The widest span (in 2° steps) whose every view fits: the baseline matters most.
    const auto views = fit_arc_views(walk, K, site_points(at.layout, board, pl), rng);
    if (!views) continue;
    // Every antenna mostly unoccluded (by the mast, the other panels, the board) in every view.
    half_site = walk.distance_m + 6.0;
    // (The site's patches cannot hide a panel: the phone stands on the roof or the ground below
    // it; leaving them out saves drawing their textures for every attempt.)
    Scene check;
    check.patches.push_back(board_patch(texture, pl.R_world_board, pl.p_world_board, "board"));
    check.meshes = antenna_meshes(at.layout, RadomeLook::kPlain, sc.seed);
    const auto panel_mesh = panel_indices(check.meshes, at.layout);
    bool fine = true;
    for (const auto& pose : views->poses) {
      for (const double f : visible_fractions(low, check, panel_mesh, pose)) fine = fine && f >= 0.6;
      if (!fine) break;
    }
    if (!fine) continue;
    plan.board = pl;
    waypoints.clear();
    for (const auto& pose : views->poses)
      waypoints.push_back(device_from_camera(d, pose.R_world_camera, pose.p_world_camera));
    ok = true;
  }
  if (!ok)
    throw std::runtime_error(fmt::format("no admissible antenna scene and walk for {} photos of {}x{} px (image too small?)",
                                         sc.photos, K.width, K.height));
  plan.meshes = antenna_meshes(at.layout, at.radome, sc.seed);
  plan.panel_mesh = panel_indices(plan.meshes, at.layout);
  const auto tripod = tripod_meshes(board, plan.board, 0.0);
  plan.meshes.insert(plan.meshes.end(), tripod.begin(), tripod.end());
  plan.surfaces = antenna_site_patches(at.layout, half_site, sc.seed);
  plan.trajectory = classic_timing(waypoints, plan.shot_times);
  if (sc.disturbance)
    at.dipoles = draw_dipoles(at.layout, field_world_uT, waypoints[waypoints.size() / 2].p_world_device, rng);
  return plan;
}

AntennaSitePlan plan_wide_antenna_site(const CaptureScenario& sc, SimulatedDevice& d, const camera::BoardSpec& board,
                                       const BoardTexture& texture, const Vec3& field_world_uT) {
  const WideSiteOptions options = wide_options(sc, d.intrinsics);
  constexpr int kAttempts = 400;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const SiteDraw site = draw_wide_site(sc.seed, options, attempt);
    auto rng = make_rng(sc.seed, static_cast<std::uint64_t>(attempt), kWalkStreams);
    const WalkDraw& w = site.walk;
    const Vec3 C = walk_middle(w);
    ArcWalk walk;
    walk.distance_m = w.distance_m, walk.azimuth = w.azimuth, walk.height_m = w.height_m;
    walk.photos = sc.photos;
    walk.board_centre = w.board_centre;
    walk.board_max_m = w.board_max_m;
    // As wide as the board allows (its distance bounds the walk's half-length), up to 50°.
    const double ahead = Vec2(C.x() - w.board_centre.x(), C.y() - w.board_centre.y()).norm();
    const double s_max = std::sqrt(std::pow(w.board_max_m - 0.15, 2) - ahead * ahead) - 0.35;
    walk.span_max = std::min(2.0 * std::asin(std::clamp(s_max / w.distance_m, 0.0, 1.0)), deg2rad(50.0));
    walk.span_min = deg2rad(sc.setting == AntennaSetting::kRooftop ? 10.0 : 4.0);
    const BoardPlacement pl = tripod_board(board, texture.face_normal_z, w.board_centre, C);
    const camera::CameraIntrinsics& K = site.photo.camera;
    const auto views = fit_arc_views(walk, K, site_points(site.layout, board, pl), rng);
    if (!views) continue;
    AntennaSitePlan plan;
    plan.occlusion_px = 300;
    Scene foreground;
    foreground.patches.push_back(board_patch(texture, pl.R_world_board, pl.p_world_board, "board"));
    foreground.meshes = finished_antenna_meshes(site.layout, sc.seed);
    const auto tripod = tripod_meshes(board, pl, 0.0);
    foreground.meshes.insert(foreground.meshes.end(), tripod.begin(), tripod.end());
    const PhotoRenderer low(scaled_intrinsics(K, std::max(1, std::min(K.width, K.height) / plan.occlusion_px)), 1);
    if (!wide_views_admissible(low, foreground, site.background, panel_indices(foreground.meshes, site.layout),
                               views->poses, site.layout, K))
      continue;
    apply_site(d, site);
    shift_offsets(d, sc.seed);
    plan.board = pl;
    std::vector<Waypoint> waypoints;
    for (const auto& pose : views->poses)
      waypoints.push_back(device_from_camera(d, pose.R_world_camera, pose.p_world_camera));
    plan.meshes = foreground.meshes;
    const auto trees = background_meshes(site.background);
    plan.meshes.insert(plan.meshes.end(), trees.begin(), trees.end());
    plan.panel_mesh = panel_indices(plan.meshes, site.layout);
    plan.surfaces = antenna_site_patches(site.layout, site.roof_half_m, sc.seed);
    const auto buildings = background_patches(site.background);
    plan.surfaces.insert(plan.surfaces.end(), buildings.begin(), buildings.end());
    plan.trajectory = wide_timing(waypoints, w, plan.shot_times);
    plan.tremor_rms_rad = deg2rad(w.tremor_deg);
    plan.lighting = site_lighting(site.light);
    plan.truth.layout = site.layout;
    plan.truth.radome = site.layout.antennas.front().finish.look;
    if (sc.disturbance) {
      auto dipole_rng = make_rng(sc.seed, 0xd1901e, kWalkStreams);
      plan.truth.dipoles =
          draw_dipoles(site.layout, field_world_uT, waypoints[waypoints.size() / 2].p_world_device, dipole_rng);
    }
    plan.truth.wide = site;
    return plan;
  }
  throw std::runtime_error(fmt::format(
      "no admissible wide antenna site and walk in {} draws for {} photos of {}x{} px native (image too small, or "
      "fixed choices that cannot be met together?)",
      kAttempts, sc.photos, d.intrinsics.width, d.intrinsics.height));
}

double apparent_width_px(const camera::CameraIntrinsics& K, const CameraPose& pose, const SimAntenna& a) {
  const auto at = [&](const Vec3& p_antenna) { return project_world(K, pose, a.p_world_antenna + a.R_world_antenna * p_antenna); };
  const auto top = at(Vec3(0.0, 0.0, a.spec.height_m / 2)), bottom = at(Vec3(0.0, 0.0, -a.spec.height_m / 2));
  if (!top || !bottom) return 0.0;
  const Vec2 axis = (*top - *bottom).normalized(), across(-axis.y(), axis.x());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const double x : {-0.5, 0.5})
    for (const double y : {-0.5, 0.5})
      if (const auto uv = at(Vec3(x * a.spec.width_m, y * a.spec.depth_m, 0.0))) {
        lo = std::min(lo, uv->dot(across)), hi = std::max(hi, uv->dot(across));
      }
  return hi > lo ? hi - lo : 0.0;
}

void choose_rois(AntennaTruth& at, const std::vector<std::vector<PixelBox>>& boxes,
                 const std::vector<std::vector<double>>& width_px, const camera::CameraIntrinsics& K) {
  at.roi_shot.clear(), at.roi.clear(), at.width_px.clear();
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    const int shots = static_cast<int>(boxes[k].size());
    int shot = shots / 2;
    std::array<double, 4> margins{0.05, 0.05, 0.05, 0.05};
    if (at.wide) {
      // A photo where the panel is 70 % unoccluded and 60–400 px wide (the planning's promise).
      std::vector<int> admissible;
      for (int i = 0; i < shots; ++i) {
        const auto shot_index = static_cast<std::size_t>(i);
        const double width = width_px[k][shot_index];
        if (at.visible_fraction[k][shot_index] >= 0.7 && width >= kMinWidthPx && width <= kMaxWidthPx)
          admissible.push_back(i);
      }
      if (admissible.empty())
        throw std::runtime_error(fmt::format("internal: {} shows 70 % at 60–400 px in no photo", at.layout.antennas[k].name));
      const RoiDraw& r = at.wide->roi[k];
      shot = admissible[std::min(admissible.size() - 1, static_cast<std::size_t>(r.pick * admissible.size()))];
      margins = r.margin_fraction;
    }
    at.roi_shot.push_back(shot);
    at.roi.push_back(roi_rect(boxes[k][static_cast<std::size_t>(shot)], margins, K.width, K.height));
    at.width_px.push_back(width_px[k][static_cast<std::size_t>(shot)]);
  }
}

}  // namespace antpose::sim
