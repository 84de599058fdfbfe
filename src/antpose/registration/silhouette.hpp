// Pose refinement of an antenna model by its silhouette in the photos.
//
// Dense stereo barely reconstructs a panel's flat, texture-free radome, so ICP fixes the long
// axis well but the yaw about it poorly. The panel's OUTLINE, however, is sharp in every photo,
// and its apparent width (w|cos θ| + d|sin θ| for a box seen at angle θ) changes with yaw over
// views spanning 25–40°. This refines the 6-DOF pose so that the model's outer silhouette meets
// the image edges in all views.
//
// Method: model-based edge tracking (Harris, "Tracking with rigid models", Active Vision 1992;
// Drummond & Cipolla, "Real-time visual tracking of complex structures", PAMI 24(7), 2002).
// For the current pose, per view: the mesh's contour generators (edges between a triangle facing
// the camera and one facing away) are projected with the distorted camera model; only points on
// the OUTER contour are kept (a rasterised mask must be filled just inside and empty just
// outside: inner shading edges and parts hidden by the brackets are not geometry). Along each
// sample's normal a 1-D search finds the nearest strong edge (gradient along the normal, a local
// maximum of its magnitude, ≥ half the strongest on the line; sub-pixel by a parabola; behind the
// outline the line ends at the projection's middle, short of the model's own far side, unless
// line_ends_at_middle is off); the residual is the signed distance. Outline points off the
// model's box (brackets, whose outline runs into the arms that hold them) are measured for the
// score with attachments only.
// Gauss–Newton with Tukey's biweight (scale from the MAD) solves for the pose, each step's
// rotation held within a trust region (max_step_rotation_rad: the yaw about the long axis is
// weakly fixed and a free step can jump basins); silhouettes are re-extracted every iteration.
// A Gaussian pyramid (cv::pyrDown) runs coarse-to-fine: wide searches on blurred images first
// (inner shading gone), ±4 px last. Optionally a monotone descent at full resolution: a step
// that raises the score is halved, as a line search would (Nocedal & Wright, Numerical
// Optimization, ch. 3), and none lowering it ends the descent.
// Scene edges not in the model (clamp arms, mast, board) are down-weighted by the robust loss;
// known objects (the board, a mast fitted to the scene) are masked out of the search instead.
// Edges are searched in linear intensity (the photo's gamma undone): in encoded values a blurred
// step's steepest point moves towards its dark side, biasing the outline's width and so the yaw.
//
// A box's outline repeats about θ = atan(d/w), so with a narrow arc of views a mirror yaw 30–50°
// away fits nearly as well: descents restarted from the solution turned ±30° about the long axis
// find it; the best score within max_rotation_change_rad of the start wins and a rival scoring
// nearly as well (rival_margin) or better is reported (converged = false, a warning).
//
// Covariance (at the solution, H = Jᵀ W J): H⁻¹ (κ σ² H + Σ_g b_g b_gᵀ) H⁻¹. σ² is the samples'
// weighted variance about their mesh edge's offset (the offsets are the b_g's, below, and are not
// counted twice), κ = correlation_length_px / sample_spacing_px because neighbouring samples
// share the blur and JPEG blocks. The sum models errors common to all samples of a mesh edge,
// which do not average out along it nor over the views: b_g = Σ_{i∈g} w_i J_iᵀ s_i over all views,
// once with s_i = f · σ_shape / depth (the model's shape error: a real radome's extrusion,
// rounding and end caps depart from the model by millimetres along a whole edge, and where the
// views leave a turn weakly observed, such as a panel seen from below turning about the
// horizontal across the line of sight, that error reads as tenths of a degree) and once with
// s_i = edge_bias_px (edge localisation biased by the shading of rounded edges near the outline and
// by the background, both similar from view to view under one sun). One more such b, over every
// sample of every edge with s_i = outline_dilation_px, is the whole outline found wider (or
// narrower) than the model's by the same amount everywhere: blur and the shading of the rounded
// long edges do that in every photo alike, and for a narrow panel seen face-on only the yaw can
// widen the outline, so a dilation of a fraction of a pixel reads as degrees of yaw.
// σ_shape is measured where the photos show it: each mesh edge's offset from its outline,
// d_g = Σ w p r / Σ w p² (m; p = f / depth), has the noise variance v_g of its samples' scatter
// about it, so over the G edges that show one the shape error's variance is estimated as
// σ̂² = Σ (d_g² − v_g) / (G − 6), six of the offsets being taken up by the pose; v_g also holds
// the edge bias's share (edge_bias_px Σ w p / Σ w p²)², which its own b_g carries. It is pooled with
// the prior shape_tolerance_m, which counts as shape_prior_edges edges (a scaled inverse-χ²
// prior; Gelman et al., Bayesian Data Analysis, 3rd ed., §2.6):
//   σ_shape² = (ν₀ σ₀² + (G − 6) σ̂²) / (ν₀ + G − 6),
// so a model that departs from the panel widens the σ it gives, and one that matches narrows it.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/camera/camera_model.hpp"
#include "antpose/core/check.hpp"
#include "antpose/geometry/point_cloud.hpp"
#include "antpose/model/mesh.hpp"
#include "antpose/registration/edge_pyramid.hpp"

