// The antenna scenario's site and walk, for simulate_capture: the classic sites (the scene and
// the walk drawn together from the scenario's stream until every view fits and every panel is
// at least 60 % unoccluded in every photo) and the wide ones (draw_wide_site, then the widest
// arc whose views fit, with every panel at least half unoccluded in three photos and at least
// 70 % in one, redrawn from the next site stream otherwise); and the regions of interest once
// the photos are taken.
#pragma once

#include <random>
#include <vector>

#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/capture_geometry.hpp"
#include "antpose/sim/capture_simulator.hpp"

namespace antpose::sim {

/// What simulate_capture renders and records of an antenna site.
struct AntennaSitePlan {
  AntennaTruth truth;                   // layout, radome, dipoles; wide: the draws
  BoardPlacement board;                 // on its tripod
  std::vector<MeshObject> meshes;       // mast, panels, mounts, tripod, trees
  std::vector<TexturedPatch> surfaces;  // roof, parapets and street, or the ground; buildings
  Trajectory trajectory;                // without the hand tremor
  double tremor_rms_rad = deg2rad(0.05);
  std::vector<double> shot_times;       // IMU clock
  Lighting lighting;
  std::vector<std::size_t> panel_mesh;  // per antenna: its panel's index in `meshes`
  int occlusion_px = 200;               // short side of the occlusion checks' id renders
};

/// The classic site, drawn from the scenario's stream `rng` exactly as the first antenna
/// scenario did (regression sites are stored as seeds). std::runtime_error when nothing fits in
/// 4000 draws.
AntennaSitePlan plan_classic_antenna_site(const CaptureScenario& scenario, const SimulatedDevice& device,
                                          const camera::BoardSpec& board, const BoardTexture& texture,
                                          const Vec3& field_world_uT, std::mt19937_64& rng);

/// A wide site. `device` is made at its native size; it leaves with the site's photo camera
/// (native_intrinsics and photo_scale set), clock offset and photo pipeline. std::runtime_error
/// when no site in 400 draws has an admissible walk.
AntennaSitePlan plan_wide_antenna_site(const CaptureScenario& scenario, SimulatedDevice& device,
                                       const camera::BoardSpec& board, const BoardTexture& texture,
                                       const Vec3& field_world_uT);

/// Each antenna's region of interest from its projected boxes in every photo ([antenna][shot])
/// and its unoccluded fractions: classic, in the middle photo, 5 % margins; wide, in the photo
/// RoiDraw::pick chooses among those where at least 70 % of it shows, with the drawn margins,
/// and its apparent width there. Fills truth.roi_shot, roi and width_px. std::runtime_error when
/// a wide site's antenna shows 70 % in no photo (the planning keeps a margin for the tremor).
void choose_rois(AntennaTruth& truth, const std::vector<std::vector<PixelBox>>& boxes,
                 const std::vector<std::vector<double>>& width_px, const camera::CameraIntrinsics& camera);

/// The apparent width (px) of a panel: the extent of its box's middle cross-section across the
/// image direction of its long axis.
double apparent_width_px(const camera::CameraIntrinsics& camera, const CameraPose& pose, const SimAntenna& antenna);

}  // namespace antpose::sim
