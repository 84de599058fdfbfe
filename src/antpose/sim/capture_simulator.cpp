#include "antpose/sim/capture_simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/geomag/wmm.hpp"
#include "antpose/sim/antenna_capture.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/capture_geometry.hpp"
#include "antpose/sim/random.hpp"
#include "antpose/geomag/earth_model.hpp"

namespace antpose::sim {
namespace fs = std::filesystem;

namespace {

constexpr std::uint32_t kCaptureStreams = 0xca9u;  // make_rng's salt

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v;
  do {
    const double x = n(rng), y = n(rng), z = n(rng);  // sequenced: deterministic order
    v = Vec3(x, y, z);
  } while (v.norm() < 1e-6);
  return v.normalized();
}

constexpr double kMinRateDegS = 10.0, kMaxRateDegS = 40.0;

struct PlannedPlacement {
  std::vector<Waypoint> waypoints;  // N + 1
  std::vector<double> durations;    // N moves
};

// Waypoints of the walk around one placement: the camera on an arc around the nominal viewing
// direction v0, looking at a point near the board centre, alternating roll so that every move
// turns the phone by ≥ 10°; move durations give a peak (mid-move) rate of 15–32 °/s.
PlannedPlacement plan_walk(const SimulatedDevice& d, const camera::BoardSpec& board, const BoardPlacement& pl,
                           const Vec3& v0, int photos, std::mt19937_64& rng) {
  const Vec3 centre = pl.p_world_board + pl.R_world_board * board_centre(board);
  const Vec3 up = Vec3::UnitZ();
  const Vec3 e1 = (std::abs(v0.dot(up)) < 0.95 ? up.cross(v0) : Vec3::UnitX().cross(v0)).normalized();
  const Vec3 e2 = v0.cross(e1);
  const auto [lo, hi] = board.extent();
  const double size = (hi - lo).norm();
  const double psi0 = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  const double sweep = deg2rad(uniform(rng, 200.0, 280.0));
  double distance = uniform(rng, 0.7, 1.3);
  const double roll_sign = uniform(rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0;
  PlannedPlacement plan;
  for (int k = 0; k <= photos; ++k) {
    const double psi = psi0 + sweep * k / photos;
    const double phi = deg2rad(uniform(rng, 8.0, 32.0));
    distance = std::clamp(distance + uniform(rng, -0.2, 0.2), 0.65, 1.45);
    const Vec3 v = std::cos(phi) * v0 + std::sin(phi) * (std::cos(psi) * e1 + std::sin(psi) * e2);
    const Vec3 c = centre + distance * v;
    const double ox = uniform(rng, -0.15, 0.15) * size, oy = uniform(rng, -0.15, 0.15) * size;  // sequenced draws
    const Vec3 target = centre + pl.R_world_board * Vec3(ox, oy, 0.0);
    // Image "down" towards the person: straight down for a level view, the horizontal direction
    // from the board to the phone for a view from above.
    Vec3 h = c - centre;
    h.z() = 0.0;
    const Vec3 down = -up + (h.norm() > 1e-6 ? Vec3(h.normalized()) : Vec3::Zero());
    const double roll = roll_sign * ((k % 2 == 0) ? 1.0 : -1.0) * deg2rad(uniform(rng, 6.0, 14.0));
    plan.waypoints.push_back(device_from_camera(d, look_rotation(target - c, down, roll), c));
  }
  for (int k = 0; k < photos; ++k) {
    const auto& a = plan.waypoints[static_cast<std::size_t>(k)];
    const auto& b = plan.waypoints[static_cast<std::size_t>(k + 1)];
    const double angle = rad2deg(rotation_distance(a.R_world_device, b.R_world_device));
    const double rate = uniform(rng, 15.0, 32.0);
    double T = kMinJerkPeak * angle / rate;
    T = std::max(T, kMinJerkPeak * (b.p_world_device - a.p_world_device).norm() / 1.2);  // ≤ 1.2 m/s
    plan.durations.push_back(std::clamp(T, 0.4, 3.0));
  }
  return plan;
}

// The walk alone (no tremor): at every mid-move instant the rate is inside [13, 35] °/s (margin
// for the tremor added later), the camera 0.6–1.5 m from the board centre at hand height, and
// the board with half a square of margin at least 1.5 % of the image width inside the image.
bool walk_admissible(const SimulatedDevice& d, const camera::BoardSpec& board, const BoardPlacement& pl,
                     const PlannedPlacement& plan) {
  Trajectory tr(plan.waypoints.front().R_world_device, plan.waypoints.front().p_world_device);
  tr.hold(0.5);
  for (std::size_t k = 1; k < plan.waypoints.size(); ++k) {
    const double t_mid = tr.duration() + 0.5 * plan.durations[k - 1];
    tr.move_to(plan.waypoints[k].R_world_device, plan.waypoints[k].p_world_device, plan.durations[k - 1]);
    const double rate = rad2deg(tr.angular_velocity_device(t_mid).norm());
    if (rate < kMinRateDegS + 3.0 || rate > kMaxRateDegS - 5.0) return false;
    const CameraPose pose = camera_pose(d, tr, t_mid);
    const double dist = (pose.p_world_camera - (pl.p_world_board + pl.R_world_board * board_centre(board))).norm();
    if (dist < 0.6 || dist > 1.5) return false;
    if (pose.p_world_camera.z() < 0.3 || pose.p_world_camera.z() > 2.1) return false;
    if (!board_in_view(d.intrinsics, pose, board, pl.R_world_board, pl.p_world_board, 0.5 * board.square_m,
                       0.015 * d.intrinsics.width))
      return false;
  }
  return true;
}

void write_binary(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
}

}  // namespace

// --- device ---------------------------------------------------------------------------------

SimulatedDevice make_device(const DeviceOptions& o, std::uint64_t seed) {
  if (o.width < 64 || o.width > 8000 || o.height < 64 || o.height > 8000)
    throw std::invalid_argument(fmt::format("image size {}x{} px is outside 64..8000", o.width, o.height));
  if (o.jpeg_quality < 1 || o.jpeg_quality > 100)
    throw std::invalid_argument(fmt::format("JPEG quality {} is outside 1..100", o.jpeg_quality));
  if (!(o.blur_sigma_px >= 0.0) || !(o.noise_scale >= 0.0) || !(o.exposure_s >= 0.0) || o.blur_sigma_px > 20.0)
    throw std::invalid_argument("blur (0..20 px), noise scale and exposure must be >= 0");
  if (o.time_offset_s && !(std::abs(*o.time_offset_s) <= 1.0))
    throw std::invalid_argument(fmt::format("time offset {} s is outside ±1 s", *o.time_offset_s));
  if (o.supersampling < 1 || o.supersampling > 8)
    throw std::invalid_argument(fmt::format("supersampling {} is outside 1..8", o.supersampling));
  auto rng = make_rng(seed, 0xde71ce, kCaptureStreams);
  SimulatedDevice d;
  if (o.phone == "ideal")
    d.phone = PhoneModel::ideal();
  else if (o.phone == "typical")
    d.phone = PhoneModel::typical();
  else if (o.phone == "random")
    d.phone = PhoneModel::random(rng);
  else
    throw std::invalid_argument(fmt::format("phone '{}' is not ideal, typical or random", o.phone));

  auto& K = d.intrinsics;
  K.width = o.width, K.height = o.height;
  K.fx = 1300.0 * o.width / 1600.0 * (1.0 + uniform(rng, -0.03, 0.03));
  K.fy = K.fx * (1.0 + uniform(rng, -0.002, 0.002));
  K.cx = 0.5 * (o.width - 1) + uniform(rng, -0.01, 0.01) * o.width;
  K.cy = 0.5 * (o.height - 1) + uniform(rng, -0.01, 0.01) * o.height;
  // A phone main camera after the ISP's own correction: mild residual barrel/pincushion terms,
  // monotonic over the image (1 + 3 k1 r² + 5 k2 r⁴ + 7 k3 r⁶ > 0 for r ≤ 0.8).
  K.distortion = {0.10 * (1.0 + uniform(rng, -0.2, 0.2)), -0.25 * (1.0 + uniform(rng, -0.2, 0.2)),
                  uniform(rng, -5e-4, 5e-4), uniform(rng, -5e-4, 5e-4), 0.12 * (1.0 + uniform(rng, -0.2, 0.2))};

  const Vec3 axis = random_unit(rng);
  const double angle = deg2rad(uniform(rng, 1.0, 3.0));
  d.R_device_camera = camera::nominal_R_device_camera() * exp_so3(angle * axis);
  d.mounting_error_deg = rad2deg(angle);
  // Main camera near the top of the back: right of centre, 6 cm up, 4 mm behind the IMU.
  const double dx = uniform(rng, -0.005, 0.005), dy = uniform(rng, -0.005, 0.005);  // sequenced draws
  d.p_device_camera = Vec3(0.02 + dx, 0.06 + dy, -0.004);
  d.time_offset_s = o.time_offset_s ? *o.time_offset_s : uniform(rng, 0.010, 0.060);
  d.sensor.exposure_s = o.exposure_s;
  d.sensor.blur_sigma_px = o.blur_sigma_px;
  d.sensor.noise_scale = o.noise_scale;
  d.sensor.jpeg_quality = o.jpeg_quality;
  d.supersampling = o.supersampling;
  return d;
}

std::string to_string(Scenario s) {
  switch (s) {
    case Scenario::kCameraCalibration:
      return "camera-calibration";
    case Scenario::kJointCalibration:
      return "joint-calibration";
    case Scenario::kPlanes:
      return "planes";
    case Scenario::kAntenna:
      return "antenna";
  }
  return "unknown";
}

Scenario parse_scenario(const std::string& name) {
  if (name == "camera-calibration") return Scenario::kCameraCalibration;
  if (name == "joint-calibration") return Scenario::kJointCalibration;
  if (name == "planes") return Scenario::kPlanes;
  if (name == "antenna") return Scenario::kAntenna;
  throw std::invalid_argument(
      fmt::format("scenario '{}' is not camera-calibration, joint-calibration, planes or antenna", name));
}

std::string to_string(Distribution d) { return d == Distribution::kClassic ? "classic" : "wide"; }

Distribution parse_distribution(const std::string& name) {
  if (name == "classic") return Distribution::kClassic;
  if (name == "wide") return Distribution::kWide;
  throw InputError("--distribution", fmt::format("'{}' is not classic or wide", name));
}

camera::BoardSpec default_board(camera::BoardType type) {
  switch (type) {
    case camera::BoardType::kChessboard:
      return {type, 9, 6, 0.03, 0.0, ""};
    case camera::BoardType::kCircles:
      return {type, 7, 5, 0.04, 0.0, ""};
    case camera::BoardType::kAsymmetricCircles:
      return {type, 4, 11, 0.03, 0.0, ""};
    case camera::BoardType::kCharuco:
      return {type, 7, 5, 0.04, 0.03, "DICT_5X5_100"};
  }
  return {};
}

camera::BoardSpec antenna_board(camera::BoardType type) {
  switch (type) {
    case camera::BoardType::kChessboard:
      return {type, 9, 6, 0.07, 0.0, ""};
    case camera::BoardType::kCircles:
      return {type, 7, 5, 0.09, 0.0, ""};
    case camera::BoardType::kAsymmetricCircles:
      return {type, 4, 11, 0.07, 0.0, ""};
    case camera::BoardType::kCharuco:
      return {type, 7, 5, 0.09, 0.0675, "DICT_5X5_100"};
  }
  return {};
}

std::vector<BoardPlacement> joint_placements(const camera::BoardSpec& board, double face_normal_z) {
  const Vec3 up = Vec3::UnitZ();
  auto horizontal = [](double az_deg) { return Vec3(std::sin(deg2rad(az_deg)), std::cos(deg2rad(az_deg)), 0.0); };
  auto facing = [&](double tilt_deg, double az_deg) {
    return Vec3(std::sin(deg2rad(tilt_deg)) * horizontal(az_deg) + std::cos(deg2rad(tilt_deg)) * up);
  };
  // Board x to the right of a person looking at the face (along −n_out): (−n_out) × up.
  auto right_of_viewer = [&](const Vec3& n_out) { return Vec3((-n_out).cross(up)); };
  struct Def {
    const char* name;
    Vec3 n_out, x_hint;
  };
  const std::array<Def, 6> defs{{
      {"hor_0", up, horizontal(90.0)},    // face up, x towards magnetic east
      {"hor_60", up, horizontal(150.0)},  // face up, turned 60°
      {"tilt_20", facing(20.0, 200.0), right_of_viewer(facing(20.0, 200.0))},
      {"tilt_45", facing(45.0, 300.0), right_of_viewer(facing(45.0, 300.0))},
      {"vert_n", horizontal(0.0), right_of_viewer(horizontal(0.0))},    // upright, facing north
      {"vert_e", horizontal(90.0), right_of_viewer(horizontal(90.0))},  // upright, facing east
  }};
  const Vec3 centre_world(0.0, 0.0, 1.0);
  std::vector<BoardPlacement> out;
  for (const auto& def : defs) {
    BoardPlacement p;
    p.name = def.name;
    p.R_world_board = board_rotation(def.n_out, face_normal_z, def.x_hint);
    p.p_world_board = centre_world - p.R_world_board * board_centre(board);
    out.push_back(p);
  }
  return out;
}

// --- scenarios ------------------------------------------------------------------------------

SimulatedCapture simulate_capture(const CaptureScenario& sc, const fs::path& scratch) {
  if (sc.photos_per_placement < 2 || sc.photos_per_placement > 100)
    throw std::invalid_argument(fmt::format("{} photos per placement is outside 2..100", sc.photos_per_placement));
  if (sc.photos < 3 || sc.photos > 500)
    throw std::invalid_argument(fmt::format("{} photos is outside 3..500", sc.photos));
  const bool antenna = sc.scenario == Scenario::kAntenna;
  if (antenna && (sc.antennas < 1 || sc.antennas > 3))
    throw InputError("--antennas", fmt::format("{} is outside 1..3", sc.antennas));
  if (antenna && sc.photos > 60)
    throw InputError("--photos", fmt::format("{} is outside 3..60 for the antenna scenario", sc.photos));
  // Nearer than 2.5 m the walk has no room beside the board; farther than 15 m a 70 mm square is
  // under 15 px at 12 MP.
  if (sc.board_max_distance_m && !(*sc.board_max_distance_m >= 2.5 && *sc.board_max_distance_m <= 15.0))
    throw InputError("--board-max-distance", fmt::format("{} m is outside 2.5..15", *sc.board_max_distance_m));
  if (antenna && sc.distribution == Distribution::kClassic && sc.radome == RadomeLook::kRibbed)
    throw InputError("--radome",
                     "'ribbed' is drawn by --distribution wide only; classic radomes are plain or weathered");
  if (antenna && sc.distribution == Distribution::kWide) validate(sc.wide);
  SimulatedCapture out;
  out.device = make_device(sc.device, sc.device_seed.value_or(sc.seed));
  const SimulatedDevice& d = out.device;
  // The calibration-sized default board is too small at 1.5–4 m: the antenna scenario's own.
  const camera::BoardSpec default_of_type = default_board(sc.board.type);
  const bool is_default = sc.board.cols == default_of_type.cols && sc.board.rows == default_of_type.rows &&
                          sc.board.square_m == default_of_type.square_m;
  const camera::BoardSpec board = antenna && is_default ? antenna_board(sc.board.type) : sc.board;
  const BoardTexture texture = board_texture(board);

  // Site and field: world = ENU with y along magnetic north.
  const geomag::SiteField field = geomag::site_field(geomag::MagneticModel::wmm2025(), sc.site);
  out.declination_deg = rad2deg(field.declination);
  const Vec3 field_world_uT = rot_z(field.declination) * field.field_enu_uT;

  auto rng = make_rng(sc.seed, 0x5ce7e, kCaptureStreams);
  const bool joint = sc.scenario == Scenario::kJointCalibration;
  const bool has_board = sc.scenario != Scenario::kPlanes;
  Trajectory tr;
  std::vector<std::pair<double, std::size_t>> shot_times;  // (t_true, placement)
  std::optional<AntennaSitePlan> antenna_plan;
  if (joint) {
    out.placements = joint_placements(board, texture.face_normal_z);
    const Vec3 up = Vec3::UnitZ();
    bool first = true;
    for (std::size_t p = 0; p < out.placements.size(); ++p) {
      const BoardPlacement& pl = out.placements[p];
      const Vec3 n_out = pl.R_world_board.col(2) * texture.face_normal_z;
      // Nominal viewing direction: in front of the face, a little above; for a board lying
      // (nearly) flat, from the side its rows run towards (the person's side).
      Vec3 v0 = n_out + 0.3 * up;
      if (n_out.z() > 0.9) {
        Vec3 h = pl.R_world_board.col(1);
        h.z() = 0.0;
        v0 = n_out + 0.5 * h.normalized();
      }
      v0.normalize();
      PlannedPlacement plan;
      bool ok = false;
      for (int attempt = 0; attempt < 200 && !ok; ++attempt) {
        plan = plan_walk(d, board, pl, v0, sc.photos_per_placement, rng);
        ok = walk_admissible(d, board, pl, plan);
      }
      if (!ok)
        throw std::runtime_error(
            fmt::format("no admissible walk around placement {} (board too large for the camera?)", pl.name));
      if (first) {
        tr = Trajectory(plan.waypoints.front().R_world_device, plan.waypoints.front().p_world_device);
        tr.hold(2.0);
        first = false;
      } else {
        // The board is moved to its next placement while the phone waits, then the walk resumes.
        tr.move_to(plan.waypoints.front().R_world_device, plan.waypoints.front().p_world_device, 3.0).hold(1.5);
      }
      for (std::size_t k = 1; k < plan.waypoints.size(); ++k) {
        shot_times.emplace_back(tr.duration() + 0.5 * plan.durations[k - 1], p);
        tr.move_to(plan.waypoints[k].R_world_device, plan.waypoints[k].p_world_device, plan.durations[k - 1]);
      }
    }
    tr.hold(1.0);
  } else if (antenna) {
    antenna_plan = sc.distribution == Distribution::kClassic
                       ? plan_classic_antenna_site(sc, d, board, texture, field_world_uT, rng)
                       : plan_wide_antenna_site(sc, out.device, board, texture, field_world_uT);
    out.placements.push_back(antenna_plan->board);
    out.meshes = antenna_plan->meshes;
    out.surfaces = antenna_plan->surfaces;
    tr = antenna_plan->trajectory;
    for (const double t : antenna_plan->shot_times) shot_times.emplace_back(t, 0);
    out.antenna = antenna_plan->truth;
  } else if (!has_board) {
    // A walk through the room: positions at least 2 m from the walls, looking at a wall or at
    // the ground 1–3 m ahead, each move turning the phone at a hand-held rate.
    std::vector<Waypoint> poses;
    for (int k = 0; k <= sc.photos; ++k) {
      const double x = uniform(rng, -3.0, 3.0), y = uniform(rng, -3.0, 3.0), z = uniform(rng, 1.1, 1.7);
      const Vec3 c(x, y, z);
      const double heading = uniform(rng, 0.0, 2.0 * std::numbers::pi);
      const Vec3 ahead(std::sin(heading), std::cos(heading), 0.0);
      const bool ground = uniform(rng, 0.0, 1.0) < 0.4;
      const double reach = uniform(rng, 1.0, 3.0), height = uniform(rng, 0.3, 2.7);
      const Vec3 target =
          ground ? Vec3(c + reach * ahead - Vec3(0.0, 0.0, z)) : Vec3(c + 8.0 * ahead + Vec3(0.0, 0.0, height - z));
      const double roll = deg2rad(uniform(rng, -10.0, 10.0));
      poses.push_back(device_from_camera(d, look_rotation(target - c, -Vec3::UnitZ(), roll), c));
    }
    tr = Trajectory(poses.front().R_world_device, poses.front().p_world_device);
    tr.hold(2.0);
    for (std::size_t k = 1; k < poses.size(); ++k) {
      const double angle = rad2deg(rotation_distance(poses[k - 1].R_world_device, poses[k].R_world_device));
      const double distance = (poses[k].p_world_device - poses[k - 1].p_world_device).norm();
      const double T = std::clamp(
          std::max(kMinJerkPeak * angle / uniform(rng, 15.0, 32.0), kMinJerkPeak * distance / 1.2), 0.6, 6.0);
      shot_times.emplace_back(tr.duration() + 0.5 * T, 0);
      tr.move_to(poses[k].R_world_device, poses[k].p_world_device, T);
    }
    tr.hold(1.0);
  } else {
    // One board on a stand, upright facing north, centre 1.2 m high.
    BoardPlacement stand;
    stand.name = "stand";
    const Vec3 n_out = Vec3::UnitY();
    stand.R_world_board = board_rotation(n_out, texture.face_normal_z, (-n_out).cross(Vec3::UnitZ()));
    const Vec3 centre(0.0, 0.0, 1.2);
    stand.p_world_board = centre - stand.R_world_board * board_centre(board);
    out.placements.push_back(stand);
    const Vec3 e1 = Vec3::UnitX(), e2 = Vec3::UnitZ();
    // Stratified target pixels: the board centre lands in each cell of a grid over the image.
    const int gx = std::max(1, static_cast<int>(std::lround(std::sqrt(sc.photos * 4.0 / 3.0))));
    const int gy = (sc.photos + gx - 1) / gx;
    std::vector<Waypoint> poses;
    for (int k = 0; k < sc.photos; ++k) {
      const int cx = k % gx, cy = (k / gx) % gy;
      bool ok = false;
      for (int attempt = 0; attempt < 1000 && !ok; ++attempt) {
        const double fu = (cx + uniform(rng, 0.1, 0.9)) / gx, fv = (cy + uniform(rng, 0.1, 0.9)) / gy;
        // A board centred in a corner cell only fits when small: widen the range towards 1.6 m
        // for the views that do not fit at first.
        const double distance = uniform(rng, 0.35, 1.0 + 0.6 * std::min(1.0, attempt / 300.0));
        const double phi = deg2rad(uniform(rng, 0.0, 50.0)), psi = uniform(rng, 0.0, 2.0 * std::numbers::pi);
        const Vec3 v = std::cos(phi) * n_out + std::sin(phi) * (std::cos(psi) * e1 + std::sin(psi) * e2);
        const Vec3 c = centre + distance * v;
        // Not from below the board: a phone held under a board looks up into the bright sky,
        // where nobody calibrates.
        if (c.z() < centre.z() - 0.15) continue;
        const double roll = deg2rad(uniform(rng, -20.0, 20.0));
        const Mat3 R0 = look_rotation(centre - c, -Vec3::UnitZ(), roll);
        // Turn the camera so that the ray through the target pixel passes through the centre.
        const Vec3 ray = d.intrinsics.ray(Vec2(fu * (d.intrinsics.width - 1), fv * (d.intrinsics.height - 1)));
        const Mat3 R_world_camera = R0 * rotation_between(ray, Vec3::UnitZ());
        const CameraPose pose{R_world_camera, c};
        if (!board_in_view(d.intrinsics, pose, board, stand.R_world_board, stand.p_world_board, 0.5 * board.square_m,
                           0.01 * d.intrinsics.width))
          continue;
        poses.push_back(device_from_camera(d, R_world_camera, c));
        ok = true;
      }
      if (!ok)
        throw std::runtime_error(
            fmt::format("no admissible view {} of the board (board too large for the camera?)", k));
    }
    tr = Trajectory(poses.front().R_world_device, poses.front().p_world_device);
    for (std::size_t k = 0; k < poses.size(); ++k) {
      if (k > 0) tr.move_to(poses[k].R_world_device, poses[k].p_world_device, 1.2);
      shot_times.emplace_back(tr.duration() + 0.75, 0);
      tr.hold(1.5);
    }
  }
  // Hand tremor on top (0.05° rms unless a wide site drew its own, 0.2 mm rms): keeps the
  // "still" photos realistically still.
  tr.with_tremor(antenna_plan ? antenna_plan->tremor_rms_rad : deg2rad(0.05), 2e-4, sc.seed);

  // IMU streams and orientation truth.
  ImuSimulation imu;
  imu.trajectory = tr;
  imu.phone = d.phone;
  imu.field_world_uT = field_world_uT;
  imu.gravity = geomag::normal_gravity(sc.site.lat_deg, sc.site.alt_m);
  imu.site = sc.site;
  imu.time_origin = sc.site.date + "T02:00:00Z";
  imu.kind = has_board ? to_string(sc.scenario) : "imu-log";  // no capture kind for "photos of a room" yet
  imu.truth_world = "enu-magnetic";
  imu.seed = sc.seed;
  if (out.antenna) imu.dipoles = out.antenna->dipoles;
  out.capture = simulate_imu(imu);
  Capture& c = out.capture;
  c.root = scratch;

  // Photos.
  fs::create_directories(scratch / "images");
  const PhotoRenderer renderer(d.intrinsics, d.supersampling);
  if (!antenna) out.surfaces = room_patches(sc.seed);
  const auto& room = out.surfaces;
  Scene scene;
  scene.meshes = out.meshes;
  const Lighting lighting = antenna_plan ? antenna_plan->lighting : Lighting{};
  std::vector<Vec3> antenna_pts;
  std::vector<std::vector<Vec3>> panel_vertices;   // per antenna, world
  std::vector<std::vector<PixelBox>> panel_boxes;  // [antenna][shot]: projected rendered panel
  std::vector<std::vector<double>> panel_widths;   // [antenna][shot]: apparent width, px
  std::unique_ptr<PhotoRenderer> low;
  if (antenna) {
    const AntennaLayout& layout = out.antenna->layout;
    antenna_pts = antenna_points(layout);
    const auto bpts = board_points(board, out.placements.front(), 0.0);
    antenna_pts.insert(antenna_pts.end(), bpts.begin(), bpts.end());
    for (const auto& a : layout.antennas) {
      std::vector<Vec3> world;
      for (const Vec3& v : rendered_panel_mesh(a).vertices) world.push_back(a.p_world_antenna + a.R_world_antenna * v);
      panel_vertices.push_back(world);
    }
    const int factor = std::max(1, std::min(d.intrinsics.width, d.intrinsics.height) / antenna_plan->occlusion_px);
    low = std::make_unique<PhotoRenderer>(scaled_intrinsics(d.intrinsics, factor), 1);
    out.antenna->visible_fraction.assign(layout.antennas.size(), {});
    panel_boxes.assign(layout.antennas.size(), {});
    panel_widths.assign(layout.antennas.size(), {});
  }
  const int total = static_cast<int>(shot_times.size());
  if (joint) c.shot_extra_columns = {"placement"};
  for (int i = 0; i < total; ++i) {
    const auto [t_true, p] = shot_times[static_cast<std::size_t>(i)];
    const BoardPlacement* pl = has_board ? &out.placements[p] : nullptr;
    ShotTruth st;
    st.index = i;
    st.image = fmt::format("images/img_{:04d}.jpg", i);
    if (pl) st.placement = pl->name;
    st.t_true = t_true;
    st.t_shot = t_true - d.time_offset_s;
    st.R_world_device = tr.R_world_device(t_true);
    st.p_world_device = tr.position_world(t_true);
    const CameraPose pose = camera_pose(d, tr, t_true);
    st.R_world_camera = pose.R_world_camera;
    st.p_world_camera = pose.p_world_camera;
    const Vec3 omega_device = tr.angular_velocity_device(t_true);
    st.angular_rate_deg_s = rad2deg(omega_device.norm());
    // The planning margins cover the tremor; these are the scenario's promises.
    if (pl && !board_in_view(d.intrinsics, pose, board, pl->R_world_board, pl->p_world_board, 0.0, 2.0))
      throw std::runtime_error(fmt::format("internal: photo {} does not show the whole board", i));
    if (joint && (st.angular_rate_deg_s < kMinRateDegS || st.angular_rate_deg_s > kMaxRateDegS))
      throw std::runtime_error(fmt::format("internal: photo {} taken at {:.1f} °/s, outside {}..{} °/s", i,
                                           st.angular_rate_deg_s, kMinRateDegS, kMaxRateDegS));

    if (antenna && fit_margin_px(d.intrinsics, pose, antenna_pts) < 2.0)
      throw std::runtime_error(fmt::format("internal: photo {} does not show the whole board and every antenna", i));

    scene.patches = room;
    if (pl) scene.patches.push_back(board_patch(texture, pl->R_world_board, pl->p_world_board, "board " + pl->name));
    cv::Mat radiance = renderer.render(scene, pose, lighting);
    if (antenna) {
      AntennaTruth& at = *out.antenna;
      at.north_shift.push_back(north_shift(at.dipoles, field_world_uT, st.p_world_device));
      const auto fractions = visible_fractions(*low, scene, antenna_plan->panel_mesh, pose);
      for (std::size_t k = 0; k < fractions.size(); ++k) {
        at.visible_fraction[k].push_back(fractions[k]);
        panel_boxes[k].push_back(projected_box(d.intrinsics, pose, panel_vertices[k]));
        panel_widths[k].push_back(apparent_width_px(d.intrinsics, pose, at.layout.antennas[k]));
      }
    }
    radiance = motion_blur(radiance, d.intrinsics, d.R_device_camera.transpose() * omega_device, d.sensor.exposure_s);
    const cv::Mat grey = sensor_image(radiance, d.sensor, sc.seed * 1000003ULL + static_cast<std::uint64_t>(i) + 1);
    const fs::path file = scratch / st.image;
    write_binary(file, encode_jpeg(grey, d.sensor.jpeg_quality));

    Shot shot;
    shot.index = i;
    shot.t = st.t_shot;
    shot.image = st.image;
    shot.source = file;
    if (joint) shot.extra = {pl->name};
    c.shots.push_back(shot);
    out.shots.push_back(st);
    if (sc.progress) sc.progress(i + 1, total);
  }

  if (antenna) {
    AntennaTruth& at = *out.antenna;
    choose_rois(at, panel_boxes, panel_widths, d.intrinsics);
    // Baseline for triangulation: the largest angle between two viewing directions of each antenna.
    for (const auto& a : at.layout.antennas) {
      double span = 0.0;
      for (const auto& s1 : out.shots)
        for (const auto& s2 : out.shots) {
          const Vec3 u = (a.p_world_antenna - s1.p_world_camera).normalized(),
                     v = (a.p_world_antenna - s2.p_world_camera).normalized();
          span = std::max(span, std::atan2(u.cross(v).norm(), u.dot(v)));
        }
      at.viewing_span_deg.push_back(rad2deg(span));
    }
  }

  // Truth and calibration files.
  if (has_board) c.generated_files["board.yaml"] = camera::format_board(board);
  if (joint) {
    // The thesis's reference instruments (§5.4.3): a level (±0.2°) for G lines, a compass
    // (±1.5°, magnetic north) for N lines; errors uniform within those bounds. N lines only for
    // axes more than 10° from the vertical (a compass cannot read a near-vertical axis).
    auto ref_rng = make_rng(sc.seed, 0x7ef, kCaptureStreams);
    std::string csv = "placement,axis,ref,angle_deg\n";
    for (const auto& pl : out.placements)
      for (int a = 0; a < 3; ++a) {
        const Vec3 axis = pl.R_world_board.col(a);
        const char name = "XYZ"[a];
        const double g = rad2deg(std::acos(std::clamp(-axis.z(), -1.0, 1.0)));
        csv += fmt::format("{},{},G,{:.3f}\n", pl.name, name, std::clamp(g + uniform(ref_rng, -0.2, 0.2), 0.0, 180.0));
        if (g > 10.0 && g < 170.0) {
          const double n = rad2deg(std::atan2(axis.x(), axis.y())) + uniform(ref_rng, -1.5, 1.5);
          csv += fmt::format("{},{},N,{:.3f}\n", pl.name, name, std::fmod(std::fmod(n, 360.0) + 360.0, 360.0));
        }
      }
    c.generated_files["board_reference.csv"] = csv;
  }
  c.generated_files["truth/device.yaml"] = capture_device_yaml(d, imu);
  c.generated_files["truth/scene.yaml"] = capture_scene_yaml(out, board);
  c.metadata["truth"]["device"] = "truth/device.yaml";
  c.metadata["truth"]["scene"] = "truth/scene.yaml";
  c.metadata["source"]["name"] = "antpose simulate capture";
  c.metadata["source"]["scenario"] = to_string(sc.scenario);
  c.metadata["source"]["seed"] = std::to_string(sc.seed);
  return out;
}

SimulatedCapture write_simulated_capture(const CaptureScenario& scenario, const fs::path& folder, bool overwrite) {
  if (fs::exists(folder) && !overwrite)
    throw InputError(folder, "already exists; choose a new output folder or --force (antpose never overwrites data)");
  const fs::path parent = folder.parent_path().empty() ? fs::path(".") : folder.parent_path();
  std::random_device rd;
  const fs::path scratch = parent / fmt::format(".{}.images-{:08x}", folder.filename().string(), rd());
  try {
    SimulatedCapture sim = simulate_capture(scenario, scratch);
    write_capture(sim.capture, folder, CaptureWriteOptions{overwrite});
    fs::remove_all(scratch);
    return sim;
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(scratch, ignored);
    throw;
  }
}

}  // namespace antpose::sim
