// antpose simulate capture: a simulated photo capture (board photos + IMU streams + truth).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "antpose/sim/capture_simulator.hpp"
#include "commands.hpp"
#include "progress.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct CaptureOptions {
  std::string output;
  bool force = false;
  std::string scenario = "joint-calibration";
  std::uint64_t seed = 1;
  int width = 1600, height = 1200;
  int photos_per_placement = 12;
  std::optional<int> photos;  // default 20, antenna 12
  std::optional<std::uint64_t> device_seed;
  std::string setting = "rooftop";
  int antennas = 1;
  bool disturbance = false;
  std::string distribution = "wide";
  std::optional<std::string> radome, arrangement, background, light;
  std::optional<double> photo_scale;
  std::optional<double> board_max_distance_m;
  std::string board = "chessboard";
  std::optional<int> jpeg_quality;
  std::optional<double> blur_px, noise, exposure_ms;
  std::optional<double> time_offset_ms;
  std::string phone = "typical";
  int supersampling = 3;
};

camera::BoardType board_type(const std::string& name) {
  for (const auto t : {camera::BoardType::kChessboard, camera::BoardType::kCircles,
                       camera::BoardType::kAsymmetricCircles, camera::BoardType::kCharuco})
    if (camera::to_string(t) == name) return t;
  throw InputError("--board", fmt::format("'{}' is not chessboard, circles, asymmetric-circles or charuco", name));
}

// The wide distribution's fixes: each names its flag when given with the classic distribution.
void set_wide_fixes(const CaptureOptions& o, sim::Distribution distribution, sim::CaptureScenario& sc) {
  const bool wide = distribution == sim::Distribution::kWide;
  const auto wide_only = [&](bool given, const char* flag) {
    if (given && !wide)
      throw InputError(flag, "is drawn by the wide distribution only: add --distribution wide (the default)");
  };
  wide_only(o.photo_scale.has_value(), "--photo-scale");
  wide_only(o.arrangement.has_value(), "--arrangement");
  wide_only(o.background.has_value(), "--background");
  wide_only(o.light.has_value(), "--light");
  sim::WideSiteFixes& f = sc.wide;
  f.photo_scale = o.photo_scale;
  if (o.arrangement) f.arrangement = sim::parse_arrangement(*o.arrangement);
  if (o.background) f.background = sim::parse_background_kind(*o.background);
  if (o.light) f.light = sim::parse_light_mode(*o.light);
  f.jpeg_quality = o.jpeg_quality;
  f.blur_sigma_px = o.blur_px;
  f.noise_scale = o.noise;
  if (o.exposure_ms) f.exposure_s = *o.exposure_ms * 1e-3;
  sim::validate(f);
}

