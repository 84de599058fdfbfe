// The registration of one antenna model to its region (docs/non-contact.md, *Registration*):
//
//   strategies ──► candidate poses ──► each refined by its outline in every photo
//   (outline search: outline_search.hpp;          (silhouette.hpp); the best one turned about its
//    the points' global start: global_start.hpp)   long axis (yaw_turns.hpp), each turn also placed
//                                                  by the outline at its own orientation, and
//                                                  turned to face a known mast it turns a side
//                                                  to; the best ones slid along it
//                                                  (axis_slide.hpp); each
//                                                  refined too; the best's crease twins placed
//                                                  (yaw_turns.hpp); the best ones' and the twins'
//                                                  shape (edges, end caps) profiled with their
//                                                  pose (shape_fit.hpp);
//                                                  the points' starts also kept as they lie
//                                                         │
//                                    evidence of each and of each turned round (pose_evidence.hpp)
//                                                         │
//                      selection: the best shape, its rivals, front and back (pose_selection.hpp)
//
// A candidate must fit the user's rectangle: its box, projected into the rectangle's photo, spans
// at least `min_roi_span` of the rectangle's larger side and has its centre inside it (the
// rectangle was drawn around this antenna, so a pose on a neighbour or the mast does not
// qualify); its box must not pass through a known neighbour's (neighbour_clearance_m: two panels
// cannot share volume) nor come against the known mast (min_mast_gap_m: a clamp holds it off its
// pipe); and its outline must meet the photos' edges at least faintly (max_faint_outline_score,
// min_outline_views). Among those, only the comparison with the best (pose_selection.hpp) rules a
// candidate out: a fixed score cut would drop the true pose wherever the edges are faint or
// cluttered and a wrong pose meets other edges a little better, leaving that wrong pose unique.
// The answer must meet edges along about a third of its outline (max_answer_outline_score); one
// met only faintly that does not show which way it faces keeps only the downtilt and roll panels
// hang in (max_faint_open_facing_deg). Its faces are then checked against the region's points
// (face_plane.hpp), and the pose against each of its long edges left out (long_edge_check.hpp).
// "Not found" is a value: the result says why and what photo or rectangle would help; a pose that
// fits clearly but spans too little of a rectangle in which nothing else fits more than faintly
// says the rectangle is drawn too loosely, and poses that fit only against the mast say the mast
// was found.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/geometry/attitude.hpp"
#include "antpose/geometry/oriented_box.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/reconstruction/mast_search.hpp"
#include "antpose/registration/axis_slide.hpp"
#include "antpose/registration/face_plane.hpp"
#include "antpose/registration/global_start.hpp"
#include "antpose/registration/long_edge_check.hpp"
#include "antpose/registration/outline_search.hpp"
#include "antpose/registration/pose_evidence.hpp"
#include "antpose/registration/pose_selection.hpp"
#include "antpose/registration/shape_fit.hpp"
#include "antpose/registration/silhouette.hpp"
#include "antpose/registration/yaw_turns.hpp"

