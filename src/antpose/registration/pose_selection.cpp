#include "antpose/registration/pose_selection.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace antpose::registration {
namespace {

// The direction from the mast's axis to the panel's centre and the pose's boresight, both across
// the axis and of unit length; nullopt where the centre lies within the mast or the boresight runs
// along it.
std::optional<std::pair<Vec3, Vec3>> across_mast(const reconstruction::Mast& mast, const Iso3& T_board_antenna) {
  const Vec3 axis = mast.up_board.normalized();
  const auto across = [&](const Vec3& v) -> Vec3 { return v - v.dot(axis) * axis; };
  const Vec3 away = across(T_board_antenna.translation() - mast.axis_point_board);
  const Vec3 boresight = across(T_board_antenna.linear().col(1));
  if (away.norm() <= mast.radius_m || boresight.norm() < 1e-9) return std::nullopt;
  return std::pair{away.normalized(), boresight.normalized()};
}

// Whether a mast stands clearly behind the pose: its boresight, across the mast's axis, within
// `max_angle` of the direction from the axis to the panel's centre. nullopt where the mast cannot
// tell (the panel beside it or on it, or side-on to it).
std::optional<bool> faces_away_from(const reconstruction::Mast& mast, const Iso3& T_board_antenna, double max_angle) {
  const auto directions = across_mast(mast, T_board_antenna);
  if (!directions) return std::nullopt;
  const double cosine = directions->first.dot(directions->second);
  if (cosine >= std::cos(max_angle)) return true;
  if (cosine <= -std::cos(max_angle)) return false;
  return std::nullopt;
}

// Where the best candidate turns a side face to the mast, the best other candidate that does not
// and whose box lies further than rival_min_deg from the best's: the mast and the photos disagree
// (pose_selection.hpp).
std::optional<std::size_t> mast_rival(const std::vector<PoseCandidate>& candidates,
                                      const std::vector<std::size_t>& order, const reconstruction::Mast& mast,
                                      const SelectionOptions& options) {
  const Iso3& best = candidates[order.front()].T_board_antenna;
  if (!side_on_to_mast(mast, best, options)) return std::nullopt;
  for (std::size_t k = 1; k < order.size(); ++k) {
    const Iso3& T = candidates[order[k]].T_board_antenna;
    if (box_angle(T.linear(), best.linear()) > deg2rad(options.rival_min_deg) && mast_bearing(mast, T) &&
        !side_on_to_mast(mast, T, options))
      return order[k];
  }
  return std::nullopt;
}

// Whether the outline of `other` lies better on the edges it meets than that of `best` by more than
// the comparison's own standard error: the placement then speaks against a lower score that owes
// to edges `best` meets and `other` does not (pose_evidence.hpp).
bool placement_leans_to(const PoseEvidence& other, const PoseEvidence& best, const EvidenceOptions& evidence) {
  const Comparison c = compare_placement(best, other, evidence);
  return c.units > 1 && c.difference < -c.standard_error;
}

// Whether `best` still ranks above `other`, by more than min_difference, with the points weighed
// against the outline at each end of the range the score's weight is known within
// (EvidenceOptions::points_weight_range). The weight is a systematic unknown, not noise: the
// units' scatter at the nominal weight decides whether a margin is real, and the ends of the range
// only whether the ranking holds.
bool ranks_first_at_every_weight(const PoseEvidence& best, const PoseEvidence& other, const EvidenceOptions& evidence) {
  for (const double factor : {evidence.points_weight_range, 1.0 / evidence.points_weight_range}) {
    EvidenceOptions weighed = evidence;
    weighed.points_weight *= factor;
    if (compare_shape(best, other, weighed).difference <= evidence.min_difference) return false;
  }
  return true;
}

// Whether `other`'s outline is decisively better than `best`'s, which then won by its points: the
// two halves each decide, against each other. One of them is of something else (a mount's points
// taken for the panel's, a crease taken for a faint outline), and no weight within any range
// makes that noise: the photos do not say which.
bool outline_decides_against(const PoseEvidence& best, const PoseEvidence& other, const EvidenceOptions& evidence) {
  EvidenceOptions outline_only = evidence;
  outline_only.points_weight = 0.0;
  return compare_shape(other, best, outline_only).decisive;
}

}  // namespace

std::string to_string(Strategy strategy) {
  switch (strategy) {
    case Strategy::kOutlineSearch:
      return "outline search";
    case Strategy::kPointsStart:
      return "points' global start";
    case Strategy::kPointsHeld:
      return "as the points place it";
    case Strategy::kTurned:
      return "turned about its long axis";
    case Strategy::kTurnedAndPlaced:
      return "turned and placed by the outline";
    case Strategy::kSlid:
      return "slid along its long axis";
    case Strategy::kFacingMast:
      return "turned to face the mast";
    case Strategy::kCreaseTwin:
      return "crease twin of the best";
    case Strategy::kGiven:
      break;
  }
  return "given";
}

std::string to_string(FrontBackCue cue) {
  switch (cue) {
    case FrontBackCue::kMast:
      return "mast";
    case FrontBackCue::kEvidence:
      return "evidence";
    case FrontBackCue::kNone:
      break;
  }
  return "none";
}

Mat3 turned_round(const Mat3& R_board_antenna) { return R_board_antenna * Vec3(-1.0, -1.0, 1.0).asDiagonal(); }

Iso3 turned_round(const Iso3& T_board_antenna) {
  Iso3 T = T_board_antenna;
  T.linear() = turned_round(T_board_antenna.linear());
  return T;
}

