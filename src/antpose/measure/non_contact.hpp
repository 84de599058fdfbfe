// The non-contact measurement (thesis ch. 6; docs/non-contact.md): photos of the antenna with the
// calibration board in view → the antenna's azimuth, downtilt and roll in the world.
//
//   capture ──► board poses (PnP) ──► bundle adjustment ──► board in the world (board_world.hpp,
//      │                                   │                  phone orientation + R_device_camera;
//      │                                   │                  field_check.hpp: a disturbed compass)
//      └► phone orientation track          └► per ROI: region points (board frame)
//                                                 ──► model registration (global start + ICP,
//                                                     the outline, front/back by mount_side.hpp)
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
#include "antpose/measure/field_check.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/measure/model_free.hpp"
#include "antpose/measure/mount_side.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/reconstruction/reconstruct.hpp"
#include "antpose/registration/global_start.hpp"
#include "antpose/registration/silhouette.hpp"

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
  std::string orientation = "antpose-smoother";
  reconstruction::PoseRefinementOptions poses;
  reconstruction::RegionOptions region;
  registration::GlobalStartOptions registration = [] {
    registration::GlobalStartOptions o;
    o.downtilt_deg = {-5.0, 5.0, 15.0};
    return o;
  }();
  /// The outline stage: starts at the points' pose turned about the panel's axis by these
  /// angles, each refined by the silhouette in every photo (registration/silhouette.hpp). A box's
  /// outline is the same turned by 180°: front and back stay the points' decision (their
  /// visibility check), so the starts stay within ±90° of it. The points' own boresight is also
  /// polished at full resolution alone (non_contact.cpp, silhouette_search).
  bool silhouette = true;
  std::vector<double> silhouette_yaw_starts_deg = {0, 25, -25, 50, -50, 75, -75};
  /// Where no outline start converged, the free outline search is repeated from the points' best
  /// poses at other places (registration/global_start.hpp's hypotheses): up to this many, each
  /// more than other_position_m from the winner's centre and from each other's; then the winner
  /// moved by the model's depth along its boresight and slid along its axis and by half its depth
  /// (other_positions).
  std::size_t other_positions = 2;
  double other_position_m = 0.15;
  /// Last, where every other search failed: upright starts every this many degrees within ±90° of
  /// the points' boresight, each also turned about the mean line of sight by each of
  /// `fine_sight_turns_deg`, and placed before they descend; 0: none. 5810-1 (a 2 m panel 27 m
  /// away, seen side-on from behind over a 9° arc) was refused: the points lay 0.20 m off towards
  /// the mast and 76° off in rotation, and the outline placed and then descended to the truth
  /// (0.021, against 0.47 for the best wrong pose) only from yaws −5° to +10° of it with its
  /// in-image tilt right. Seen side-on, its 5.2° downtilt turns it in the photos, so upright
  /// starts missed even at the true yaw. Answered, it is 0.02° off in azimuth, 0.06° in downtilt.
  double fine_yaw_step_deg = 10.0;
  std::vector<double> fine_sight_turns_deg = {-6.0, 0.0, 6.0};
  /// Last of all, the region's points this near the mast's surface (its clamps too) are set
  /// aside, the model registered to the rest and the free search repeated from there and from
  /// its other_positions; 0: never. The sim's clamps reach 0.045 m beyond the mast.
  double off_mast_m = 0.06;
  double silhouette_rival_margin = 0.02;  // a converged start within this score is a rival
  /// ... or, at another yaw, within this share of the winner's score, if more. Poses 67–79° apart
  /// scored 0.288 and 0.343 (2912-2, the worse one right) and 0.294 and 0.368 (2112-3, the better
  /// one right); of the right winners on 34 development sites, no other start at another yaw came
  /// within half the winner's score.
  double silhouette_rival_share = 0.35;
  /// A converged start whose score (the outline's mean truncated edge cost, 0 .. 1) is above this
  /// fits too little of the outline to be trusted. On the development sites 601–912 and 1008
  /// the right poses scored 0.013–0.351, the confidently wrong ones (606-3 65°, 610-1 28°,
  /// 1008-1 130° off) 0.466–0.562.
  double silhouette_max_score = 0.4;
  /// A winner scoring above this fits the outline poorly enough that the held-axis search (the
  /// points' long axis, the mast known) is run too, and wins unless the winner, descended again
  /// with the mast known, scores lower by more than silhouette_rival_margin. The right
  /// poses of 27 development sites scored at most 0.24 but for three antennas partly hidden by
  /// their mast (1612-3, 1712-1: 0.34–0.36), and 2112-3's, 79° off, 0.37.
  double silhouette_doubtful_score = 0.3;
  /// A start whose descent left its basin is descended again from where it ended, up to this many
  /// times, until a descent stays put (non_contact.cpp, silhouette_search). Twice once let a start
  /// far from the truth settle in a wrong basin that scored best (606-3, 52° off, before the mast
  /// was known to the held-axis search); with one, 2606-3 (a 2 m panel from the ground) was
  /// refused, its one start to reach the right basin doing so on a second descent that moved 23°
  /// (so counted as leaving its basin); a third stays put there. With two, on 31
  /// development sites 2606-3 is answered (−3.9° on a disturbed site, σ 4.9°) and 606-3, 1706-1
  /// and 2106-1 fit with the axis free (their downtilt errors 0.01–0.05°), nothing else moved.
  int silhouette_redescents = 2;
  /// The free search's winner is tilted by ± this about the axis across its long axis and the
  /// line of sight, and refined again (non_contact.cpp, silhouette_search); 0: not probed. Seen
  /// from below, the descents from upright stopped 3.4° short of 3312-2's 8.3° downtilt; on 34
  /// development sites no error moved by more than 0.12°, and two σ narrowed: 2204-1's azimuth
  /// (89° → 0.95°, error −0.03° → +0.09°), 1712-3's downtilt (3.8° → 0.21°, error +0.11° → −0.09°).
  double silhouette_tilt_probe_deg = 4.0;
  /// The starts already span the yaws: the refinement's own mirror restarts are left out.
  registration::SilhouetteOptions silhouette_options = [] {
    registration::SilhouetteOptions o;
    o.rival_yaw_offsets_rad.clear();
    o.min_inlier_fraction = 0.35;  // a neighbouring panel or the mast may hide part of the outline
    return o;
  }();
  ModelFreeOptions model_free;
  /// The antpose filter's covariance weights its corrections (a steady state near 2° tilt and 7°
  /// heading) and is not a calibrated uncertainty, so the orientation error common to a capture
  /// is modelled: heading 0.6°, tilt 0.1° per axis (the board attitude errors of the development
  /// captures were 0.42° and 0.06° RMS, a calibrated typical phone; docs/non-contact.md).
  BoardWorldOptions board_world = [] {
    BoardWorldOptions o;
    o.common_sigma_rad = Vec2(deg2rad(0.1), deg2rad(0.6));
    return o;
  }();
  /// The board's heading from the compass at the photos, each photo's tilt from the board
  /// (heading_from_field, board_world.hpp); false: from the orientation track at the photos.
  bool heading_from_compass = true;
  CompassOptions compass;
  FieldCheckOptions field;        // magnetic disturbance (field_check.hpp)
  double model_spacing_m = 0.01;  // model surface samples
  double warn_rmse_m = 0.015;     // fit RMSE above this: poor fit warning
  double fail_rmse_m = 0.05;      // or fitness below fail_fitness: the region does not hold the model
  double fail_fitness = 0.5;
  double fail_fitness_with_outline = 0.2;  // when the outline matched the photos
  double warn_fitness = 0.75;              // share of points near the model below this: warning
  /// The outline's yaw σ owed to a dilation of the whole outline alone
  /// (registration::SilhouetteResult::dilation_yaw_sigma_rad) above this: a warning to photograph
  /// over a wider arc or from nearer (the azimuth target).
  double warn_dilation_yaw_sigma_deg = 1.0;
  /// The outline refit with the points' long axis held (hold_axis_to_points) has fitted something
  /// else where it leaves fewer of the region's points near the model than this share of those
  /// the points' own pose does: it is not taken (2112-1, a thesis panel face-on before its mast:
  /// 0.16 of the points' own share; the answered antennas of 22 development sites kept at least
  /// 0.88). The free search's winner is not held to it: its axis may lie off the points' until
  /// that refit (1602-1: below 0.6 before it, 1.01 after).
  double outline_points_fit_ratio = 0.6;
  double rival_min_deg = 10.0;  // another hypothesis this far in boresight, scoring within the
                                // ambiguity margin, is a rival (AntennaMeasurement::rivals_board)
  /// The outline against the points' long axis (hold_axis_to_points in non_contact.cpp, and
  /// long_axis.hpp): beyond the gate the points' tilt along the line of sight is kept, with
  /// points_axis_sigma_deg and half the difference (either may be the wrong one: 602-1 the
  /// points 3.2° off). The outline's axis was 4–7° off where it failed (development sites
  /// 602–612); from the ground, 20–30 m away, the points' own axis was 1.1–2.0° off where the
  /// outline's was right within 0.2° (sites 710-1, 712-2, 802, 810-1), so smaller disagreements
  /// keep the outline's.
  double axis_gate_deg = 3.0;
  /// The board hides what lies behind it and is not the antenna: the outline is not sought on
  /// it, nor region points taken from it, within its printed extent plus this white margin
  /// (squares; printed boards keep about one).
  double board_margin_squares = 1.5;
  /// Region points within this of the board's plane, inside that margin, are the board's.
  double board_thickness_m = 0.03;
  double points_axis_sigma_deg = 0.2;
  /// Where the outline fits from no start, the search again with the long axis held to the
  /// points' (non_contact.cpp), each descent monotone with this many step halvings
  /// (SilhouetteOptions::max_step_halvings).
  bool held_axis_search = true;
  int held_axis_step_halvings = 3;
  /// The points' axis of a narrow panel from the ground: 0.13–0.71° off on 8 development
  /// antennas (RMS 0.47°), per axis.
  double held_axis_sigma_deg = 0.35;
  /// The yaw about a held axis is profiled (profile_yaw in non_contact.cpp) over ± this range in
  /// these steps; yaws scoring within the margin of the minimum bound it.
  double held_yaw_range_deg = 40, held_yaw_step_deg = 2, held_yaw_margin = 0.05;
  /// Where the profile has two basins (a box's outline repeats either side of the view where it
  /// looks widest), the region's points judge: the one whose seen surface holds this share more
  /// of them within reach wins; closer, the other stays a rival. 4906-1: the truth's held 0.567,
  /// its mirror 0.508 (12 % more). 5611-3 (its region cluttered by the mast and two panels'
  /// brackets): a basin 22° from the truth's held 0.38, the truth's 0.36 (5.5 % less).
  double seen_fit_margin = 0.10;
  MountSideOptions mount;  // the mount's side decides front and back (mount_side.hpp)
  /// The mast as a known occluder and background for the outline (reconstruction/mast.hpp),
  /// fitted to the region's points this far beyond the panel's box turned any way about its axis.
  bool mast = true;
  double mast_clearance_m = 0.03;
  double mast_outline_below_m = 1.5;  // its outline is sought over this stretch below the panel
  reconstruction::MastOptions mast_options;
  /// Where the mount's side cannot tell front from back, the downtilt's sign does: turning a
  /// panel round negates its downtilt, and mounts tilt panels down (tilt kits 0–15°), not up by
  /// more than this.
  double max_uptilt_deg = 3.0;
  /// A rectangle is drawn around its antenna, so the registered antenna's box covers most of it
  /// in its photo. Below this share the object behind is measured too and taken where it fills
  /// the rectangle clearly better and lies within an antenna's size (a nearer panel of the same
  /// mount crossed the rectangle); otherwise a warning says another object may have been
  /// measured. Site 5111: 24 % where the nearer middle one of three panels, crossing the lower
  /// half of the top one's rectangle, was measured for it, 52 % for the top one behind it; 59 %
  /// for a right answer partly hidden by the board.
  double min_roi_fill = 0.4;
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
  /// Other poses that fit about as well (another yaw of the outline, front and back): each
  /// angle's σ is widened to cover them (half the difference, a two-way mixture's spread).
  std::vector<Mat3> rivals_board;
  AntennaAttitudeResult attitude;
  double fit_rmse_m = 0.0;
  double fitness = 0.0;                      // share of region points within reach of the model
  std::optional<double> front_back_margin;   // model registration only
  std::optional<double> silhouette_rms_px;   // the outline's edge RMS, when it decided the pose
  std::optional<MountSide> mount_points;     // beyond the model, behind and before the panel, when counted
  std::optional<reconstruction::Mast> mast;  // the mast found beside it, if any (the outline's occluder)
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
  FieldCheck field;                          // the magnetometer at the photos
  std::vector<AntennaMeasurement> antennas;  // one per ROI, in order
  std::vector<std::string> warnings;         // capture-wide
};

/// The whole measurement. `capture` should already carry the device's IMU calibration
/// (imu::apply). InputError for an ROI naming no photo of the capture or lying outside its
/// image, or a number of models other than 0, 1 or one per ROI; MeasurementError when the board is found in fewer than two photos or the board's world
/// attitude cannot be formed. A failure of one antenna is recorded in its `error`.
NonContactResult measure_non_contact(const Capture& capture, const NonContactSetup& setup,
                                     const NonContactOptions& options, Diagnostics& diagnostics);

/// The JSON of the command (docs/non-contact.md): per antenna azimuth_magnetic_deg,
/// azimuth_true_deg (null without a site), downtilt_deg, roll_deg, uncertainty_deg {azimuth,
/// downtilt, roll}, fit_rmse_m, photos_used, warnings, and more.
nlohmann::json to_json(const NonContactResult& result);

}  // namespace antpose::measure
