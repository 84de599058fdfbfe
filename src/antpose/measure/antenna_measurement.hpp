// One antenna of a non-contact measurement (non_contact.hpp): its rectangle → the region's points
// (reconstruction/reconstruct.hpp) → the model registered to its points and its outline in every
// photo (registration/register_antenna.hpp), or the model-free face fit → its attitude in the
// world with a covariance (antenna_attitude.hpp), widened to cover every pose the evidence does
// not rule out.
//
// Covariance (board frame, rad²): the outline refinement's at the pose (silhouette.hpp: edge
// noise, the model's shape tolerance, biases shared along a mesh edge and by the whole outline),
// plus the camera poses' rotation uncertainty averaged over the photos (common to the whole
// reconstruction), plus the board's attitude in the world (antenna_attitude.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/measure/antenna_attitude.hpp"
#include "antpose/measure/camera_poses.hpp"
#include "antpose/measure/model_free.hpp"
#include "antpose/measure/registration_scene.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/reconstruction/mast_search.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/register_antenna.hpp"

namespace antpose::measure {

/// A user's rectangle: `image` as in shots.csv (or its file name), the rectangle in its pixels.
/// `drawn` is as the user gave it, on the photo shown upright; `roi` is the same rectangle in the
/// photo's stored pixels, where the measurement works (in_stored_pixels; equal where the photo has
/// no EXIF turn, exif_orientation 1).
struct AntennaRoi {
  std::string image;
  reconstruction::Roi roi;
  reconstruction::Roi drawn;
  int exif_orientation = 1;
};

/// Parses "IMAGE:x,y,w,h" (InputError naming the value and the expected form).
AntennaRoi parse_roi(const std::string& text);

struct AntennaOptions {
  reconstruction::RegionOptions region;
  registration::RegisterOptions registration;
  ModelFreeOptions model_free;
  /// The board hides what lies behind it and is not the antenna: no outline is sought on it, nor
  /// region points taken from it, within its printed extent plus this white margin (squares;
  /// printed boards keep about one), and within board_thickness_m of its plane.
  double board_margin_squares = 1.5;
  double board_thickness_m = 0.03;
  /// A mast sought among the region's points off the registered box (reconstruction/mast.hpp) and
  /// made known to a second registration, over this stretch below the panel. Where the mast holds
  /// at least `mast_points_share` of the region's points, the first registration's starts from the
  /// points were drawn towards it: the second one also starts afresh from the points without them.
  /// A mast found again within `same_mast_m` of the one the registration already knew
  /// (reconstruction::same_mast) needs no second registration: that one saw it.
  bool mast = true;
  double same_mast_m = 0.01;
  double mast_clearance_m = 0.03;
  double mast_outline_below_m = 1.5;
  double mast_points_share = 0.1;
  reconstruction::MastOptions mast_options;
  reconstruction::MastSearchOptions mast_search;  // by its outline, where the points give no mast
  double min_viewing_span_deg = 2.0;              // of the photos' lines of sight to the antenna
  double warn_viewing_span_deg = 10.0;            // below: a warning that the angles rest on one outline
  double reach_m = 0.03;                          // a point this near the registered model is explained by it
  double warn_rmse_m = 0.015;                     // their RMS distance above this: a poor fit
  double warn_fitness = 0.5;                      // a share of the region's points explained below this: a warning
  double warn_dilation_yaw_sigma_deg = 1.0;
  /// An answer whose σ reaches what an audit counts as a wrong reading (3° of azimuth, 1° of
  /// downtilt) cannot tell a right antenna from a wrong one: a warning names the σ, what limits it
  /// and what would narrow it.
  double warn_sigma_azimuth_deg = 3.0;
  double warn_sigma_downtilt_deg = 1.0;
  OptionProblems Check() const;
};

/// One antenna (one ROI).
struct AntennaMeasurement {
  AntennaRoi roi;
  std::optional<std::string> error;  // why this antenna has no result (the others may have one)
  std::string method;                // "model NAME, ..." or "model-free (front face + long axis)"
  Mat3 R_board_antenna = Mat3::Identity();
  Vec3 p_board_antenna = Vec3::Zero();       // m
  std::vector<UncertaintySource> cov_board;  // the registration's rotation covariance by source, board frame
  std::vector<Mat3> rivals_board;            // other poses the evidence does not rule out
  std::vector<Mat3> face_rivals_board;       // the result laid on its faces' points where they disagree with it
  std::vector<registration::FacePlane> face_planes;  // the faces' planes (registration/face_plane.hpp)
  std::vector<registration::LongEdgeLeftOut> long_edges_left_out;  // registration/long_edge_check.hpp
  registration::RegistrationVerdict verdict = registration::RegistrationVerdict::kUnique;
  std::optional<registration::Comparison> runner_up;  // the result against the best other pose
  /// Where the result turns a side face to the mast: it against the best pose that faces the mast.
  std::optional<registration::Comparison> mast_rival;
  std::optional<registration::Comparison> front_back;
  registration::FrontBackCue front_back_cue = registration::FrontBackCue::kNone;
  AntennaAttitudeResult attitude;
  double fit_rmse_m = 0.0;
  double fitness = 0.0;                                // share of region points within reach of the model
  std::optional<double> silhouette_rms_px;             // the outline's edge RMS
  std::optional<double> model_shape_sigma_m;           // the model's shape error per edge, as the outline measured it
  std::optional<double> edge_radius_m;                 // the radome's edge rounding fitted (a parametric panel)
  std::optional<double> end_cap_rim_m;                 // how far its end caps stand out of the radome (fitted)
  std::vector<std::array<double, 2>> shapes_within_m;  // (radius, rim) the photos do not rule out
  std::optional<reconstruction::Mast> mast;            // the mast found beside it, if any
  std::size_t candidates = 0;                          // poses proposed by the strategies
  std::vector<registration::PoseCandidate> registration_candidates;  // refined and distinct (board frame)
  reconstruction::RegionReconstruction region;
  std::size_t region_view = 0;  // the rectangle's photo among the posed views
  PointCloud model_board;       // the registered model's samples, board frame (report)
  std::vector<std::string> warnings;

