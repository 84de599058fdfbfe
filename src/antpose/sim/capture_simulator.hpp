// Simulated photo captures (`antpose simulate capture`): a phone with a camera and an IMU takes
// photos of a calibration board while its sensors stream, and everything needed to score the
// camera and camera–IMU calibrations is written to truth/.
//
// Device: CameraIntrinsics of a phone main camera (fx ≈ 1300 px at 1600 × 1200, mild barrel
// distortion, all drawn from the seed), R_device_camera = nominal_R_device_camera() · exp(δ) with
// a mounting error δ of 1–3°, the camera centre at p_device_camera (a lever arm of a few cm), a
// camera–IMU time offset, and the IMU errors of a PhoneModel (imu_simulator.hpp).
//
// Clocks: the sensor streams and truth/orientation.csv run on the IMU clock, which is the true
// clock of the simulation. A photo taken at true instant t_true (the middle of its exposure) is
// written to shots.csv with t = t_true − time_offset_s, so that, as in
// store/device_profile.hpp, "IMU-clock instant of a photo = shots.csv t + time_offset_s".
//
// World: ENU with y along MAGNETIC north (truth.world = enu-magnetic), the Earth field from
// WMM2025 at the site; truth/scene.yaml gives the declination to convert to true north.
//
// Scenarios (deterministic for a seed):
//   camera-calibration  a board on a stand, ~20 photos from varied distances (0.35–1.6 m) and
//                       angles (up to 50° off the board normal), the board anywhere in the
//                       image including its corners; the phone is held still for each photo.
//   joint-calibration   six board placements on a tripod (origin ≈ 1 m high): face up at two
//                       yaws, tilted 20° and 45° facing different azimuths, vertical facing
//                       north and east. Per placement the phone walks an arc around the board
//                       (0.6–1.5 m away, board fully in view) without stopping; photos are
//                       taken mid-move at angular rates of 10–40 °/s (what makes the time offset
//                       observable). board_reference.csv: level (G lines) and compass (N lines,
//                       magnetic north) readings with uniform errors within ±0.2° and ±1.5°.
//   planes              no board: the phone walks through the room (ground and four walls,
//                       the planar patches of room_patches) photographing walls and ground
//                       mid-move; kind imu-log.
//   antenna             a mast with 1–3 panel antennas (antenna_scene.hpp) on a roof or on open
//                       ground, a large board on a tripod a few metres from the phone; the phone
//                       walks an arc around the mast pausing for each photo, every photo showing
//                       the whole board and every antenna; optional magnetised-mast disturbance.
//                       Two distributions of sites (antenna_capture.hpp): `classic`, the narrow
//                       scenes the measurement was first tuned on (kept draw for draw), and
//                       `wide` (antenna_site.hpp), drawn from wide ranges of everything.
// Every truth/scene.yaml lists the room's planes, so photos can be re-rendered or scored.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/antenna_site.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

/// The simulated phone: IMU error model, camera, camera–IMU geometry and clock offset.
struct SimulatedDevice {
  PhoneModel phone = PhoneModel::typical();
  camera::CameraIntrinsics intrinsics;  // of the photos
  /// Wide antenna sites: the photos are the native frame resized by photo_scale; the camera at
  /// its native size.
  std::optional<camera::CameraIntrinsics> native_intrinsics;
  double photo_scale = 1.0;
  Mat3 R_device_camera = camera::nominal_R_device_camera();
  Vec3 p_device_camera = Vec3::Zero();  // camera centre in the device frame, m
  double mounting_error_deg = 0.0;      // angle of nominal_R_device_camera()^T R_device_camera
  double time_offset_s = 0.0;           // IMU-clock instant of a photo = shots.csv t + time_offset_s
  SensorModel sensor;
  int supersampling = 3;
};

struct DeviceOptions {
  int width = 1600, height = 1200;      // px; fx scales with the width (1300 px at 1600)
  std::string phone = "typical";        // ideal | typical | random (PhoneModel)
  std::optional<double> time_offset_s;  // fixed; default uniform in [10, 60] ms
  double blur_sigma_px = 0.6;
  double noise_scale = 1.0;
  double exposure_s = 0.002;
  int jpeg_quality = 92;
  int supersampling = 3;
};

