// Choosing an antenna's pose among candidates judged by the same evidence (pose_evidence.hpp).
//
// Shape first: the candidate with the lowest score wins; every other candidate whose boresight is
// more than `rival_min_deg` from the winner's or from the winner's reversed (turned round about its
// long axis, a box lies where it lay: front and back are decided apart, below) and that the winner
// does not beat decisively is a rival — the photos and points do not tell the two apart, and the
// answer must say so (a σ that covers both, or a refusal). A nearer candidate the winner does not
// beat decisively (another local minimum a few degrees off) is the same answer, but the σ must
// cover it too: a near rival. So is a nearer candidate whose outline lies better on the edges it
// meets than the winner's, by more than that comparison's standard error (pose_evidence.hpp: where
// part of the true outline is too faint to be seen, a pose laying its outline on a crease meets
// more edges and scores lower in every photo alike). A candidate further off is also a rival,
// however decisively the winner beats it at the nominal weight, where it ranks first with the
// points weighed against the outline at either end of the range that weight is known within
// (EvidenceOptions::points_weight_range): the crease error above, or a mount's points taken for the
// panel's, is common to every unit of one half and escapes the comparison's noise, so where the two
// halves point to different poses, the winner must stay first at every weight. Where each half
// decides, against the other (the candidate's outline decisively better, the winner first by its
// points), one half is of something else and no weight makes that noise: a rival too. The noise
// test stays at the nominal weight: at the ends of the range one half's scatter swamps the
// other's, and a margin that is real would read as noise there. A crease twin of the winner
// (yaw_turns.hpp: turned by atan(depth / width), where a faint side face lets a box lay its
// outline on the crease) is that crease error at its full size, often beyond rival_min_deg: it is
// a rival wherever its placement leans to it as a near candidate's would.
// Then front and back, which the box's outline cannot tell: the winner against its twin turned
// by 180° about its long axis. A known mast decides first where it stands clearly behind one of
// them (a panel's back plate faces its mount); otherwise the side units (the vertical structure
// on either side, the mount's points) decide where one side is decisively better; otherwise front
// and back stay open.
// A known mast also speaks to the shape, though it never decides it. A panel's back faces what it
// hangs on: on a sector mount its arms run along its boresight, on a frame it hangs beside its
// neighbours, the mast behind the frame up to about atan(offset / stand-off) off its back. A box
// whose width and depth are alike shows nearly the same outline turned a quarter about its long
// axis, and where the photos favour the turn that puts a side face to the mast, the two
// disagree: the best candidate facing the mast (within `mast_side_on_deg`) is then a rival
// however the scores compare, and the answer is ambiguous rather than confidently side-on. That
// candidate may be one whose outline is too faint to be the answer itself (faint_outline): where
// the side-on pose fits its outline only faintly too, the photos cannot outweigh the mast.
// No prior on the sign of the downtilt: panels with uptilt exist.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/reconstruction/mast.hpp"
#include "antpose/registration/pose_evidence.hpp"
#include "antpose/registration/shape_fit.hpp"