void run(const CaptureOptions& o) {
  // Every value is checked here so that the message names the option.
  if (o.width < 64 || o.width > 8000) throw InputError("--width", fmt::format("{} px is outside 64..8000", o.width));
  if (o.height < 64 || o.height > 8000)
    throw InputError("--height", fmt::format("{} px is outside 64..8000", o.height));
  if (o.photos_per_placement < 2 || o.photos_per_placement > 100)
    throw InputError("--photos-per-placement", fmt::format("{} is outside 2..100", o.photos_per_placement));
  const bool antenna = o.scenario == "antenna";
  const int photos = o.photos.value_or(antenna ? 12 : 20);
  if (photos < 3 || photos > (antenna ? 60 : 500))
    throw InputError("--photos", fmt::format("{} is outside 3..{}", photos, antenna ? 60 : 500));
  if (o.antennas < 1 || o.antennas > 3) throw InputError("--antennas", fmt::format("{} is outside 1..3", o.antennas));
  const sim::AntennaSetting setting = sim::parse_antenna_setting(o.setting);
  const sim::Distribution distribution = sim::parse_distribution(o.distribution);
  if (o.jpeg_quality && (*o.jpeg_quality < 1 || *o.jpeg_quality > 100))
    throw InputError("--jpeg-quality", fmt::format("{} is outside 1..100", *o.jpeg_quality));
  if (o.blur_px && !(*o.blur_px >= 0.0 && *o.blur_px <= 20.0))
    throw InputError("--blur-px", fmt::format("{} px is outside 0..20 (σ of the Gaussian defocus)", *o.blur_px));
  if (o.noise && !(*o.noise >= 0.0 && *o.noise <= 100.0))
    throw InputError("--noise", fmt::format("{} is outside 0..100 (1 = a typical phone sensor, 0 = none)", *o.noise));
  if (o.exposure_ms && !(*o.exposure_ms >= 0.0 && *o.exposure_ms <= 200.0))
    throw InputError("--exposure-ms", fmt::format("{} ms is outside 0..200", *o.exposure_ms));
  if (o.time_offset_ms && !(std::abs(*o.time_offset_ms) <= 1000.0))
    throw InputError("--time-offset-ms", fmt::format("{} ms is outside ±1000 ms", *o.time_offset_ms));
  if (o.supersampling < 1 || o.supersampling > 8)
    throw InputError("--supersampling", fmt::format("{} is outside 1..8", o.supersampling));

  const fs::path out = o.output;
  bool overwrite = o.force;
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) throw InputError(out, "exists and is not a folder; choose a new output folder");
    if (!fs::is_empty(out) && !o.force)
      throw InputError(out, "already exists and is not empty; choose a new output folder or add --force to replace it");
    overwrite = true;  // an empty folder (or --force)
  }

  sim::CaptureScenario sc;
  sc.scenario = sim::parse_scenario(o.scenario);
  sc.seed = o.seed;
  sc.device.width = o.width;
  sc.device.height = o.height;
  sc.device.phone = o.phone;
  sc.device.jpeg_quality = o.jpeg_quality.value_or(sc.device.jpeg_quality);
  sc.device.blur_sigma_px = o.blur_px.value_or(sc.device.blur_sigma_px);
  sc.device.noise_scale = o.noise.value_or(sc.device.noise_scale);
  if (o.exposure_ms) sc.device.exposure_s = *o.exposure_ms * 1e-3;
  sc.device.supersampling = o.supersampling;
  if (o.time_offset_ms) sc.device.time_offset_s = *o.time_offset_ms * 1e-3;
  sc.board = sim::default_board(board_type(o.board));
  sc.photos_per_placement = o.photos_per_placement;
  sc.photos = photos;
  sc.device_seed = o.device_seed;
  sc.setting = setting;
  sc.antennas = o.antennas;
  sc.disturbance = o.disturbance;
  sc.distribution = distribution;
  if (o.radome) sc.radome = sim::parse_radome_look(*o.radome);
  sc.board_max_distance_m = o.board_max_distance_m;
  set_wide_fixes(o, distribution, sc);
  ProgressLine progress;
  if (auto report = progress.callback())
    sc.progress = [report](int done, int total) { report("rendering photos", done, total); };
  const sim::SimulatedCapture sim = sim::write_simulated_capture(sc, out, overwrite);
  std::string subject = sc.scenario == sim::Scenario::kPlanes
                            ? std::string("the room")
                            : fmt::format("the board ({} {}x{})", o.board, sc.board.cols, sc.board.rows);
  if (sim.antenna) {
    const auto& s0 = sim.antenna->layout.antennas.front();
    subject =
        fmt::format("{} antenna(s) on a {} mast{} (antenna-1 azimuth {:.1f}° magnetic, downtilt {:.1f}°)",
                    sim.antenna->layout.antennas.size(), o.setting, sim.antenna->dipoles.empty() ? "" : ", magnetised",
                    rad2deg(s0.azimuth_magnetic), rad2deg(s0.downtilt));
    if (const auto& w = sim.antenna->wide)
      subject += fmt::format(" [wide: {}, {} radome, {} light, {} behind, {:.1f} MP]",
                             sim::to_string(sim.antenna->layout.arrangement), sim::to_string(s0.finish.look),
                             sim::to_string(w->light.mode), sim::to_string(w->background.kind),
                             sim.device.intrinsics.width * static_cast<double>(sim.device.intrinsics.height) / 1e6);
  }
  fmt::print(
      "wrote {} ({}, seed {}): {} photos {}x{} of {}, {:.1f} s of IMU data; "
      "time offset {:.1f} ms, camera mounting error {:.2f}°\n",
      out.string(), o.scenario, o.seed, sim.shots.size(), sim.device.intrinsics.width, sim.device.intrinsics.height, subject,
      sim.capture.truth_orientation->t.back(), sim.device.time_offset_s * 1e3, sim.device.mounting_error_deg);
}

}  // namespace