/// Draws a device from the seed. std::invalid_argument for a size outside 64..8000 px, an
/// unknown phone, a JPEG quality outside 1..100, negative blur/noise/exposure.
SimulatedDevice make_device(const DeviceOptions& options, std::uint64_t seed);

enum class Scenario { kCameraCalibration, kJointCalibration, kPlanes, kAntenna };
std::string to_string(Scenario scenario);
/// "camera-calibration" | "joint-calibration" | "planes" | "antenna"; std::invalid_argument otherwise.
Scenario parse_scenario(const std::string& name);

/// The antenna scenario's distribution of sites: the narrow classic scenes (reproduced draw for
/// draw: regression sites are stored as seeds) or the wide one (antenna_site.hpp).
enum class Distribution { kClassic, kWide };
std::string to_string(Distribution distribution);
/// "classic" | "wide"; InputError naming --distribution otherwise.
Distribution parse_distribution(const std::string& name);

/// A board placement of the joint-calibration scenario.
struct BoardPlacement {
  std::string name;
  Mat3 R_world_board = Mat3::Identity();  // world ENU-magnetic ← board frame (board.hpp)
  Vec3 p_world_board = Vec3::Zero();      // board-frame origin, m
};

/// The six placements (names hor_0, hor_60, tilt_20, tilt_45, vert_n, vert_e) for a board
/// whose printed face looks along face_normal_z · z_board (BoardTexture::face_normal_z), the
/// pattern centred 1.0 m above the ground.
std::vector<BoardPlacement> joint_placements(const camera::BoardSpec& board, double face_normal_z);

/// The default board of each type for the simulation: chessboard 9 × 6 inner corners, 30 mm;
/// circles 7 × 5, 40 mm; asymmetric-circles 4 × 11, 30 mm; charuco 7 × 5 squares of 40 mm with
/// 30 mm DICT_5X5_100 markers.
camera::BoardSpec default_board(camera::BoardType type);
/// The boards of the antenna scenario, seen from 1.5–4 m: chessboard 9 × 6 of 70 mm; circles
/// 7 × 5 at 90 mm; asymmetric-circles 4 × 11 at 70 mm; charuco 7 × 5 of 90 mm, 67.5 mm markers.
/// The antenna scenario uses it when CaptureScenario::board is default_board of its type.
camera::BoardSpec antenna_board(camera::BoardType type);

struct CaptureScenario {
  Scenario scenario = Scenario::kJointCalibration;
  std::uint64_t seed = 1;
  DeviceOptions device;
  camera::BoardSpec board = default_board(camera::BoardType::kChessboard);
  int photos_per_placement = 12;  // joint-calibration
  int photos = 20;                // camera-calibration, planes, antenna (the CLI's default there: 12)
  /// Seed of the phone (make_device); default = seed. One phone can take many scenes.
  std::optional<std::uint64_t> device_seed;
  AntennaSetting setting = AntennaSetting::kRooftop;  // antenna
  int antennas = 1;                                   // antenna: 1..3
  bool disturbance = false;                           // antenna: magnetised mast (antenna_scene.hpp)
  Distribution distribution = Distribution::kWide;    // antenna
  /// antenna: classic default weathered (ribbed is wide only); wide: drawn when unset.
  std::optional<RadomeLook> radome;
  /// antenna: the board's greatest distance from the phone along the walk, m, which bounds the
  /// walk's length and so its span of viewing directions; the board stands 0.55–0.85 of it ahead
  /// of the walk's middle. Default 4 (classic) or drawn in 3.5–6 (wide); 2.5..15.
  std::optional<double> board_max_distance_m;
  /// antenna, wide: the draws fixed (the photo pipeline's fixes override `device`'s values, which
  /// wide sites otherwise draw; the radome, board distance and time offset come from the fields
  /// above and from device.time_offset_s).
  WideSiteFixes wide;
  Site site{30.26, 120.12, 20.0, "2025-06-01"};
  /// Called after each photo with (photos done, photos in all).
  std::function<void(int, int)> progress;
};