namespace antpose::registration {

/// The strategy that proposed a candidate (register_antenna.hpp). The refinement keeps a pose the
/// points placed where they placed it (kPointsHeld), also in a later registration.
enum class Strategy {
  kGiven,            // passed in by the caller
  kOutlineSearch,    // outline_search.hpp
  kPointsStart,      // global_start.hpp
  kPointsHeld,       // a points' start kept where the points place it, its outline not descended
  kTurned,           // yaw_turns.hpp
  kTurnedAndPlaced,  // a turned start placed again by the outline
  kSlid,             // axis_slide.hpp
  kFacingMast,       // yaw_turns.hpp's facing_turn: turned about its long axis to face a known mast
  kCreaseTwin,       // yaw_turns.hpp's crease_twins of the best, placed by the outline at that turn
};
std::string to_string(Strategy strategy);  // as reports name it, e.g. "outline search"

/// One pose of the model with what the evidence says of it.
struct PoseCandidate {
  Iso3 T_board_antenna = Iso3::Identity();
  Strategy strategy = Strategy::kGiven;
  PoseEvidence evidence;
  double score = 1.0;  // evidence.score
  /// The panel's shape profiled at this pose (shape_fit.hpp), where it was: a later
  /// registration of the same antenna starts from that model and keeps the profile.
  std::shared_ptr<const ShapeFit> panel_shape;
  /// Its outline meets the photos' edges too faintly to be the answer (register_antenna.hpp); it
  /// is weighed only as the mast's rival (file comment).
  bool faint_outline = false;
};

/// The selection's order: candidates that may be the answer first (not faint_outline), then by score.
bool ranks_before(const PoseCandidate& a, const PoseCandidate& b);

struct SelectionOptions {
  double rival_min_deg = 10.0;  // boresights closer than this are the same answer
  /// The mast decides front and back where the boresight of one of the two lies within this of
  /// the direction from the mast to the panel (the other then faces the mast).
  double mast_max_angle_deg = 60.0;
  /// A pose whose boresight, either way, lies further than this from the direction between a known
  /// mast and the panel turns a side face to the mast (file comment). Above the largest angle a
  /// frame puts between a panel's back and its mast.
  double mast_side_on_deg = 70.0;
  OptionProblems Check() const;
};

enum class FrontBackCue { kNone, kMast, kEvidence };
std::string to_string(FrontBackCue cue);  // "none", "mast", "evidence"

struct Selection {
  std::size_t best = 0;                  // index into the candidates; its twin turned round is not among them
  bool turned = false;                   // the best's twin won front and back: use it turned round
  std::vector<std::size_t> rivals;       // shape rivals, best first
  std::vector<std::size_t> near_rivals;  // within rival_min_deg, not ruled out (file comment), best first
  std::optional<Comparison> runner_up;   // the best against the best distinct other candidate
  /// Where the best turns a side face to the known mast: the best candidate that does not (also
  /// among the rivals), and the best against it.
  std::optional<std::size_t> mast_rival;
  Comparison versus_mast_rival;
  FrontBackCue front_back_cue = FrontBackCue::kNone;
  Comparison front_back;         // the chosen side against the other (side units)
  bool front_back_open = false;  // no cue decided
};

/// `candidates` non-empty; `twins[i]` is candidate i's evidence turned round (same order).
/// std::invalid_argument for empty or mismatched inputs.
Selection select_pose(const std::vector<PoseCandidate>& candidates, const std::vector<PoseEvidence>& twins,
                      const std::optional<reconstruction::Mast>& mast, const EvidenceOptions& evidence,
                      const SelectionOptions& options);

/// R_board_antenna turned by 180° about the antenna's own long axis: front and back swapped, the
/// box's outline the same.
Mat3 turned_round(const Mat3& R_board_antenna);
Iso3 turned_round(const Iso3& T_board_antenna);

/// R_board_antenna with its long axis z_a upward (against `up_board`): where it points down, turned
/// by 180° about its boresight y_a. A box is symmetric under that half turn, so its outline and
/// points cannot tell a panel's top end cap from its bottom one; panels hang top end up (z_a runs
/// towards the top end cap: ../shared/notes/antenna-model.md).
Mat3 upright(const Mat3& R_board_antenna, const Vec3& up_board);
Iso3 upright(const Iso3& T_board_antenna, const Vec3& up_board);

/// The angle between the pose's boresight (y_a), either way, and the direction from the mast's axis
/// to the panel's centre, both across the mast's axis: rad, in [0, π/2]. nullopt where the centre
/// lies within the mast or the boresight runs along it.
std::optional<double> mast_bearing(const reconstruction::Mast& mast, const Iso3& T_board_antenna);

/// Whether the pose turns a side face to the mast: its mast_bearing beyond mast_side_on_deg.
bool side_on_to_mast(const reconstruction::Mast& mast, const Iso3& T_board_antenna, const SelectionOptions& options);

/// The angle between two poses' boresights (y_a), rad.
double boresight_angle(const Mat3& R_board_a, const Mat3& R_board_b);

/// The angle between two box orientations, rad, the box's own half-turn about its long axis
/// allowed (turned_round: the same outline).
double box_angle(const Mat3& R_board_a, const Mat3& R_board_b);

}  // namespace antpose::registration