void add_simulate_capture_command(CLI::App& simulate) {
  auto* cmd = simulate.add_subcommand(
      "capture", "Simulate photos with IMU streams (camera and camera-IMU calibration captures, a room, antenna sites; truth in truth/)");
  auto o = std::make_shared<CaptureOptions>();
  cmd->add_option("-o,--output", o->output, "Capture folder to create")->required();
  cmd->add_flag("--force", o->force, "Replace an existing non-empty output folder");
  cmd->add_option(
         "--scenario", o->scenario,
         "camera-calibration: ~20 still views of a board (intrinsics); joint-calibration: six board placements, "
         "the phone walking around each (camera-IMU rotation and time offset); planes: no board, photos of the "
         "room's ground and walls while walking; antenna: a mast with panel antennas and a board on a tripod, "
         "photographed while walking an arc (truth/scene.yaml: antenna attitudes and regions of interest)")
      ->check(CLI::IsMember({"camera-calibration", "joint-calibration", "planes", "antenna"}))
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed (the same seed gives the same capture)")->capture_default_str();
  cmd->add_option("--width", o->width,
                  "Image width, px (fx scales with it: 1300 px at 1600); wide antenna sites: the phone's native width, "
                  "the photos a 2-12 MP resize of it")
      ->capture_default_str();
  cmd->add_option("--height", o->height, "Image height, px (wide antenna sites: the native height)")
      ->capture_default_str();
  cmd->add_option("--photos-per-placement", o->photos_per_placement, "joint-calibration: photos per board placement")
      ->capture_default_str();
  cmd->add_option("--photos", o->photos,
                  "camera-calibration, planes (default 20) and antenna (default 12): number of photos");
  cmd->add_option("--device-seed", o->device_seed,
                  "Seed of the phone (intrinsics, R_device_camera, IMU errors, time offset); default --seed. The scene "
                  "comes from --seed, so captures with one device seed share a phone calibrated once");
  cmd->add_option("--setting", o->setting,
                  "antenna: rooftop (a pipe mast on a roof) or ground (a monopole, antennas 8-30 m up; classic 10-20)")
      ->capture_default_str();
  cmd->add_option("--antennas", o->antennas, "antenna: number of panels on the mast, 1..3")->capture_default_str();
  cmd->add_flag(
      "--disturbance", o->disturbance,
      "antenna: a magnetised steel mast (dipole line) turning magnetic north by 3-8° at the middle of the walk");
  cmd->add_option("--distribution", o->distribution,
                  "antenna: wide (every site drawn from wide ranges of photo size, hardware, attitude, mounting, "
                  "background, light, antenna size in the image, walk, clock offset and photo pipeline; "
                  "docs/simulator.md) or classic (the narrow scenes of the first antenna scenario, reproduced "
                  "byte for byte for a seed)")
      ->capture_default_str();
  cmd->add_option("--radome", o->radome,
                  "antenna: plain (uniform albedo), weathered (dirt, streaks, label) or ribbed (vertical grooves; wide "
                  "only); default: weathered (classic), drawn (wide)");
  cmd->add_option("--photo-scale", o->photo_scale,
                  "antenna, wide: the photos' size as a fraction of --width x --height, 0.25..1 (default: drawn so "
                  "that the megapixels are uniform in 2..min(12, native))");
  cmd->add_option("--arrangement", o->arrangement,
                  "antenna, wide: sectors (each panel on its own arms, ~360/N apart) or side-by-side (on one frame, "
                  "0.3-1 m apart, looking the same way); default drawn");
  cmd->add_option("--background", o->background,
                  "antenna, wide: sky, buildings or trees behind the mast; default drawn");
  cmd->add_option("--light", o->light, "antenna, wide: sun, low-sun, overcast or shade; default drawn");
  cmd->add_option("--board-max-distance", o->board_max_distance_m,
                  "antenna: the board's greatest distance from the phone along the walk, m, which bounds the walk's "
                  "span of viewing directions (default 4 classic, drawn in 3.5-6 wide; 2.5..15)");
  cmd->add_option("--board", o->board, "Board type: chessboard, circles, asymmetric-circles, charuco")
      ->capture_default_str();
  cmd->add_option("--jpeg-quality", o->jpeg_quality, "JPEG quality 1..100 (default 92; wide antenna sites: drawn 75-95)");
  cmd->add_option("--blur-px", o->blur_px, "Gaussian defocus σ, px (default 0.6; wide antenna sites: drawn 0.4-1.2)");
  cmd->add_option("--noise", o->noise,
                  "Sensor noise scale (1 = typical phone: photon + 3 e- read noise; 0 = none; default 1; wide "
                  "antenna sites: drawn 0.7-2)");
  cmd->add_option("--exposure-ms", o->exposure_ms,
                  "Exposure time (motion blur), ms (default 2; wide antenna sites: drawn 1-8)");
  cmd->add_option("--time-offset-ms", o->time_offset_ms,
                  "Camera-IMU time offset, ms (IMU instant = shots.csv t + offset); default random in 10..60 (wide "
                  "antenna sites: -150..150 per site)");
  cmd->add_option("--phone", o->phone, "IMU error model: ideal, typical, random")
      ->check(CLI::IsMember({"ideal", "typical", "random"}))
      ->capture_default_str();
  cmd->add_option("--supersampling", o->supersampling, "Ray samples per pixel side (anti-aliasing)")
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace antpose::cli
