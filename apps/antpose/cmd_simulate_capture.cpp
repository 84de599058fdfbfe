// antpose simulate capture: a simulated photo capture (board photos + IMU streams + truth).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "antpose/sim/capture_simulator.hpp"
#include "commands.hpp"

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
  int photos = 20;
  std::string board = "chessboard";
  int jpeg_quality = 92;
  double blur_px = 0.6;
  double noise = 1.0;
  double exposure_ms = 2.0;
  std::optional<double> time_offset_ms;
  std::string phone = "typical";
  int supersampling = 3;
};

camera::BoardType board_type(const std::string& name) {
  for (const auto t : {camera::BoardType::kChessboard, camera::BoardType::kCircles, camera::BoardType::kAsymmetricCircles,
                       camera::BoardType::kCharuco})
    if (camera::to_string(t) == name) return t;
  throw InputError("--board", fmt::format("'{}' is not chessboard, circles, asymmetric-circles or charuco", name));
}

void run(const CaptureOptions& o) {
  // Every value is checked here so that the message names the option.
  if (o.width < 64 || o.width > 8000) throw InputError("--width", fmt::format("{} px is outside 64..8000", o.width));
  if (o.height < 64 || o.height > 8000) throw InputError("--height", fmt::format("{} px is outside 64..8000", o.height));
  if (o.photos_per_placement < 2 || o.photos_per_placement > 100)
    throw InputError("--photos-per-placement", fmt::format("{} is outside 2..100", o.photos_per_placement));
  if (o.photos < 3 || o.photos > 500) throw InputError("--photos", fmt::format("{} is outside 3..500", o.photos));
  if (o.jpeg_quality < 1 || o.jpeg_quality > 100)
    throw InputError("--jpeg-quality", fmt::format("{} is outside 1..100", o.jpeg_quality));
  if (!(o.blur_px >= 0.0 && o.blur_px <= 20.0))
    throw InputError("--blur-px", fmt::format("{} px is outside 0..20 (σ of the Gaussian defocus)", o.blur_px));
  if (!(o.noise >= 0.0 && o.noise <= 100.0))
    throw InputError("--noise", fmt::format("{} is outside 0..100 (1 = a typical phone sensor, 0 = none)", o.noise));
  if (!(o.exposure_ms >= 0.0 && o.exposure_ms <= 200.0))
    throw InputError("--exposure-ms", fmt::format("{} ms is outside 0..200", o.exposure_ms));
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
  sc.device.jpeg_quality = o.jpeg_quality;
  sc.device.blur_sigma_px = o.blur_px;
  sc.device.noise_scale = o.noise;
  sc.device.exposure_s = o.exposure_ms * 1e-3;
  sc.device.supersampling = o.supersampling;
  if (o.time_offset_ms) sc.device.time_offset_s = *o.time_offset_ms * 1e-3;
  sc.board = sim::default_board(board_type(o.board));
  sc.photos_per_placement = o.photos_per_placement;
  sc.photos = o.photos;
  const auto start = std::chrono::steady_clock::now();
  sc.progress = [&](int done, int total) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fmt::print(stderr, "\rrendering photo {}/{} ({:.1f} s)", done, total, s);
    if (done == total) fmt::print(stderr, "\n");
    std::fflush(stderr);
  };
  const sim::SimulatedCapture sim = sim::write_simulated_capture(sc, out, overwrite);
  const std::string subject = sc.scenario == sim::Scenario::kPlanes
                                  ? std::string("the room")
                                  : fmt::format("the board ({} {}x{})", o.board, sc.board.cols, sc.board.rows);
  fmt::print("wrote {} ({}, seed {}): {} photos {}x{} of {}, {:.1f} s of IMU data; "
             "time offset {:.1f} ms, camera mounting error {:.2f}°\n",
             out.string(), o.scenario, o.seed, sim.shots.size(), o.width, o.height, subject,
             sim.capture.truth_orientation->t.back(), sim.device.time_offset_s * 1e3, sim.device.mounting_error_deg);
}

}  // namespace

void add_simulate_capture_command(CLI::App& simulate) {
  auto* cmd = simulate.add_subcommand(
      "capture", "Simulate board photos with IMU streams (camera or camera-IMU calibration capture, truth in truth/)");
  auto o = std::make_shared<CaptureOptions>();
  cmd->add_option("-o,--output", o->output, "Capture folder to create")->required();
  cmd->add_flag("--force", o->force, "Replace an existing non-empty output folder");
  cmd->add_option("--scenario", o->scenario,
                  "camera-calibration: ~20 still views of a board (intrinsics); joint-calibration: six board placements, "
                  "the phone walking around each (camera-IMU rotation and time offset); planes: no board, photos of the "
                  "room's ground and walls while walking")
      ->check(CLI::IsMember({"camera-calibration", "joint-calibration", "planes"}))
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed (the same seed gives the same capture)")->capture_default_str();
  cmd->add_option("--width", o->width, "Image width, px (fx scales with it: 1300 px at 1600)")->capture_default_str();
  cmd->add_option("--height", o->height, "Image height, px")->capture_default_str();
  cmd->add_option("--photos-per-placement", o->photos_per_placement, "joint-calibration: photos per board placement")
      ->capture_default_str();
  cmd->add_option("--photos", o->photos, "camera-calibration and planes: number of photos")->capture_default_str();
  cmd->add_option("--board", o->board, "Board type: chessboard, circles, asymmetric-circles, charuco")->capture_default_str();
  cmd->add_option("--jpeg-quality", o->jpeg_quality, "JPEG quality 1..100")->capture_default_str();
  cmd->add_option("--blur-px", o->blur_px, "Gaussian defocus σ, px")->capture_default_str();
  cmd->add_option("--noise", o->noise, "Sensor noise scale (1 = typical phone: photon + 3 e- read noise; 0 = none)")
      ->capture_default_str();
  cmd->add_option("--exposure-ms", o->exposure_ms, "Exposure time (motion blur), ms")->capture_default_str();
  cmd->add_option("--time-offset-ms", o->time_offset_ms,
                  "Camera-IMU time offset, ms (IMU instant = shots.csv t + offset); default random in 10..60");
  cmd->add_option("--phone", o->phone, "IMU error model: ideal, typical, random")
      ->check(CLI::IsMember({"ideal", "typical", "random"}))
      ->capture_default_str();
  cmd->add_option("--supersampling", o->supersampling, "Ray samples per pixel side (anti-aliasing)")->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace antpose::cli
