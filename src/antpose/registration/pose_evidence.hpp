// What the photos and the region's points say of one pose of an antenna model, unit by unit, and
// the comparison of two poses with the noise of that comparison measured from the units' own
// scatter: the registration's one score (docs/non-contact.md, *The score*).
//
// Shape units (which pose of the box): each photo v, the box's outline cost there o_v (the mean
// truncated edge cost of silhouette.hpp, 0 .. 1), and each of `point_slices` slices of the
// region's points along the vertical, the mean truncated cost p_b = min(d, τ)²/τ² of its points'
// distances d to the model's surface (τ = point_truncation_m; a point the pose does not explain
// costs 1). The score is
//   S = mean_v o_v + points_weight · mean_b p_b,
// a negative log-likelihood up to scale in which each photo and each slice counts once: errors
// are correlated within a unit (one photo's blur, background and JPEG blocks; one stereo window's
// depth error) and roughly independent between units.
//
// Side units (front or back, which the box's outline cannot tell, and which no prior on the
// downtilt's sign may decide: panels with uptilt exist). A panel hangs from a mast, pipe or frame
// behind it by arms and clamps on its back plate, and its radome faces open space:
//  - each photo: the outline cost of the best-fitting vertical cylinder behind the panel
//    (reconstruction/mast_search.hpp), set by the caller for the best candidate and its twin;
//  - each slice: the share of its points that lie before the panel's front face, beyond the
//    face's depth noise, within its footprint, unexplained by the model.
// The brackets' own outline is not used: a datasheet model's brackets stand where the maker's
// may not, and their predicted contours mislead where the photos show the back.
//
// Two poses are compared by their units' paired differences d_k = u_k(B) − u_k(A): the score
// difference D and its standard error from the differences' scatter within each stratum
// (photos, slices), as a stratified paired test (Cochran, Sampling Techniques, 3rd ed., §5.3).
// A is decisively better than B where D > decisive_z · SE and D > min_difference; else B is its
// rival. The units' scatter includes every error common to a unit that a pixel-noise likelihood
// would miss (a model unlike the real panel, clutter, partial occlusion), so a difference the
// photos do not agree on is never taken for evidence.
//
// One error is common to every photo and escapes that scatter: a face about as bright as what
// lies behind it (a sunlit side face or end cap against a bright sky, a shaded one against dark
// trees) leaves that stretch of the true outline without an edge, and a pose a few degrees off
// that lays its outline on the crease between that face and the next meets an edge at every
// sample. Its outline then costs less in every photo alike although the edges it meets lie
// worse on it. So the outline's cost is also kept without the samples that found no edge (the
// placement), and a pose whose placement is better than the winner's is not ruled out by the
// winner's lower score (pose_selection.hpp).
#pragma once

#include <cstddef>
#include <vector>

#include "antpose/camera/camera_model.hpp"
#include "antpose/core/check.hpp"
#include "antpose/geometry/point_cloud.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/registration/kdtree.hpp"
#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

struct EvidenceOptions {
  SilhouetteOptions outline;  // its outline_box_m is set to the model's box
  std::size_t point_slices = 6;
  double point_truncation_m = 0.03;
  double points_weight = 1.0;
  // The points' weight against the outline is known only within this factor either way: each
  // half's errors common to all its units (a crease taken for a faint outline, a mount's points
  // taken for the panel's) escape the units' scatter. A candidate that ranks first at either end of
  // that range stays a rival (pose_selection.hpp).
  double points_weight_range = 4.0;
  double model_spacing_m = 0.01;  // the model's surface samples
  // The mount's slabs before and behind the panel (antenna frame): from a gap beyond the face
  // (on the cameras' side at least mount_noise_sigmas of the face's depth noise) to mount_depth_m,
  // within mount_margin_m of its footprint across.
  double mount_gap_m = 0.03, mount_depth_m = 0.6, mount_margin_m = 0.1, mount_noise_sigmas = 3.0;
  double side_mount_weight = 1.0;          // the mount's slices in the side score
  double side_mount_outline_weight = 1.0;  // the vertical structure's photos
  double decisive_z = 2.5;
  double min_difference = 0.01;
  // Whether the photos' outline errors are common to them all, as where no shape of the panel
  // explains where its edges lie (shape_fit.hpp, unbracketed): the photos then count as one unit,
  // their mean difference weighed against their scatter, not against that mean's standard error.
  bool outline_errors_common = false;
  OptionProblems Check() const;
};

/// Per unit; NaN where a unit says nothing (a photo that shows none of the outline, an empty slice).
struct PoseEvidence {
  std::vector<double> outline;        // per photo
  std::vector<double> placement;      // per photo: the outline's cost over the samples that found an edge
  std::vector<double> points;         // per slice
  std::vector<double> mount;          // per slice
  std::vector<double> mount_outline;  // per photo: the best vertical cylinder's outline cost behind the pose
  double score(const EvidenceOptions& options) const;       // S of the file comment
  double side_score(const EvidenceOptions& options) const;  // the side units' mean, as S
};

struct Comparison {
  double difference = 0.0;  // score(other) − score(better): positive where `better` is
  double standard_error = 0.0;
  std::size_t units = 0;  // paired units that entered
  bool decisive = false;
};

/// The comparisons of the file comment: of the shape units, of the outline's placement alone (the
/// photos), and of the side units.
Comparison compare_shape(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& options);
Comparison compare_placement(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& options);
Comparison compare_side(const PoseEvidence& better, const PoseEvidence& other, const EvidenceOptions& options);

/// The scene a model's poses are judged in: the photos (with known objects as occluders and
/// background edges), the region's points and where the cameras were (board frame).
struct EvidenceScene {
  const std::vector<SilhouetteView>* views = nullptr;
  camera::CameraIntrinsics intrinsics;
  const PointCloud* points_board = nullptr;
  std::vector<Vec3> viewpoints_board;
  Vec3 up_board = Vec3::UnitZ();
};

/// Evaluates poses of one model in one scene (the model's surface samples and the points' slices
/// prepared once).
class EvidenceJudge {
 public:
  /// std::invalid_argument for a scene without views or points, or bad options.
  EvidenceJudge(const model::AntennaModel& model, const EvidenceScene& scene, const EvidenceOptions& options);
  PoseEvidence operator()(const Iso3& T_board_antenna) const;
  const EvidenceOptions& options() const { return options_; }
  const model::AntennaModel& model() const { return model_; }

 private:
  void judge_points(const Iso3& T_board_antenna, PoseEvidence& out) const;
  const model::AntennaModel& model_;
  const EvidenceScene& scene_;
  EvidenceOptions options_;
  KdTree surface_;                  // the model's samples, antenna frame
  std::vector<std::size_t> slice_;  // per point
  std::vector<std::size_t> slice_size_;
};

}  // namespace antpose::registration
