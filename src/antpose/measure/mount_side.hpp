// Which side of a registered panel its mount is on: front and back where the outline cannot tell.
//
// A box's outline is the same turned by 180° about its long axis, and seen face-on the brackets
// on the back plate hide behind the panel; the points' visibility test then has little to go on
// (docs/non-contact.md). But a panel hangs by brackets and clamps on its back plate from a mast
// or a wall, and its radome faces open space: the region around it holds the mount, behind it.
// Counted are the region's points that the registered model does not explain (farther than
// `reach_m` from it), inside the panel's outline across (plus `lateral_margin_m`) and along it,
// between `gap_m` and `depth_m` beyond its back face or its front face.
//
// The face the cameras see most has depth noise of its own, which scatters its points towards the
// cameras as much as into the panel: from the ground (20–30 m) σ 2–3 cm along the boresight. Seen
// from the front that scatter lies before the panel; seen from the back, or registered turned round,
// it lies where the mount should be, and at `gap_m` it was 116 "mount" points behind a thesis panel
// registered turned round (5606-1, 21 m, face-on; mast and clamps hidden behind it). So on the
// cameras' side the points are counted only beyond `noise_sigmas` times that noise too, measured
// from the points' spread into the panel behind the seen face (where no mount lies).
//
// Verdict: at least `min_points` behind and `ratio` times as many as before: as registered; the
// other way round, with at least `min_points_to_turn` before: turned (the front is the back).
// Else undecided. On the acceptance sites 701–712 the right poses had 3.6–∞ times more behind
// than before them (the fewest from the ground, where the radome's points scatter in depth), the
// one wrong front/back (706-3) 9.5 times more before.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "antpose/geometry/point_cloud.hpp"
#include "antpose/registration/kdtree.hpp"

