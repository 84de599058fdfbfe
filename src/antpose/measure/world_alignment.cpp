#include "antpose/measure/world_alignment.hpp"

#include <cmath>

#include "antpose/camera/board_pose.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {
namespace {

std::vector<BoardPhoto> board_photos(const Capture& capture, const CameraPoses& poses) {
  std::vector<BoardPhoto> photos;
  for (std::size_t i = 0; i < poses.views.size(); ++i)
    photos.push_back({poses.views[i].name, capture.shots[poses.shot_of_view[i]].t, poses.refined.R_camera_board[i],
                      poses.refined.t_camera_board[i], poses.refined.covariance[i].topLeftCorner<3, 3>()});
  return photos;
}

// The compass at the photos: the board's heading from it (heading_from_field), and the field along
// the walk checked against WMM and itself (check_field), which widens the heading's σ where the
// steel of the mast disturbs it.
void use_compass(WorldAlignment& out, const Capture& capture, const CameraPoses& poses,
                 const orientation::ImuData& data, const orientation::OrientationTrack& track,
                 const CameraImu& camera_imu, const WorldAlignmentOptions& options) {
  std::vector<double> shot_t;
  std::vector<Mat3> R_world_device;
  for (std::size_t i = 0; i < poses.views.size(); ++i) {
    shot_t.push_back(capture.shots[poses.shot_of_view[i]].t + camera_imu.time_offset_s);
    R_world_device.push_back(out.board.R_world_board * poses.views[i].R_camera_board.transpose() *
                             camera_imu.R_device_camera.transpose());
  }
  const auto fields = field_at_photos(data, track, shot_t, R_world_device, options.field.half_window_s);
  std::vector<CompassPhoto> compass;
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i]) compass.push_back({*fields[i], R_world_device[i]});
  if (options.heading_from_compass)
    out.board = heading_from_field(std::move(out.board), compass, camera_imu.compass, options.compass);
  // The fields through the board's heading as now decided.
  const Mat3 R_turn = exp_so3(Vec3(0.0, 0.0, out.board.compass_turn_rad.value_or(0.0)));
  std::vector<Vec3> field_world_uT, p_world_m;
  for (const auto& p : compass) field_world_uT.push_back(R_turn * p.field_world_uT);
  // Where each photo was taken: the camera centre in the board frame, turned to world axes.
  for (std::size_t i = 0; i < fields.size(); ++i)
    if (fields[i])
      p_world_m.push_back(out.board.R_world_board *
                          camera::camera_centre(poses.views[i].R_camera_board, poses.views[i].t_camera_board));
  out.field = check_field(field_world_uT, out.site, options.field, p_world_m);
  out.board.covariance(2, 2) += std::pow(out.field.heading_sigma_rad, 2);
  for (const auto& w : out.field.warnings) {
    out.board.warnings.push_back(w);  // carried into every antenna's attitude
    out.warnings.push_back(w);
  }
}

}  // namespace

OptionProblems WorldAlignmentOptions::Check() const {
  OptionProblems p;
  p.require(!orientation.empty(), "orientation", "an orientation estimator's name");
  p.nest("time_offset", time_offset.Check());
  p.require(board_world.min_photos >= 1, "board_world.min_photos", "at least 1");
  p.require(board_world.outlier_deg > 0, "board_world.outlier_deg", "positive");
  p.nest("field", field.Check());
  return p;
}

WorldAlignment align_to_world(const Capture& capture, const CameraPoses& poses, const CameraImu& device_camera_imu,
                              const WorldAlignmentOptions& options, Diagnostics& diagnostics,
                              const reconstruction::Progress& progress) {
  throw_unless_ok(options.Check(), "WorldAlignmentOptions");
  WorldAlignment out;
  if (progress) progress("phone orientation", 0, 1);
  const auto data = orientation::imu_data_from_capture(capture, diagnostics);
  const auto track = orientation::make_estimator(options.orientation)->estimate(data, diagnostics);
  if (progress) progress("phone orientation", 1, 1);
  const auto photos = board_photos(capture, poses);
  out.time_offset = check_time_offset(photos, track, device_camera_imu, options.time_offset);
  out.warnings = out.time_offset.warnings;
  CameraImu camera_imu = device_camera_imu;
  camera_imu.time_offset_s = out.time_offset.used_s;
  out.board = board_world_attitude(photos, track, camera_imu, options.board_world, diagnostics);
  out.warnings.insert(out.warnings.end(), out.board.warnings.begin(), out.board.warnings.end());
  if (capture.site) out.site = geomag::site_field(geomag::MagneticModel::wmm2025(), *capture.site);
  if (data.has_magnetometer()) use_compass(out, capture, poses, data, track, camera_imu, options);
  return out;
}

}  // namespace antpose::measure
