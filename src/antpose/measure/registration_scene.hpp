// What one antenna's registration sees (registration/register_antenna.hpp), built from the
// capture's camera poses and the antenna's region: the photos with every object already known
// in them, so that the outline is never sought on another object's edge.
//
// Known objects: the calibration board (nearer than the antenna: its printed extent plus a white
// margin hides what lies behind it); a mast found beside the antenna (an occluder in the photos
// where it stands in front of the antenna, elsewhere its outline is an edge that is not the
// antenna's); and the capture's other antennas as registered (the same, each by its box). The
// region's points on a neighbour's box or on the mast are left out: that object explains them,
// and left in they would draw the model onto it.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "antpose/camera/board.hpp"
#include "antpose/measure/camera_poses.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/register_antenna.hpp"

namespace antpose::measure {

/// A known box in the board frame: another antenna as registered.
struct KnownBox {
  Iso3 T_board_box = Iso3::Identity();
  Vec3 size_m = Vec3::Zero();
};

struct SceneObjects {
  std::pair<Vec3, Vec3> board_box;  // board frame, min and max corner (printed extent + margin)
  std::optional<reconstruction::Mast> mast;
  std::vector<KnownBox> neighbours;
  double object_clearance_m = 0.03;  // region points this near a neighbour's box or the mast are its own
  /// Where the antenna may show in a photo: the region carried there, grown by this share of its
  /// larger side (and `area_margin_px`) on every side.
  double area_growth = 0.25;
  double area_margin_px = 20;
  /// The depths (near, far along the rectangle photo's axis, m) where the model would fill the
  /// rectangle: each photo's area also covers that stretch of the rectangle's frustum, whatever
  /// object the region's points came from.
  std::optional<std::pair<double, double>> antenna_depth_m;
};

/// `region_view` indexes poses.views; `roi` is the user's rectangle there; `up_board` the upward
/// vertical in the board frame.
registration::AntennaScene registration_scene(const CameraPoses& poses, const Vec3& up_board,
                                              const reconstruction::RegionReconstruction& region,
                                              std::size_t region_view, const cv::Rect& roi,
                                              const SceneObjects& objects);

/// The depths (near, far, m along the rectangle photo's axis) at which the model's box would fill
/// the rectangle, widened for the unknown orientation and the rectangle's margin.
std::pair<double, double> depths_filling(const Vec3& size_m, const cv::Rect& roi,
                                         const camera::CameraIntrinsics& intrinsics);

/// A box's projected hull in a photo (px), empty where a corner is behind the camera.
std::vector<cv::Point2f> box_hull(const KnownBox& box, const camera::CameraIntrinsics& intrinsics,
                                  const Mat3& R_camera_board, const Vec3& t_camera_board);

/// The board's outline in a photo (px, as taken), empty when a corner is behind the camera.
std::vector<cv::Point2f> board_outline(const std::pair<Vec3, Vec3>& box, const camera::CameraIntrinsics& intrinsics,
                                       const Mat3& R_camera_board, const Vec3& t_camera_board);

}  // namespace antpose::measure
