// The wide distribution of antenna sites (`antpose simulate capture --scenario antenna
// --distribution wide`): every site drawn from wide ranges of photo size, panel hardware,
// attitude, mounting, mast, radome, background, light, antenna size in the image, walk, clock
// offset and photo pipeline, so that the measurement can be developed on some seeds and accepted
// on fresh ones (docs/simulator.md lists the ranges). Each draw can be fixed (WideSiteFixes), so
// that tests can force a case.
//
// draw_wide_site draws the parameters only (nothing is rendered): the layout is checked for
// intersecting parts and the walk's distance for the setting's range, and drawn again until
// both hold. The capture simulator then plans the walk's views and checks occlusions
// (antenna_capture.hpp), drawing a further site (the next `attempt`) when they fail.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "antpose/camera/camera_model.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "antpose/sim/site_background.hpp"
#include "antpose/sim/site_light.hpp"

namespace antpose::sim {

/// Draws a wide site may be forced to (the CLI's flags); unset: drawn.
struct WideSiteFixes {
  std::optional<double> photo_scale;  // 0.25..1 of the native size (--photo-scale)
  std::optional<Arrangement> arrangement;
  std::optional<RadomeLook> radome;
  std::optional<BackgroundKind> background;
  std::optional<LightMode> light;
  std::optional<double> board_max_distance_m;  // 2.5..15 (--board-max-distance)
  std::optional<double> time_offset_s;         // ±1 (--time-offset-ms)
  std::optional<int> jpeg_quality;             // 1..100
  std::optional<double> blur_sigma_px, noise_scale, exposure_s;
};

struct WideSiteOptions {
  AntennaSetting setting = AntennaSetting::kRooftop;
  int antennas = 1;  // 1..3
  int photos = 12;
  camera::CameraIntrinsics native;  // the phone's camera at its native size
  WideSiteFixes fixes;
};

/// The photos' size and pipeline.
struct PhotoDraw {
  double scale = 1.0;               // of the native size: megapixels uniform in [2, min(12, native)]
  camera::CameraIntrinsics camera;  // camera::rescaled_intrinsics of the native camera at `scale`
  int jpeg_quality = 92;            // 75–95
  double blur_sigma_px = 0.6;       // defocus, 0.4–1.2
  double noise_scale = 1.0;         // 0.7–2
  double exposure_s = 0.002;        // 1–8 ms (motion blur)
};

/// The walk: an arc around the mast, the board on its tripod before its middle, and how the
/// photographer moves.
struct WalkDraw {
  double target_width_px = 100.0;  // antenna 1's width in the photos at the walk's middle (log-uniform 60–400)
  double distance_m = 10.0;        // of the walk from the mast's axis, from the target width
  double azimuth = 0.0;            // of the walk's middle from the mast, rad
  double height_m = 1.5;           // camera above the roof or the ground, 1.4–1.7
  double board_max_m = 4.0;        // greatest board distance from the phone, 3.5–6
  Vec3 board_centre = Vec3::Zero();  // 0.55–0.85 board_max ahead of the walk's middle, ±0.3 m aside
  std::vector<double> holds_s;       // per photo, 0.3–2 s
  std::vector<double> instants;      // per photo: where in its hold, 0.15–0.85
  double walk_speed_m_s = 0.9;       // 0.5–1.3
  double max_turn_deg_s = 40.0;
  GaitBob bob;                       // 1.6–2.2 Hz, 1–3 cm
  double tremor_deg = 0.05;          // hand tremor rms, 0.03–0.15°
};

/// The middle of the walk: the camera's nominal position there, world.
Vec3 walk_middle(const WalkDraw& walk);

/// How the user draws each antenna's region of interest.
struct RoiDraw {
  std::array<double, 4> margin_fraction{};  // left, top, right, bottom: 3–15 % of the box's larger side
  double pick = 0.0;                        // [0, 1): which of the admissible photos holds it
};

struct SiteDraw {
  int attempt = 0;
  PhotoDraw photo;
  SiteLight light;
  AntennaLayout layout;  // panels (model names, rendered specs, finishes, attitudes), mounts, mast
  Background background;
  WalkDraw walk;
  std::vector<RoiDraw> roi;  // per antenna
  double time_offset_s = 0.0;  // camera–IMU clock offset of this recording, ±150 ms
  double roof_half_m = 0.0;    // rooftop: parapets at ± this around the mast
};

/// Draws a site from stream `attempt` of the seed. InputError for a fix out of range (validate),
/// std::invalid_argument for other options out of range; std::runtime_error if no layout and
/// distance fit in 1000 draws (photos too small for 60 px antennas at the setting's distances,
/// such as a ground site in 1 MP photos, or fixes that exclude each other).
SiteDraw draw_wide_site(std::uint64_t seed, const WideSiteOptions& options, int attempt = 0);

/// InputError naming the flag, the value and its range when a fix is out of range: photo scale
/// 0.25..1, board distance 2.5..15 m, time offset ±1 s, JPEG quality 1..100, blur 0..20 px,
/// noise 0..100, exposure 0..0.2 s.
void validate(const WideSiteFixes& fixes);

}  // namespace antpose::sim
