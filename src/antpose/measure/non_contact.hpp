// The non-contact measurement (thesis ch. 6; docs/non-contact.md): photos of the antenna with the
// calibration board in view → the antenna's azimuth, downtilt and roll in the world. A pipeline
// of stages, each a function with its options and a typed result:
//
//   capture ─► camera poses (camera_poses.hpp: board poses by PnP, bundle adjustment)
//           ─► the board in the world (world_alignment.hpp: orientation track, the capture's time
//              offset, compass heading, the field along the walk)
//           ─► per antenna (antenna_measurement.hpp): region → points (reconstruction/)
//              → registration: strategies, evidence, selection (registration/register_antenna.hpp)
//              → attitude + covariance (antenna_attitude.hpp)
//           ─► the antennas again with each other known (joint: a neighbour is explained by its
//              own model, never taken for the target); one left with front and back open once
//              more with the mast its neighbours found
//           ─► result, JSON (non_contact_json.cpp), report (report.hpp)
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/camera/board.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/check.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/measure/antenna_measurement.hpp"
#include "antpose/measure/camera_poses.hpp"
#include "antpose/measure/scale_check.hpp"
#include "antpose/measure/world_alignment.hpp"
#include "antpose/model/antenna_model.hpp"

namespace antpose::measure {

struct NonContactSetup {
  camera::BoardSpec board;
  camera::CameraIntrinsics intrinsics;  // as calibrated (rescaled to the photos where they differ)
  CameraImu camera_imu;
  /// None: the model-free face fit; one: every antenna's; else one per ROI, in order.
  std::vector<model::AntennaModel> models;
  std::vector<AntennaRoi> rois;

  /// The model of ROI k, or nullptr (model-free).
  const model::AntennaModel* model_for(std::size_t k) const {
    if (models.empty()) return nullptr;
    return &models[models.size() == 1 ? 0 : k];
  }
};

struct NonContactOptions {
  CameraPoseOptions poses;
  WorldAlignmentOptions world;
  AntennaOptions antenna;
  ScaleCheckOptions scale;
  /// Rounds with the other antennas known (their boxes masked in the photos, their points left
  /// out); 0: each antenna alone.
  int joint_rounds = 1;
  /// In the joint pass, an antenna whose own photos confirm no mast takes the nearest one found
  /// for another antenna within this horizontal distance of its centre (neighbours_mast). Panels
  /// side by side hang on one frame round one mast: a sector frame 2–3 m wide, held a few
  /// decimetres out from the mast, puts its outer panels up to ~1.7 m from it.
  double shared_mast_reach_m = 2.0;
  /// (stage, done, total) as the measurement advances.
  std::function<void(const std::string&, int, int)> progress;
  OptionProblems Check() const;
};

struct NonContactResult {
  std::vector<std::string> photos;      // every shot: "images/..."
  std::vector<std::size_t> posed;       // shots with a board pose, in order
  std::vector<std::string> skipped;     // "image: reason" for shots without one
  camera::CameraIntrinsics intrinsics;  // of the photos
  reconstruction::RefinedPoses poses;   // of the posed shots
  BoardWorldAttitude board;
  std::optional<geomag::SiteField> site;
  FieldCheck field;  // the magnetometer at the photos
  TimeOffsetCheck time_offset;
  std::vector<AntennaMeasurement> antennas;  // one per ROI, in order
  std::vector<std::string> warnings;         // capture-wide
};

/// The whole measurement. `capture` should already carry the device's IMU calibration
/// (imu::apply). InputError for an ROI naming no photo of the capture or lying outside its image,
/// or a number of models other than 0, 1 or one per ROI; MeasurementError when the board is found
/// in fewer than two photos or its world attitude cannot be formed. An antenna that cannot be
/// measured has its `error` (the others may have results).
NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& setup,
                                     const NonContactOptions& options, Diagnostics& diagnostics);

/// The boxes of antenna k's neighbours that the joint pass takes as known: the other antennas
/// registered with a model whose box is settled (a unique pose, or front and back open: the same
/// box). A neighbour whose registration is ambiguous is not known: one of its rival poses may be
/// the true one, and the pose reported may stand on antenna k itself, where taking it as known
/// would rule out k's true pose and leave a wrong one unique.
std::vector<KnownBox> settled_neighbours(const std::vector<AntennaMeasurement>& antennas, const NonContactSetup& setup,
                                         std::size_t k);

/// The mast antenna k may hang on where its own photos confirmed none: the nearest found for
/// another measured antenna of the capture whose axis lies within `reach_m` of k's centre and
/// clear of k's box (across the mast's axis). Panels side by side hang on one structure, and where one
/// panel's neighbours hide the foot of its mast in the photos, another panel may show it.
/// nullopt where no other antenna's mast stands there.
std::optional<reconstruction::Mast> neighbours_mast(const std::vector<AntennaMeasurement>& antennas,
                                                    const NonContactSetup& setup, std::size_t k, double reach_m);

/// Per antenna, the mast it is measured once more with after the joint pass, or nullopt: an
/// antenna left with front and back open and no mast of its own takes the one its neighbours found
/// in that pass (neighbours_mast), where their neighbours were masked and a mast's foot may show
/// only then; where the mast stands clearly behind one face, it decides them.
std::vector<std::optional<reconstruction::Mast>> front_back_masts(const std::vector<AntennaMeasurement>& antennas,
                                                                  const NonContactSetup& setup, double reach_m);

/// The JSON of the command (docs/non-contact.md): per antenna azimuth_magnetic_deg,
/// azimuth_true_deg (null without a site), downtilt_deg, roll_deg, their 1σ under the same keys
/// in sigma and its budget by source (sigma_budget), verdict, fit_rmse_m, photos_used, warnings,
/// and more. Every numeric key carries its unit.
nlohmann::json to_json(const NonContactResult& result);

}  // namespace antpose::measure