Mat3 upright(const Mat3& R_board_antenna, const Vec3& up_board) {
  if (R_board_antenna.col(2).dot(up_board) >= 0.0) return R_board_antenna;
  return R_board_antenna * Vec3(-1.0, 1.0, -1.0).asDiagonal();
}

Iso3 upright(const Iso3& T_board_antenna, const Vec3& up_board) {
  Iso3 T = T_board_antenna;
  T.linear() = upright(T_board_antenna.linear(), up_board);
  return T;
}

bool ranks_before(const PoseCandidate& a, const PoseCandidate& b) {
  return a.faint_outline != b.faint_outline ? b.faint_outline : a.score < b.score;
}

std::optional<double> mast_bearing(const reconstruction::Mast& mast, const Iso3& T_board_antenna) {
  const auto directions = across_mast(mast, T_board_antenna);
  if (!directions) return std::nullopt;
  return std::acos(std::min(1.0, std::abs(directions->first.dot(directions->second))));
}

bool side_on_to_mast(const reconstruction::Mast& mast, const Iso3& T_board_antenna, const SelectionOptions& options) {
  const auto bearing = mast_bearing(mast, T_board_antenna);
  return bearing && *bearing > deg2rad(options.mast_side_on_deg);
}

double boresight_angle(const Mat3& a, const Mat3& b) { return angle_between(a.col(1), b.col(1)); }

double box_angle(const Mat3& a, const Mat3& b) {
  return std::min(rotation_distance(a, b), rotation_distance(a, turned_round(b)));
}

OptionProblems SelectionOptions::Check() const {
  OptionProblems p;
  p.require(rival_min_deg > 0 && rival_min_deg < 90, "rival_min_deg", "in (0, 90)");
  p.require(mast_max_angle_deg > 0 && mast_max_angle_deg <= mast_side_on_deg && mast_side_on_deg < 90,
            "mast_max_angle_deg, mast_side_on_deg", "0 < mast_max_angle_deg ≤ mast_side_on_deg < 90");
  return p;
}

Selection select_pose(const std::vector<PoseCandidate>& candidates, const std::vector<PoseEvidence>& twins,
                      const std::optional<reconstruction::Mast>& mast, const EvidenceOptions& evidence,
                      const SelectionOptions& options) {
  throw_unless_ok(options.Check(), "SelectionOptions");
  if (candidates.empty() || twins.size() != candidates.size())
    throw std::invalid_argument("select_pose: no candidates, or not one twin each");
  Selection s;
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return ranks_before(candidates[a], candidates[b]); });
  s.best = order.front();
  const Mat3& R_best = candidates[s.best].T_board_antenna.linear();
  const double rival_min = deg2rad(options.rival_min_deg);
  for (std::size_t k = 1; k < order.size(); ++k) {
    const auto& c = candidates[order[k]];
    if (c.faint_outline) continue;  // only ever the mast's rival
    // Turned round, a box lies where it lay (box_angle): a boresight a few degrees from the winner's
    // reversed is a pose a few degrees from the winner's, its front and back decided apart.
    const double boresights = boresight_angle(c.T_board_antenna.linear(), R_best);
    const double angle = std::min(boresights, M_PI - boresights);
    const Comparison versus = compare_shape(candidates[s.best].evidence, c.evidence, evidence);
    // The same answer a few degrees off, or another: a boresight elsewhere.
    if (angle <= rival_min) {
      if (!versus.decisive || placement_leans_to(c.evidence, candidates[s.best].evidence, evidence))
        s.near_rivals.push_back(order[k]);
      continue;
    }
    if (!s.runner_up) s.runner_up = versus;
    const bool crease_leans =
        c.strategy == Strategy::kCreaseTwin && placement_leans_to(c.evidence, candidates[s.best].evidence, evidence);
    if (!versus.decisive || crease_leans ||
        !ranks_first_at_every_weight(candidates[s.best].evidence, c.evidence, evidence) ||
        outline_decides_against(candidates[s.best].evidence, c.evidence, evidence))
      s.rivals.push_back(order[k]);
  }
  if (mast)
    if ((s.mast_rival = mast_rival(candidates, order, *mast, options))) {
      s.versus_mast_rival = compare_shape(candidates[s.best].evidence, candidates[*s.mast_rival].evidence, evidence);
      if (std::find(s.rivals.begin(), s.rivals.end(), *s.mast_rival) == s.rivals.end()) {
        s.rivals.push_back(*s.mast_rival);
        std::stable_sort(s.rivals.begin(), s.rivals.end(),
                         [&](std::size_t a, std::size_t b) { return candidates[a].score < candidates[b].score; });
      }
    }
  // Front and back: the mast where it stands clearly behind one of the two, else the side units.
  const Iso3& T = candidates[s.best].T_board_antenna;
  if (mast)
    if (const auto away = faces_away_from(*mast, T, deg2rad(options.mast_max_angle_deg))) {
      s.turned = !*away;
      s.front_back_cue = FrontBackCue::kMast;
    }
  const PoseEvidence& as_is = candidates[s.best].evidence;
  const PoseEvidence& twin = twins[s.best];
  if (s.front_back_cue == FrontBackCue::kNone) {
    s.turned = twin.side_score(evidence) < as_is.side_score(evidence);
    s.front_back = s.turned ? compare_side(twin, as_is, evidence) : compare_side(as_is, twin, evidence);
    if (s.front_back.decisive)
      s.front_back_cue = FrontBackCue::kEvidence;
    else
      s.front_back_open = true;
  } else {
    s.front_back = s.turned ? compare_side(twin, as_is, evidence) : compare_side(as_is, twin, evidence);
  }
  return s;
}

}  // namespace antpose::registration
