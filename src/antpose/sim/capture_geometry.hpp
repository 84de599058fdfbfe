// Where the simulated phone looks: camera aiming, the tests that a view shows what it must
// (a board, the antennas) and the occlusion checks, shared by the capture scenarios.
#pragma once

#include <array>
#include <optional>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

struct SimulatedDevice;
struct BoardPlacement;

/// Minimum-jerk peak speed is 1.875 × the mean speed (s'(1/2) of 10τ³ − 15τ⁴ + 6τ⁵).
inline constexpr double kMinJerkPeak = 1.875;

/// Rotation taking unit vector a onto unit vector b by the shortest arc.
Mat3 rotation_between(const Vec3& a, const Vec3& b);

/// Camera looking along `forward`, image "down" as close as possible to `down`, then rolled.
Mat3 look_rotation(const Vec3& forward, const Vec3& down, double roll);

/// Centre of the board's printed area (BoardSpec::extent), board frame.
Vec3 board_centre(const camera::BoardSpec& board);

/// R_world_board of a board whose printed face looks along n_out (world), with board x along
/// the horizontal `x_hint` (made orthogonal to the board normal).
Mat3 board_rotation(const Vec3& n_out, double face_normal_z, const Vec3& x_hint);

/// The board's printed area seen from a camera pose: every corner of extent() widened by
/// `margin_m` projects inside the image with `border_px` to spare.
bool board_in_view(const camera::CameraIntrinsics& K, const CameraPose& pose, const camera::BoardSpec& board,
                   const Mat3& R_world_board, const Vec3& p_world_board, double margin_m, double border_px);

/// The board's outline widened by `margin_m`, 9 points per side (edges bow with distortion).
std::vector<Vec3> board_points(const camera::BoardSpec& board, const BoardPlacement& pl, double margin_m);

/// A device pose (the IMU's frame) of the trajectory.
struct Waypoint {
  Mat3 R_world_device;
  Vec3 p_world_device;
};

/// The device pose that puts the camera at R_world_camera, p_world_camera.
Waypoint device_from_camera(const SimulatedDevice& d, const Mat3& R_world_camera, const Vec3& p_world_camera);

/// The camera pose of the device on the trajectory at t.
CameraPose camera_pose(const SimulatedDevice& d, const Trajectory& tr, double t);

/// World points that must be inside every photo of an antenna site: each rendered panel's mesh
/// vertices (brackets and end caps included).
std::vector<Vec3> antenna_points(const AntennaLayout& layout);

/// Smallest distance (px) of the points' projections to the image border; −1 when one is behind
/// the camera or far outside the field of view (where the distortion polynomial means nothing).
double fit_margin_px(const camera::CameraIntrinsics& K, const CameraPose& pose, const std::vector<Vec3>& points);

/// Camera at c looking so that the points' bounding box (undistorted normalised coordinates) is
/// centred in the image; image y along world down (landscape) or image x along world down
/// (portrait), plus a hand-held roll.
Mat3 aim_camera(const Vec3& c, const std::vector<Vec3>& points, bool portrait, double roll);

/// The camera of photos `factor` times smaller (integer division of the size).
camera::CameraIntrinsics scaled_intrinsics(const camera::CameraIntrinsics& K, int factor);

/// The unoccluded fraction of each antenna's silhouette from `pose`, by id renders (scene, and
/// each panel alone) with a low-resolution renderer. Panel k is scene mesh `panel_mesh[k]`.
std::vector<double> visible_fractions(const PhotoRenderer& low, const Scene& scene,
                                      const std::vector<std::size_t>& panel_mesh, const CameraPose& pose);

/// Tripod under a board: three legs from a head below the board's lower edge to the ground, and
/// a post up to the board.
std::vector<MeshObject> tripod_meshes(const camera::BoardSpec& board, const BoardPlacement& pl, double ground_z);

/// The board of the antenna scenario on its tripod: centred at `centre`, facing the point `facing`
/// (the middle of the walk), rows running down.
BoardPlacement tripod_board(const camera::BoardSpec& board, double face_normal_z, const Vec3& centre,
                            const Vec3& facing);

/// An arc walked around the mast (axis = world z): photos at horizontal distance ≈ distance_m
/// from the axis, centred on azimuth `azimuth` (from the mast, clockwise from north), the board
/// centre at `board_centre` and at most board_max_m (and at least 1.5 m) from every photo.
struct ArcWalk {
  double distance_m = 0.0, azimuth = 0.0, height_m = 1.5;
  double span_max = 0.0, span_min = 0.0;  // rad, of viewing directions from the axis
  int photos = 12;
  Vec3 board_centre = Vec3::Zero();
  double board_max_m = 4.0;
};

/// The views of an arc walk.
struct ArcViews {
  std::vector<CameraPose> poses;  // one per photo
  bool portrait = true;
};

/// The widest arc (in 2° steps from span_max down to span_min) whose every view keeps `points`
/// 4 % of the image width inside the image: positions jittered by ±0.3 m in distance and ±5 cm
/// in height, the camera aimed at the points' bounding box in portrait or landscape (whichever
/// leaves more room at the middle of the walk; kept for the walk) and rolled ±4°. nullopt when
/// no span fits.
std::optional<ArcViews> fit_arc_views(const ArcWalk& walk, const camera::CameraIntrinsics& K,
                                      const std::vector<Vec3>& points, std::mt19937_64& rng);

/// The bounding box (px) of the points' projections (those in front of the camera).
struct PixelBox {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};
PixelBox projected_box(const camera::CameraIntrinsics& K, const CameraPose& pose, const std::vector<Vec3>& points);

/// A region of interest as a user draws it around a box: each side (left, top, right, bottom)
/// moved out by its fraction of the box's larger side, at least 8 px (straight edges bow a
/// little between vertices under distortion), then clipped to the image.
cv::Rect roi_rect(const PixelBox& box, const std::array<double, 4>& margin_fraction, int width, int height);

}  // namespace antpose::sim