namespace antpose::registration {

/// What one antenna's registration sees, board frame.
struct AntennaScene {
  std::vector<SilhouetteView> views;  // the photos, with known objects (board, mast, neighbours)
  camera::CameraIntrinsics intrinsics;
  std::vector<Vec3> viewpoints_board;  // camera centres, one per view
  Vec3 up_board = Vec3::UnitZ();
  PointCloud points_board;                     // the region's points, normals towards the cameras
  std::size_t region_view = 0;                 // the photo the rectangle is drawn in
  cv::Rect roi;                                // the rectangle (px)
  std::vector<std::optional<cv::Rect>> areas;  // per view, where the antenna may show (px)
  std::optional<reconstruction::Mast> mast;    // a mast known beside it
  std::vector<OrientedBox> neighbours_board;   // the capture's other antennas as registered
};

struct RegisterOptions {
  OutlineSearchOptions search;
  bool points_start = true;  // the points' global start as a second strategy (where there are points)
  GlobalStartOptions points;
  std::size_t min_points_for_start = 200;
  std::size_t refine_candidates = 6;  // of each strategy, best first
  YawTurnOptions turns;               // the best refined candidates turned about their long axis (yaw_turns.hpp)
  bool place_turns = true;            // each turned start also placed by the outline at its own orientation
  bool face_mast = true;              // the best turned to face a known mast it turns a side to (facing_turn)
  AxisSlideOptions slide;             // the best refined candidates slid along their long axis (axis_slide.hpp)
  bool crease_twins = true;           // the best's crease twins (yaw_turns.hpp), placed by the outline at their turn
  /// The points' starts also kept where the points place them, their outline not descended:
  /// where a faint stretch of the true outline lets the descent lay it on a crease, the descent
  /// leaves the pose the points hold, and the selection could never weigh it.
  bool hold_points_poses = true;
  /// A candidate whose box, and a neighbour's, each shrunk by this on every face, still meet passes
  /// through that neighbour: no panel hangs there (the neighbour's own pose is known to a few cm).
  double neighbour_clearance_m = 0.05;
  /// A candidate whose panel (its box, the long edges rounded) comes closer to a known mast's
  /// surface than this hangs where no mount holds it: clamp, bracket and arm hold a panel's back
  /// at least 4–5 cm off its pipe, and the mast's outline and the pose fix the gap to a centimetre.
  double min_mast_gap_m = 0.02;
  /// The refinement: no restarts of its own (the strategies span the yaws), a trust region on the
  /// rotation, and a neighbour or the mast may hide part of the outline.
  SilhouetteOptions refine = [] {
    SilhouetteOptions o;
    o.rival_yaw_offsets_rad.clear();
    o.min_inlier_fraction = 0.35;
    o.max_rotation_change_rad = deg2rad(20.0);
    return o;
  }();
  EvidenceOptions evidence;
  SelectionOptions selection;
  ShapeOptions panel_shape;                        // the best candidates' shape profiled (shape_fit.hpp)
  reconstruction::MastSearchOptions mount_search;  // vertical structure behind and before the best
  FacePlaneOptions face_plane;                     // the result's faces checked against its points (face_plane.hpp)
  LongEdgeCheckOptions long_edges;                 // the result against each long edge left out (long_edge_check.hpp)
  /// The answer polished at last with the outline's width free (SilhouetteOptions::
  /// free_outline_width), and its long edges checked so: the candidates are compared by their
  /// outline as it is, but the answer's pose and σ rest on where its edges lie, not on the width
  /// that the shading of a rounded radome narrows alike in every photo.
  bool free_answer_width = true;
  std::size_t shape_candidates = 3;                // that many, by their outline
  double same_pose_deg = 2.0, same_pose_m = 0.03;  // refined candidates this close are one
  double min_roi_span = 0.55;                      // outline_search.hpp's rectangle_fit
  /// A pose fits its outline clearly where SilhouetteResult::score is at most `max_outline_score`
  /// (half of the outline without an edge within the cutoff scores 0.5) in at least
  /// `min_outline_views` photos. A result beyond it may still be the antenna, its edges faint
  /// against the background (a grey radome before cloud) or partly hidden (a neighbour, foliage):
  /// its outline covariance widens with its residuals, and the result says so. Candidates up to
  /// `max_faint_outline_score` take part in the selection; beyond that, under about a quarter of
  /// the outline meets an edge: no object (a rectangle on the sky) or the wrong model.
  double max_outline_score = 0.5;
  double max_faint_outline_score = 0.8;
  /// The answer itself must score at most `max_answer_outline_score`: about a third of its
  /// outline on edges running its way. A pose laid over a mount's pipes, the mast or a neighbour
  /// can meet that much of their edges, and a panel of its background's brightness can meet
  /// less than they do at its true pose; beyond it the photos do not tell the antenna from what
  /// stands round it, and the answer is none. Fainter candidates still serve as rivals.
  double max_answer_outline_score = 2.0 / 3.0;
  /// An answer met only faintly (beyond `max_outline_score`) whose rivals turn its boresight by
  /// more than `max_faint_open_facing_deg` (the front/back turn left out) shows no faces: beyond
  /// 45° a rival lies nearer the answer turned a side face forward than the answer itself, and
  /// the edges it faintly meets tell a panel from a pipe no better (a pipe fits a panel's model at
  /// every turn about its axis). Its long axis may then be a mount's pipe or the mast's, so its
  /// downtilt and roll are known only as panels hang: uniform over `hanging_downtilt_deg` and
  /// `hanging_roll_deg` (mechanical downtilt brackets, the outline search's range), whose standard
  /// deviations join its covariance about its own x and y axes ("long axis not shown to be the
  /// panel's"), with a warning.
  double max_faint_open_facing_deg = 45.0;
  std::array<double, 2> hanging_downtilt_deg{-12.0, 18.0};
  std::array<double, 2> hanging_roll_deg{-5.0, 5.0};
  std::size_t min_outline_views = 3;
  OptionProblems Check() const;
};

enum class RegistrationVerdict {
  kUnique,          // one pose, front and back decided
  kAmbiguousShape,  // another pose fits about as well (rivals)
  kFrontBackOpen,   // front and back undecided
};
std::string to_string(RegistrationVerdict verdict);  // "unique", "ambiguous", "front-back-open"

struct AntennaRegistration {
  bool found = false;
  std::string why_not;  // when not found: why, and what would help
  /// Not found because every candidate that fits hangs against the known mast (min_mast_gap_m):
  /// what was found is the mast, and a registration without the mast known would only find it again.
  bool against_mast = false;
  Iso3 T_board_antenna = Iso3::Identity();
  /// The pose's rotation covariance by its sources (rad², board frame): the outline's parts
  /// (silhouette.hpp OutlineCovarianceParts) and the profiled shape's spread.
  std::vector<UncertaintySource> rotation_covariance_sources;
  std::optional<ShapeFit> panel_shape;  // where the model's shape was refitted
  double dilation_yaw_sigma_rad = 0.0;  // SilhouetteResult's
  double outline_score = 1.0, outline_rms_px = 0.0;
  double outline_shape_sigma_m = 0.0;  // SilhouetteResult::shape_sigma_m: the model against the panel
  std::size_t outline_views = 0;
  RegistrationVerdict verdict = RegistrationVerdict::kUnique;
  std::vector<Iso3> rivals;       // other poses the evidence does not rule out (front and back as decided)
  std::vector<Iso3> near_rivals;  // poses within a few degrees it does not rule out: the σ covers them
  /// The planes of the faces the points show (face_plane.hpp), and the pose laid on each plane
  /// that disagrees with the outline: the σ covers those too.
  std::vector<FacePlane> face_planes;
  std::vector<Iso3> face_rivals;
  /// The result refined with each long edge left out (long_edge_check.hpp); where one disagrees
  /// with it, that edge decides the pose against the others, and the σ covers both.
  std::vector<LongEdgeLeftOut> long_edges_left_out;
  Selection selection;
  std::vector<PoseCandidate> candidates;  // refined, distinct, with their evidence
  std::size_t proposed = 0;               // candidates the strategies proposed
  std::vector<std::string> warnings;