namespace antpose::measure {

struct MountSideOptions {
  double gap_m = 0.03;
  double depth_m = 0.6;  // a mast of 0.25 m radius stands ~0.3 m behind the back plate
  double lateral_margin_m = 0.1;
  std::size_t min_points = 50;
  /// Turning the registered pose round overrules the outline's choice: it takes more. On the
  /// development sites every right turn had 813 points or more behind the turned panel, the two
  /// wrong ones (1004-1, 1211-1, both turning a right pose into an uptilt) 114 and 80.
  std::size_t min_points_to_turn = 300;
  double ratio = 2.0;
  /// On the cameras' side, points count beyond this many σ of the seen face's depth noise. 5606-1
  /// (σ 2.4 cm), 5112-3 (2.2 cm) and 5304-2 (2.6 cm), thesis panels seen face-on from 21–26 m, in
  /// their true frames over the panel's footprint: before their fronts 224, 1800 and 252 points
  /// beyond 3 cm, 0, 164 and 0 beyond 3σ; behind their backs, beyond 3 cm, 8, 464 and 403.
  double noise_sigmas = 3.0;
  std::size_t min_noise_points = 30;  // fewer points behind the seen face: its noise is not known
  /// mast_side_verdict's limit: a panel's boresight this near the direction away from its mast.
  double mast_max_angle_deg = 60.0;
};

struct MountSide {
  std::size_t behind = 0, before = 0;  // points beyond the back face, beyond the front face
  double depth_noise_m = 0.0;          // the seen face's noise (σ along y_a); 0: not measured
};

/// Counts of the file comment. `cloud` in any frame c, `T_antenna_cloud` the registered pose,
/// `model_antenna` a tree over the model's surface samples (antenna frame), `size_m` its box
/// (width along x_a, depth along y_a, height along z_a; the boresight is +y_a), `toward_cameras_c`
/// from the panel towards the cameras (their mean), frame c.
MountSide count_mount_side(const PointCloud& cloud, const Iso3& T_antenna_cloud,
                           const registration::KdTree& model_antenna, const Vec3& size_m, double reach_m,
                           const Vec3& toward_cameras_c, const MountSideOptions& options);

/// The depth noise (σ along y_a, m) of the panel's face at y_a = ±size_m.y/2 on the side of
/// `toward_cameras_antenna`, from the points (antenna frame) in the middle half of its width
/// that lie up to the panel's depth behind it (a half-normal's median is 0.674σ). Nothing where
/// the cameras see a side face more than it (their points' y_a spread is the panel's depth, not
/// noise), or fewer than options.min_noise_points lie there.
std::optional<double> seen_face_depth_noise(const std::vector<Vec3>& points_antenna, const Vec3& size_m,
                                            const Vec3& toward_cameras_antenna, const MountSideOptions& options);

enum class MountVerdict { kUndecided, kAsRegistered, kTurned };

MountVerdict mount_verdict(const MountSide& side, const MountSideOptions& options);

/// The mast the panel hangs on, where one was fitted (reconstruction/mast.hpp), as a cue of its
/// own: a panel's back plate faces its mast. Counted points need not show it: from the ground a
/// thin panel's radome points scatter 2 cm in depth, beyond its front face as much as its back,
/// and a thesis panel face-on before its mast had 2.8 times more before it than behind (3502-1).
/// Across the mast's axis (frame c, `axis_dir_c` unit), the panel's centre lies off the mast by
/// more than its radius; the boresight y_a within `max_angle_rad` of the direction from the axis
/// to the centre: as registered; within it of the opposite: turned. Else (the panel beside or
/// on the mast, or side-on to it) undecided.
MountVerdict mast_side_verdict(const Vec3& axis_point_c, const Vec3& axis_dir_c, double radius_m,
                               const Iso3& T_c_antenna, double max_angle_rad);

/// Front and back from both cues. The mount's verdict where it has one. Else the downtilt's sign
/// (the mast hides behind a panel seen face-on): turned by 180° about its long axis a panel's
/// downtilt changes sign, and mounts tilt panels down (tilt kits 0–15°), not up: as registered
/// when it tilts down and the turn up by more than `max_uptilt_rad`, turned the other way round
/// (`by_downtilt`). Where the mount's choice tilts the panel up by more than that the cues
/// disagree: undecided and `in_doubt` (the other way round stays possible). Downtilts in rad,
/// positive down, of the pose as registered and turned round (boresight_downtilt).
struct FrontBack {
  MountVerdict verdict = MountVerdict::kUndecided;
  bool by_downtilt = false, in_doubt = false;
};
FrontBack decide_front_back(MountVerdict mount, double downtilt_registered, double downtilt_turned,
                            double max_uptilt_rad);

/// The outline's cue (registration/silhouette.hpp), the first one asked: the scores, without and
/// with the attachments' outline, of the pose as registered and of it turned round by 180° about
/// its long axis, each refined to its own minimum. The two have the same box outline, so only the
/// attachments (brackets seen from the side) tell them apart: true where the turned pose scores
/// better by more than `margin` with them counted, and their part of it
/// (score_with_attachments − score) is better by more than `margin` too. A polish of the turned
/// pose may find a better fit of the box itself, which says nothing about which way round the
/// panel is: 4706-1 (a thesis panel 29 m away, no bracket sample in any photo) was turned round by
/// a polish 3.7° away that scored 0.146 against 0.251, and came out 165° off in azimuth with a
/// roll σ of 0.13°. On 11 antennas the brackets turned rightly (sites 502–4711) their part was
/// better by 0.033–0.106; on a 12th, 4611-1, by 0.013 only, and its mount turned it instead.
struct OutlineScores {
  double score = 1, score_with_attachments = 1;
};
bool attachments_turn_round(const OutlineScores& registered, const OutlineScores& turned, double margin);

/// Downtilt (rad, positive down) of the boresight y_a of R_b_antenna, `up_b` the upward vertical.
double boresight_downtilt(const Mat3& R_b_antenna, const Vec3& up_b);

}  // namespace antpose::measure