  Iso3 T_board_antenna() const { return isometry(R_board_antenna, p_board_antenna); }
};

/// What every antenna of a capture shares.
struct CaptureContext {
  const CameraPoses* poses = nullptr;
  const BoardWorldAttitude* board = nullptr;
  const std::optional<geomag::SiteField>* site = nullptr;
  camera::BoardSpec board_spec;
  Vec3 up_board = Vec3::UnitZ();
  Mat3 cov_poses_board = Mat3::Zero();  // the camera poses' rotation uncertainty (board frame)
};

/// The region's points of one rectangle (its photo `region_view` among poses.views). With a model
/// (nullptr: model-free) a region with few points is returned with a warning, its depth sought
/// where the model fills the rectangle if the features give none: the outline may still place
/// it. MeasurementError where the region cannot be reconstructed (reconstruct_region's reasons).
reconstruction::RegionReconstruction antenna_region(const CaptureContext& capture, std::size_t region_view,
                                                    const AntennaRoi& roi, const model::AntennaModel* model,
                                                    const AntennaOptions& options,
                                                    const reconstruction::Progress& progress = {});

/// The warning of AntennaOptions::warn_sigma_azimuth_deg and warn_sigma_downtilt_deg for an
/// attitude whose σ reaches them, naming the source of its budget that limits it most; nullopt
/// where both angles are narrower.
std::optional<std::string> imprecision_warning(const AntennaAttitudeResult& attitude, const AntennaOptions& options);

/// Registers `model` (nullptr: the model-free fit) to the region with `neighbours` known, and
/// reads the attitude. `previous`: an earlier registration's candidates, judged again beside a new
/// outline search instead of every strategy; `m.mast`, where set, is known from the start (found
/// by that registration, or a neighbour's) and sought again beside the new pose. Sets `m.error` where no pose is
/// found.
void measure_antenna(AntennaMeasurement& m, const model::AntennaModel* model, const CaptureContext& capture,
                     const std::vector<KnownBox>& neighbours, const AntennaOptions& options,
                     const std::vector<registration::PoseCandidate>& previous = {});

}  // namespace antpose::measure