  Mat3 rotation_covariance_board() const;  // the sources' sum
};

/// The strategies' proposals (the outline search; the points' global start where
/// `options.points_start` and the region has points), best of each first.
std::vector<PoseCandidate> propose_poses(const model::AntennaModel& model, const AntennaScene& scene,
                                         const RegisterOptions& options);

/// The proposals refined, judged and selected. A second registration of the same antenna in a
/// scene that knows more (a mast, neighbours) passes the first one's candidates as proposals;
/// those with a profiled shape keep it (PoseCandidate::panel_shape). The first registration's
/// turns are among them: the second needs none of its own (continuing(options)).
AntennaRegistration register_antenna(const model::AntennaModel& model, const AntennaScene& scene,
                                     const RegisterOptions& options, const std::vector<PoseCandidate>& proposals);

/// The gap between the panel of `model` at `T_board_antenna` (its box, the long edges rounded) and
/// the mast's surface over the mast's extent (m); negative where they overlap.
double mast_gap(const model::AntennaModel& model, const Iso3& T_board_antenna, const reconstruction::Mast& mast);

/// "Not found", marked against_mast: every pose of `model` that fits an outline hangs against or
/// through the known mast (RegisterOptions::min_mast_gap_m), so the outline found is the mast's.
AntennaRegistration found_only_the_mast(const model::AntennaModel& model, std::size_t proposed);

/// The options of a registration that starts from an earlier one's candidates: those hold the
/// earlier one's turns, so it makes none of its own (`turns.of_best = 0`).
RegisterOptions continuing(RegisterOptions options);

/// propose_poses, then the above.
AntennaRegistration register_antenna(const model::AntennaModel& model, const AntennaScene& scene,
                                     const RegisterOptions& options);

}  // namespace antpose::registration