namespace antpose::registration {

class KnownObjectMasks;  // known_object_masks.hpp

struct SilhouetteView {
  cv::Mat image;  // CV_8UC1 grey photo as taken (distorted), full size
  Mat3 R_camera_board = Mat3::Identity();
  Vec3 t_camera_board = Vec3::Zero();  // p_camera = R p_board + t (refined camera pose)
  /// Crop (px) holding the antenna's whole outline plus the search range; else the start's
  /// projected bounding box + margin (the normal choice).
  std::optional<cv::Rect> roi;
  /// Known objects nearer than the antenna (the calibration board, a mast in front of it), as
  /// image polygons (px, as taken): outline points on them are hidden and not used, and the
  /// edge search does not look into them (nor within mask_guard_px of their border), so their
  /// border is never taken for the antenna's outline.
  std::vector<std::vector<cv::Point2f>> occluders;
  /// Known edges of other objects (a mast behind the antenna), as image polylines (px, as
  /// taken): within mask_guard_px of them the antenna's outline cannot be told from theirs, and
  /// neither outline points nor edges there are used.
  std::vector<std::vector<cv::Point2f>> background_edges;
  /// The photo's edge images (edge_pyramid.hpp), shared by every view of this photo so that each
  /// crop is prepared once; nullptr (or one made with another gamma or smoothing): each
  /// refinement prepares its own.
  std::shared_ptr<EdgePyramid> edges;
  /// The known objects' masks drawn once for every refinement in this photo with these objects
  /// (known_object_masks.hpp); nullptr: each refinement draws its own. Used with `edges`.
  std::shared_ptr<KnownObjectMasks> masks;
};

struct SilhouetteOptions {
  double search_range_px = 40;  // ± along the normal at the coarsest level (full-resolution px)
  // Behind the outline the search line ends at the projection's middle, short of the model's own
  // far side (see the file comment); false: it runs the whole search range.
  bool line_ends_at_middle = true;
  double fine_search_px = 4;          // ± at every later level (in that level's px)
  double sample_spacing_px = 3;       // along the contour, at full resolution (× 2^level on coarser levels)
  double min_edge_gradient = 3;       // linear grey levels (0–255) / px after smoothing; weaker: no sample
  double smoothing_sigma_px = 1.0;    // Gaussian before the gradient, per level
  double gamma = 2.2;                 // photo encoding undone before edge search (sRGB ≈ 2.2); 0: as stored
  int max_level = 3;                  // coarsest pyramid level allowed
  double min_coarse_width_px = 16;    // the coarsest level keeps the model's projection this wide
  int max_iterations_per_level = 12;  // Gauss–Newton steps per level and descent; done below 0.01 px
  double swing_motion_px = 0.05;      // or below this when a step reverses the last (see the .cpp)
  // ≥ 0: a monotone descent at full resolution: a step that raises the score is halved up to this
  // many times, and the descent has arrived when none lowers it; where the model is too narrow
  // for a pyramid, a ±fine_search_px stage follows the wide one. −1: steps are not checked.
  int max_step_halvings = -1;
  // A step turning further is shortened to this (a trust region; see the file comment).
  double max_step_rotation_rad = deg2rad(5.0);
  double tukey_c = 4.685;             // × robust σ (MAD), σ ≥ 0.5 px of the level
  double roi_margin_px = 40;          // around the projected model (plus 10 % of its size)
  double mask_guard_px = 3;           // occluders and background edges widened by this, per level
  double correlation_length_px = 12;  // covariance inflation (see the file comment)
  double shape_tolerance_m = 0.002;   // model vs real panel, per mesh edge: the prior σ₀ (covariance)
  double shape_prior_edges = 4;       // ν₀: σ₀'s weight, in mesh edges, against the offsets measured
  double edge_bias_px = 0.1;          // edge-localisation bias per mesh edge, all views (covariance)
  double outline_dilation_px = 0.10;  // the same, common to the whole outline in all views (covariance)
  // The outline's width left free: an offset common to the samples of the model's long edges along
  // their normals (the outline found wider or narrower than the model's, px) is estimated with the
  // pose and eliminated from its normal equations, the score taken about it. The pose then rests
  // on where the long edges lie, not on how far apart: a rounded radome's shading near its outline,
  // or a background of its own brightness, narrows the outline found by pixels alike in every
  // photo, which a narrow panel seen face-on can fit only by turning. The ends keep their own
  // shading and are not offset. The covariance loses the width's information (and the part of its
  // dilation the offset absorbs).
  bool free_outline_width = false;
  // The model's box (width, depth, height along x_a, y_a, z_a, centred at the antenna frame's
  // origin); outline points more than box_tolerance_m outside it (brackets and mounting parts on
  // the back plate) are not measured: in a photo their outline runs into the arms and clamps that
  // hold them, which the model lacks, and at the back plate's lever arm that bias turns the yaw.
  // They still hide what lies behind them. Zero: every outline point is measured.
  Vec3 outline_box_m = Vec3::Zero();
  double box_tolerance_m = 0.002;
  // The model's four long edges (along z_a), by long_edge_of's index: outline points on one set
  // false are not measured, as if it had no outline (long_edge_check.hpp leaves each out in turn).
  std::array<bool, 4> long_edges{true, true, true, true};
  std::array<bool, 6> free{true, true, true, true, true, true};  // rotation δ x, y, z (board), translation x, y, z
  // Rivals: descents from the solution turned by these angles about the long axis (file comment).
  std::vector<double> rival_yaw_offsets_rad{deg2rad(-30.0), deg2rad(30.0)};  // empty: none
  double score_cutoff_px = 2.0;  // truncation of the score's squared distance (full resolution)
  double rival_margin = 0.02;    // a distinct rival within this score of the best: ambiguous
  // Acceptance: otherwise converged = false with a warning.
  double min_inlier_fraction = 0.5;                // contour samples that found an edge with weight > 0
  double max_outside_fraction = 0.05;              // contour samples outside the crops (ROI or photo)
  double max_rms_px = 2.5;                         // at full resolution
  double max_rotation_change_rad = deg2rad(15.0);  // 15° from the start: beyond, a different local minimum
  int min_views = 2;
  OptionProblems Check() const;
};

/// A Gaussian prior on the rotation from another measurement (e.g. the long axis from the 3-D
/// points): the residual is log(R_board_antenna · R⁻¹) (board frame, rad), `information` its
/// inverse covariance (rad⁻², board frame; singular where the prior says nothing, e.g. about the
/// long axis). It enters the Gauss–Newton steps and the covariance as one more measurement,
/// weighted against the edges by their residual variance × the correlation inflation.
struct RotationPrior {
  Mat3 R_board_antenna = Mat3::Identity();
  Mat3 information = Mat3::Zero();
};

/// The outline covariance's independent parts (file comment), each the sandwich H⁻¹ M_part H⁻¹ of
/// one term of M: they sum to SilhouetteResult::covariance.
struct OutlineCovarianceParts {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Mat6 noise = Mat6::Zero();      // white edge noise, inflated for the samples' overlap (and a prior's own)
  Mat6 shape = Mat6::Zero();      // the model's shape tolerance, common to each mesh edge's samples
  Mat6 edge_bias = Mat6::Zero();  // edge-localisation bias, common to each mesh edge's samples
  Mat6 dilation = Mat6::Zero();   // the whole outline found wider or narrower than the model's
};

struct SilhouetteResult {
  Iso3 T_board_antenna = Iso3::Identity();  // refined; p_board = T p_antenna
  /// (rotation vector δ in the board frame, R_true = exp(δ) R_est; translation, m).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  OutlineCovarianceParts covariance_parts;  // covariance split by its sources
  /// The σ of the turn about the model's z axis (a panel's long axis) that covariance owes to
  /// SilhouetteOptions::outline_dilation_px alone (rad): large where the outline's width barely
  /// changes with yaw (a narrow panel seen face-on), which wider-spread views cure.
  double dilation_yaw_sigma_rad = 0;
  /// The model's shape error per mesh edge that covariance holds (σ_shape, m; file comment), and
  /// the mesh edges whose offsets from the outline measured it.
  double shape_sigma_m = 0;
  std::size_t shape_edges = 0;
  double rms_px = 0;  // weighted edge-distance RMS of the samples used, full resolution
  double inlier_fraction = 0;
  double score = 1;  // mean truncated cost of the outline, 0 (perfect) .. 1 (no edge found)
  /// The same over the whole outline, attachments outside SilhouetteOptions::outline_box_m
  /// included: too biased to place the model, but they tell its back from its front.
  double score_with_attachments = 1;
  double rival_score = 1, rival_rotation_rad = 0;  // best distinct rival minimum, if any
  std::size_t views_used = 0, samples = 0;
  int iterations = 0;  // Gauss–Newton steps over all descents (start and rivals)
  bool converged = false;
  /// Set when the descent left the start's basin (turned more than max_rotation_change_rad from
  /// it, or a rival that far away scored better): the pose it reached, the better rival's if
  /// any. Then not converged; a multi-start search may descend again from there.
  std::optional<Iso3> left_start;
  /// Set when the descent passed every check but stopped at the iteration limit
  /// (max_iterations_per_level) still moving: not converged, and a search may continue it from
  /// T_board_antenna.
  bool stopped_at_iteration_limit = false;
  /// Some search line behind the outline reached the model's projection's middle (where
  /// SilhouetteOptions::line_ends_at_middle ends it), in any evaluation. Where none did, the
  /// descent and this result are the same with line_ends_at_middle on or off.
  bool search_reached_middle = false;
  std::vector<std::string> warnings;
};

/// Refines T_board_antenna_initial (see the file comment). Views whose crop is empty or whose
/// model projection falls behind the camera are skipped with a warning. std::invalid_argument
/// for a mesh without triangles or an image that is not CV_8UC1 of the intrinsics' size.
SilhouetteResult refine_by_silhouette(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna_initial,
                                      const std::vector<SilhouetteView>& views,
                                      const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options,
                                      const std::optional<RotationPrior>& prior = std::nullopt);

/// The same from one start with each of `runs`, options that differ only in their search
/// (levels, ranges, iterations, rivals): the photos are cropped and their gradient pyramids made
/// once, to the coarsest level any run allows. std::invalid_argument also where the runs would
/// prepare the photos differently (roi_margin_px, gamma, smoothing_sigma_px, mask_guard_px,
/// min_coarse_width_px).
std::vector<SilhouetteResult> refine_by_silhouette_runs(const model::Mesh& mesh_antenna,
                                                        const Iso3& T_board_antenna_initial,
                                                        const std::vector<SilhouetteView>& views,
                                                        const camera::CameraIntrinsics& intrinsics,
                                                        const std::vector<SilhouetteOptions>& runs,
                                                        const std::optional<RotationPrior>& prior = std::nullopt);

/// The outline's fit at one pose, photo by photo, without a descent: what the registration's
/// selection compares between poses (registration/pose_evidence.hpp). Costs as
/// SilhouetteResult::score (the mean truncated edge cost, 0 .. 1) over each photo's samples at
/// full resolution with the fine search; NaN where a photo shows none of that outline (hidden,
/// out of view), of the box's outline (options.outline_box_m). A sample that finds no edge costs
/// as much as one far from its edge; `placement` leaves those out: how well the edges a pose
/// meets lie on its outline, whatever the share of its outline that is too faint to be seen.
struct OutlineEvaluation {
  std::vector<double> cost;          // per view
  std::vector<double> placement;     // per view: the mean cost of the samples that found an edge; NaN: none did
  std::vector<std::size_t> samples;  // per view: its samples (measured or not)
  double score = 1;                  // over all views, as SilhouetteResult's
};

OutlineEvaluation evaluate_outline(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                   const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                                   const SilhouetteOptions& options);

/// The long edge of a panel (SilhouetteOptions::long_edges) that the mesh edge from `a_antenna` to
/// `b_antenna` lies on: where it runs along z_a, the quadrant of its middle, (x_a > 0) + 2 (y_a > 0);
/// else none. A convex panel's outline runs along its long sides only on these four edges (a
/// rounded one's on the rounding's facets), whatever the view.
std::optional<int> long_edge_of(const Vec3& a_antenna, const Vec3& b_antenna);

/// evaluate_outline at each of `poses`, which lie close together (a line search's): the photos are
/// prepared once, cropped around all of them.
std::vector<OutlineEvaluation> evaluate_outlines(const model::Mesh& mesh_antenna, const std::vector<Iso3>& poses,
                                                 const std::vector<SilhouetteView>& views,
                                                 const camera::CameraIntrinsics& intrinsics,
                                                 const SilhouetteOptions& options);

}  // namespace antpose::registration
