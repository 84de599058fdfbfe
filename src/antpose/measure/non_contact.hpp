// The non-contact measurement (thesis ch. 6; docs/non-contact.md): photos of the antenna with the
// calibration board in view → the antenna's azimuth, downtilt and roll in the world.
//
//   capture ──► board poses (PnP) ──► bundle adjustment ──► board in the world (board_world.hpp,
//      │                                   │                  phone orientation + R_device_camera)
//      └► phone orientation track          └► per ROI: region points (board frame)
//                                                 ──► model registration (global start + ICP)
//                                                     or the model-free face fit
//                                                 ──► R_world_antenna = R_world_board R_board_antenna
//
// Registration uncertainty (board frame, rad²): a spatial block bootstrap of the fine ICP
// (Künsch 1989: points of one stereo window share their errors, so blocks of `bootstrap_block_m`
// are resampled, not points), plus the camera poses' rotation uncertainty averaged over the views
// (errors common to the reconstruction that no resampling of points can see).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/geomag/wmm.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/measure/antenna_attitude.hpp"
#include "antpose/measure/board_world.hpp"
#include "antpose/measure/model_free.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/global_start.hpp"

namespace antpose::measure {

/// A user's rectangle: `image` as in shots.csv (or its file name), the rectangle in its pixels.
struct AntennaRoi {
  std::string image;
  reconstruction::Roi roi;
};

/// Parses "IMAGE:x,y,w,h" (InputError naming the value and the expected form).
AntennaRoi parse_roi(const std::string& text);

struct NonContactSetup {
  camera::BoardSpec board;
  camera::CameraIntrinsics intrinsics;
  CameraImu camera_imu;
  std::optional<model::AntennaModel> model;  // none: the model-free face fit
  std::vector<AntennaRoi> rois;
};

struct NonContactOptions {
  std::string orientation = "antpose-smoother";
  reconstruction::PoseRefinementOptions poses;
  reconstruction::RegionOptions region;
  registration::GlobalStartOptions registration = [] {
    registration::GlobalStartOptions o;
    o.downtilt_deg = {-5.0, 5.0, 15.0};
    return o;
  }();
  ModelFreeOptions model_free;
  BoardWorldOptions board_world;
  double model_spacing_m = 0.01;  // model surface samples
  double warn_rmse_m = 0.015;     // fit RMSE above this: poor fit warning
  double fail_rmse_m = 0.05;      // or fitness below fail_fitness: the region does not hold the model
  double fail_fitness = 0.5;
  int bootstrap_replicas = 40;
  double bootstrap_block_m = 0.10;
  std::uint64_t seed = 1;
  /// (stage, done, total) as the measurement advances.
  std::function<void(const std::string&, int, int)> progress;
};

/// One antenna (one ROI).
struct AntennaMeasurement {
  AntennaRoi roi;
  std::optional<std::string> error;  // why this antenna has no result (the others may have one)
  std::string method;                // "model NAME" or "model-free (front face + long axis)"
  Mat3 R_board_antenna = Mat3::Identity();
  Vec3 p_board_antenna = Vec3::Zero();  // m
  Mat3 cov_board = Mat3::Zero();        // registration, rad², board frame
  AntennaAttitudeResult attitude;
  double fit_rmse_m = 0.0;
  double fitness = 0.0;                     // share of region points within reach of the model
  std::optional<double> front_back_margin;  // model registration only
  reconstruction::RegionReconstruction region;
  PointCloud model_board;  // the registered model's samples, board frame (report)
  std::vector<std::string> warnings;
};

struct NonContactResult {
  std::vector<std::string> photos;     // every shot: "images/..."
  std::vector<std::size_t> posed;      // shots with a board pose, in order
  std::vector<std::string> skipped;    // "image: reason" for shots without one
  reconstruction::RefinedPoses poses;  // of the posed shots
  BoardWorldAttitude board;
  std::optional<geomag::SiteField> site;
  std::vector<AntennaMeasurement> antennas;  // one per ROI, in order
  std::vector<std::string> warnings;         // capture-wide
};

/// The whole measurement. `capture` should already carry the device's IMU calibration
/// (imu::apply). InputError for an ROI naming no photo of the capture or lying outside its
/// image; MeasurementError when the board is found in fewer than two photos or the board's world
/// attitude cannot be formed. A failure of one antenna is recorded in its `error`.
NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& setup,
                                     const NonContactOptions& options, Diagnostics& diagnostics);

/// The JSON of the command (docs/non-contact.md): per antenna azimuth_magnetic_deg,
/// azimuth_true_deg (null without a site), downtilt_deg, roll_deg, uncertainty_deg {azimuth,
/// downtilt, roll}, fit_rmse_m, photos_used, warnings, and more.
nlohmann::json to_json(const NonContactResult& result);

}  // namespace antpose::measure