/// Truth of one photo.
struct ShotTruth {
  int index = 0;
  std::string image, placement;
  double t_true = 0.0;  // IMU clock, s
  double t_shot = 0.0;  // shots.csv t = t_true − time_offset_s
  Mat3 R_world_device = Mat3::Identity();
  Vec3 p_world_device = Vec3::Zero();
  Mat3 R_world_camera = Mat3::Identity();
  Vec3 p_world_camera = Vec3::Zero();
  double angular_rate_deg_s = 0.0;  // |ω| at t_true
};

/// Truth of the antenna scenario.
struct AntennaTruth {
  AntennaLayout layout;
  RadomeLook radome = RadomeLook::kWeathered;         // classic: every panel's
  std::vector<MagneticDipole> dipoles;                // empty without disturbance
  std::vector<double> north_shift;                    // per shot, rad (north_shift in antenna_scene.hpp)
  std::vector<int> roi_shot;                          // per antenna: the photo its region of interest is in
  std::vector<cv::Rect> roi;                          // per antenna: its projection's bounding box + margin, clipped
  std::vector<double> width_px;                       // per antenna: its apparent width in its ROI photo
  std::vector<std::vector<double>> visible_fraction;  // [antenna][shot]: unoccluded part of its silhouette
  std::vector<double> viewing_span_deg;               // per antenna: largest angle between two viewing directions
  std::optional<SiteDraw> wide;                       // the drawn parameters of a wide site
};

struct SimulatedCapture {
  Capture capture;  // streams, shots (images in the scratch folder), generated truth files
  SimulatedDevice device;
  std::vector<BoardPlacement> placements;  // joint: six; camera-calibration: one ("stand"); planes: none
  std::vector<TexturedPatch> surfaces;     // the room (ground, walls)
  std::vector<ShotTruth> shots;
  double declination_deg = 0.0;
  std::optional<AntennaTruth> antenna;  // antenna scenario
  std::vector<MeshObject> meshes;       // antenna scenario: mast, panels, arms, clamps, tripod
};

/// Runs a scenario; photos are written as JPEG into `scratch` (created), which write_capture
/// then copies from (Shot::source). std::invalid_argument for bad options; std::runtime_error
/// when no admissible view is found for a placement (e.g. a board too large for the camera).
SimulatedCapture simulate_capture(const CaptureScenario& scenario, const std::filesystem::path& scratch);

/// simulate_capture into a scratch folder next to `folder`, then io::write_capture (atomic) and
/// removes the scratch folder. `overwrite` as CaptureWriteOptions.
SimulatedCapture write_simulated_capture(const CaptureScenario& scenario, const std::filesystem::path& folder,
                                         bool overwrite);

/// truth/device.yaml: the IMU model of device_yaml(imu) plus `camera:` (the photos': width_px,
/// height_px, fx_px, fy_px, cx_px, cy_px, distortion [k1, k2, p1, p2, k3]), `camera_imu:`
/// (R_device_camera rows, mounting_error_deg, p_device_camera_m, time_offset_s and its
/// definition) and `photo:` (exposure_s, blur_sigma_px, noise_scale, full_well_e, read_noise_e,
/// gain, gamma, jpeg_quality, supersampling); with native intrinsics (wide antenna sites) also
/// `photo_scale` and `native_camera:` (as camera).
std::string capture_device_yaml(const SimulatedDevice& device, const ImuSimulation& imu);

/// truth/scene.yaml (see docs/simulator.md): world, declination_deg, board and placements (name,
/// R_world_board rows, p_world_board_m, shots_t_true) unless the scenario has no board, planes
/// (name, R_world_plane rows, p_world_plane_m, min_xy_m, max_xy_m) and shots (index, image, placement,
/// t_true, t, R_world_device, p_world_device_m, R_world_camera, p_world_camera_m,
/// angular_rate_deg_s); antenna captures also setting, mast, antennas and disturbance
/// (docs/simulator.md).
std::string capture_scene_yaml(const SimulatedCapture& sim, const camera::BoardSpec& board);

}  // namespace antpose::sim
