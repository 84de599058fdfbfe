#include "antpose/registration/register_antenna.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/model/box_file.hpp"
#include "antpose/model/sampling.hpp"

namespace antpose::registration {
namespace {

struct Refined {
  PoseCandidate candidate;
  SilhouetteResult outline;
  std::shared_ptr<const model::AntennaModel> model;  // refined with: the panel's shape fitted, where it was
  std::optional<ShapeFit> panel_shape;
  // Kept where the points placed it (refine_all), its outline not descended.
  bool held() const { return candidate.strategy == Strategy::kPointsHeld; }
};

// Whether two poses put the box in one place: orientations within `max_deg` of each other, the box's
// half turn about its long axis allowed (box_angle: the same outline), and centres within `max_m`.
bool same_place(const Iso3& T, const Iso3& U, double max_deg, double max_m = std::numeric_limits<double>::infinity()) {
  return rad2deg(box_angle(T.linear(), U.linear())) < max_deg && (T.translation() - U.translation()).norm() < max_m;
}

// Whether one of `kept` stands where T puts the box (same_place).
bool stands_among(const Iso3& T, const std::vector<Refined>& kept, double max_deg,
                  double max_m = std::numeric_limits<double>::infinity()) {
  return std::any_of(kept.begin(), kept.end(),
                     [&](const Refined& k) { return same_place(T, k.candidate.T_board_antenna, max_deg, max_m); });
}

bool fits_better(const Refined& a, const Refined& b) { return a.outline.score < b.outline.score; }

// The candidate whose outline fits best, or end() where there is none.
std::vector<Refined>::iterator best_outline(std::vector<Refined>& kept) {
  return std::min_element(kept.begin(), kept.end(), fits_better);
}

// Where the outline search starts the box's centre besides the rectangle's own fit: the region's
// points' centroid.
std::vector<Vec3> search_starts(const AntennaScene& s) {
  if (s.points_board.empty()) return {};
  return {centroid(s.points_board.points)};
}

OutlineSearchInput outline_input(const model::AntennaModel& model, const AntennaScene& s, const RegisterOptions& o) {
  OutlineSearchInput in;
  in.box_size_m = model.size_m;
  in.views = &s.views;
  in.areas = s.areas;
  in.region_view = s.region_view;
  in.expected_width_px = std::max(8.0, std::min(s.roi.width, s.roi.height) / 1.1);
  in.up_board = s.up_board;
  in.starts_board = search_starts(s);
  in.roi = s.roi;
  in.min_roi_span = o.min_roi_span;
  return in;
}

std::vector<PoseCandidate> from_outline(const model::AntennaModel& model, const AntennaScene& s,
                                        const RegisterOptions& o) {
  std::vector<PoseCandidate> out;
  for (const auto& c : search_box_outline(outline_input(model, s, o), s.intrinsics, o.search).candidates) {
    if (out.size() >= o.refine_candidates) break;
    out.push_back({c.T_board_antenna, Strategy::kOutlineSearch, {}, c.cost, nullptr});
  }
  return out;
}

std::vector<PoseCandidate> from_points(const model::AntennaModel& model, const AntennaScene& s,
                                       const RegisterOptions& o) {
  if (!o.points_start || s.points_board.size() < o.min_points_for_start) return {};
  auto g = o.points;
  g.viewpoints_scene = s.viewpoints_board;
  const auto model_cloud = prepare(model::sample_surface(model.mesh_antenna, o.evidence.model_spacing_m, 1), g.fine);
  const auto cloud = prepare(s.points_board, g.fine);
  const auto start = global_align(cloud, model_cloud, s.up_board, g);
  std::vector<PoseCandidate> out{{start.fit.T_target_source.inverse(), Strategy::kPointsStart, {}, 0.0, nullptr}};
  for (const auto& h : start.hypotheses) {
    if (out.size() >= o.refine_candidates) break;
    const Iso3 T = h.T_model_scene.inverse();
    const bool apart = std::all_of(out.begin(), out.end(), [&](const PoseCandidate& c) {
      return boresight_angle(c.T_board_antenna.linear(), T.linear()) > deg2rad(o.selection.rival_min_deg);
    });
    if (apart) out.push_back({T, Strategy::kPointsStart, {}, h.score(), nullptr});
  }
  return out;
}

// The polish of refine_all: full resolution alone, ±fine_search_px.
SilhouetteOptions polish_of(const SilhouetteOptions& descent) {
  auto polish = descent;
  polish.max_level = 0;
  polish.search_range_px = polish.fine_search_px;
  return polish;
}

// Each proposal descended by its outline (silhouette.hpp) with the model's box as the outline,
// twice: through the pyramid from the coarse levels' wide search, and polished at full resolution
// alone (±fine_search_px), which keeps a narrow panel in its own basin where the coarse levels
// blur its edges into its neighbours'. The points' starts are also kept as they lie
// (RegisterOptions::hold_points_poses), their outline measured there without a descent.
std::vector<Refined> refine_all(const std::shared_ptr<const model::AntennaModel>& shared, const AntennaScene& s,
                                const std::vector<PoseCandidate>& proposals, const RegisterOptions& o) {
  std::vector<Refined> out;
  for (const auto& proposal : proposals) {
    // A proposal whose shape was profiled is refined with that shape's model (shared, not copied).
    const auto with = proposal.panel_shape ? std::shared_ptr<const model::AntennaModel>(proposal.panel_shape,
                                                                                        &proposal.panel_shape->model)
                                           : shared;
    auto descent = o.refine;
    descent.outline_box_m = model::outline_box(*with);
    auto polish = polish_of(descent);
    auto hold = polish;
    hold.max_iterations_per_level = 0;
    // A pose the points placed is kept there, and in a later registration stays there.
    const bool was_held = proposal.strategy == Strategy::kPointsHeld;
    const bool hold_it = o.hold_points_poses && (was_held || proposal.strategy == Strategy::kPointsStart);
    std::vector<SilhouetteOptions> runs;
    if (!(hold_it && was_held)) runs = {descent, polish};
    if (hold_it) runs.push_back(hold);
    // A crease twin stands for its turn (yaw_turns.hpp): its centre is placed at that turn first,
    // then polished whole; a descent through the pyramid would leave it for the crease's basin.
    Iso3 start = proposal.T_board_antenna;
    if (proposal.strategy == Strategy::kCreaseTwin) {
      auto place = polish;
      place.free = {false, false, false, true, true, true};
      start = refine_by_silhouette(with->mesh_antenna, start, s.views, s.intrinsics, place).T_board_antenna;
      runs = {polish};
    }
    auto outlines = refine_by_silhouette_runs(with->mesh_antenna, start, s.views, s.intrinsics, runs);
    for (std::size_t k = 0; k < runs.size(); ++k) {
      Refined& r = out.emplace_back();
      r.outline = std::move(outlines[k]);
      r.candidate = proposal;
      r.candidate.T_board_antenna = r.outline.T_board_antenna;
      if (hold_it && k + 1 == runs.size()) r.candidate.strategy = Strategy::kPointsHeld;
      r.model = with;
      if (proposal.panel_shape) r.panel_shape = *proposal.panel_shape;
    }
  }
  return out;
}

// Whether the box and a neighbour's, each shrunk by `clearance_m` on every face, still meet.
bool passes_through_neighbour(const OrientedBox& box, const std::vector<OrientedBox>& neighbours, double clearance_m) {
  const auto core = shrunk(box, clearance_m);
  return core && std::any_of(neighbours.begin(), neighbours.end(), [&](const OrientedBox& n) {
           const auto other = shrunk(n, clearance_m);
           return other && boxes_overlap(*core, *other);
         });
}

// What distinct_in_rectangle drops that a refusal may have to explain:
//  - the best outline among the candidates centred in the rectangle but spanning too little of it,
//    and its span: where it fits clearly and nothing that spans the rectangle does, the rectangle
//    is drawn too loosely, not the photos unclear;
//  - whether a candidate against the known mast fits its outline at least faintly: where nothing
//    else fits, the outline found is the mast's and its clamps', not the panel's.
struct Dropped {
  double small_score = 1.0, small_span = 0.0;
  bool mast_fits = false;
  void too_small(double outline_score, double rectangle_span) {
    if (outline_score < small_score) small_score = outline_score, small_span = rectangle_span;
  }
};

// The rounding of a parametric panel's long edges; 0 for a mesh model.
double edge_rounding(const model::AntennaModel& model) { return model.panel ? model.panel->edge_radius_m : 0.0; }

// The gap between the panel, its box with the vertical edges rounded by `edge_radius_m`, and the
// mast's surface over the mast's extent; negative where they overlap.
double mast_gap(const OrientedBox& box, double edge_radius_m, const reconstruction::Mast& mast) {
  OrientedBox core = box;
  core.size_m.head<2>().array() -= 2 * std::min(edge_radius_m, box.size_m.head<2>().minCoeff() / 2);
  const Vec3 low = mast.axis_point_board + mast.low_m * mast.up_board;
  const Vec3 high = mast.axis_point_board + mast.high_m * mast.up_board;
  return box_segment_distance(core, low, high) - edge_radius_m - mast.radius_m;
}

// Refined candidates that fit the rectangle, pass through no known neighbour and stand clear of
// the known mast, one per place: of those ending at the same box pose, the one whose outline fits
// best, or the best with a profiled shape where one has it (the shape is the panel's; a descent
// with the model's guessed one is no better evidence of the pose). Best outline first.
std::vector<Refined> distinct_in_rectangle(std::vector<Refined> refined, const model::AntennaModel& model,
                                           const AntennaScene& s, const RegisterOptions& o, Dropped& dropped) {
  std::sort(refined.begin(), refined.end(), fits_better);
  std::vector<Refined> out;
  for (auto& r : refined) {
    const Iso3& T = r.candidate.T_board_antenna;
    const auto fit = roi_span(model.size_m, T, s.views[s.region_view], s.intrinsics, s.roi);
    if (fit.centred && fit.span < o.min_roi_span && r.outline.views_used >= o.min_outline_views)
      dropped.too_small(r.outline.score, fit.span);
    if (fit.span < o.min_roi_span || !fit.centred) continue;
    if (passes_through_neighbour({T, model.size_m}, s.neighbours_board, o.neighbour_clearance_m)) continue;
    if (s.mast && mast_gap({T, model.size_m}, edge_rounding(*r.model), *s.mast) < o.min_mast_gap_m) {
      dropped.mast_fits |= r.outline.views_used >= o.min_outline_views && r.outline.score <= o.max_faint_outline_score;
      continue;
    }
    const auto known = std::find_if(out.begin(), out.end(), [&](const Refined& k) {
      return same_place(T, k.candidate.T_board_antenna, o.same_pose_deg, o.same_pose_m);
    });
    if (known == out.end())
      out.push_back(std::move(r));
    else if (r.panel_shape && !known->panel_shape)
      *known = std::move(r);
  }
  return out;
}

// The best candidates turned about their long axis (yaw_turns.hpp) where no candidate stands yet.
std::vector<PoseCandidate> turned_proposals(const std::vector<Refined>& kept, const AntennaScene& s,
                                            const RegisterOptions& o) {
  std::vector<PoseCandidate> out;
  for (std::size_t i = 0; i < std::min(kept.size(), o.turns.of_best); ++i) {
    for (const Iso3& T : yaw_turns(kept[i].candidate.T_board_antenna, model::outline_box(*kept[i].model),
                                   s.viewpoints_board, o.turns)) {
      const bool known = stands_among(T, kept, o.turns.min_turn_deg) ||
                         std::any_of(out.begin(), out.end(), [&](const PoseCandidate& c) {
                           return same_place(T, c.T_board_antenna, o.turns.min_turn_deg);
                         });
      if (!known) out.push_back({T, Strategy::kTurned, {}, 0.0, nullptr});
    }
  }
  return out;
}

// The best candidate turned to face a known mast (yaw_turns.hpp's facing_turn) where it turns a side
// face to it (pose_selection.hpp) and no candidate stands there yet: the strategy "held axis with
// the mast known". Where the outline favours the quarter turn, the mast's own is otherwise never
// refined, and the selection could not weigh the two.
std::optional<PoseCandidate> facing_mast_proposal(const std::vector<Refined>& kept, const AntennaScene& s,
                                                  const RegisterOptions& o) {
  if (!o.face_mast || !s.mast || kept.empty()) return std::nullopt;
  const Iso3& best = kept.front().candidate.T_board_antenna;
  if (!side_on_to_mast(*s.mast, best, o.selection)) return std::nullopt;
  const auto T = facing_turn(best, best.translation() - s.mast->axis_point_board);
  if (!T || stands_among(*T, kept, o.turns.min_turn_deg)) return std::nullopt;
  return PoseCandidate{*T, Strategy::kFacingMast, {}, 0.0, nullptr};
}

// The turned starts placed again by the outline at their own orientation (outline_search.hpp's
// place_box_outlines): a turn about the candidate's centre keeps a centre that belongs to the
// candidate's orientation, and where the two orientations' basins lie further apart than the
// refinement reaches, the turned orientation's own is never found. Those that land where a kept
// candidate or a turned start already stands add nothing.
std::vector<PoseCandidate> placed_turns(const std::vector<PoseCandidate>& turned, const std::vector<Refined>& kept,
                                        const model::AntennaModel& model, const AntennaScene& s,
                                        const RegisterOptions& o) {
  if (!o.place_turns || turned.empty()) return {};
  std::vector<Iso3> starts, taken;
  for (const auto& t : turned) starts.push_back(t.T_board_antenna);
  for (const auto& k : kept) taken.push_back(k.candidate.T_board_antenna);
  taken.insert(taken.end(), starts.begin(), starts.end());
  std::vector<PoseCandidate> out;
  for (const auto& c : place_box_outlines(outline_input(model, s, o), s.intrinsics, o.search, starts).candidates) {
    const bool known = std::any_of(taken.begin(), taken.end(), [&](const Iso3& U) {
      return same_place(c.T_board_antenna, U, o.same_pose_deg, o.same_pose_m);
    });
    if (c.views < o.search.min_views || known) continue;
    out.push_back({c.T_board_antenna, Strategy::kTurnedAndPlaced, {}, c.cost, nullptr});
    taken.push_back(c.T_board_antenna);
  }
  return out;
}

// The best candidates slid along their long axis (axis_slide.hpp) where their outline scores better.
std::vector<PoseCandidate> slid_proposals(const std::vector<Refined>& kept, const AntennaScene& s,
                                          const RegisterOptions& o) {
  std::vector<PoseCandidate> out;
  for (std::size_t i = 0; i < std::min(kept.size(), o.slide.of_best); ++i) {
    auto outline = o.refine;
    outline.outline_box_m = model::outline_box(*kept[i].model);
    if (const auto T = slide_along_axis(kept[i].model->mesh_antenna, kept[i].candidate.T_board_antenna, s.views,
                                        s.intrinsics, outline, o.slide))
      out.push_back({*T, Strategy::kSlid, {}, 0.0, kept[i].candidate.panel_shape});
  }
  return out;
}

// The proposals refined (refine_all), distinct in the rectangle, and the best turned about its
// long axis (turned_proposals, placed_turns) or slid along it (slid_proposals) and refined too.
std::vector<Refined> refine_and_turn(const std::shared_ptr<const model::AntennaModel>& shared, const AntennaScene& s,
                                     const std::vector<PoseCandidate>& proposals, const RegisterOptions& o,
                                     Dropped& dropped) {
  auto kept = distinct_in_rectangle(refine_all(shared, s, proposals, o), *shared, s, o, dropped);
  auto turned = turned_proposals(kept, s, o);
  if (auto facing = facing_mast_proposal(kept, s, o)) turned.push_back(std::move(*facing));
  const auto placed = placed_turns(turned, kept, *shared, s, o);
  turned.insert(turned.end(), placed.begin(), placed.end());
  const auto slid = slid_proposals(kept, s, o);
  if (turned.empty() && slid.empty()) return kept;
  // A turned start that descends back to a kept candidate's orientation found no other basin; a
  // slid one that descends back to a kept candidate's place found no other.
  auto more = refine_all(shared, s, turned, o);
  auto moved = refine_all(shared, s, slid, o);
  std::erase_if(more,
                [&](const Refined& m) { return stands_among(m.candidate.T_board_antenna, kept, o.same_pose_deg); });
  std::erase_if(moved, [&](const Refined& m) {
    return stands_among(m.candidate.T_board_antenna, kept, o.same_pose_deg, o.same_pose_m);
  });
  kept.insert(kept.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  kept.insert(kept.end(), std::make_move_iterator(moved.begin()), std::make_move_iterator(moved.end()));
  return distinct_in_rectangle(std::move(kept), *shared, s, o, dropped);
}

// The best candidates' shape (edge rounding, end caps) profiled with their poses (shape_fit.hpp),
// and every crease twin's (yaw_turns.hpp: it was placed with the shape that fits the best):
// each then carries its best shape's pose, outline and model. Before any judgement of the outline:
// fitted with the wrong shape, even the right pose may fit its outline poorly. A candidate whose
// shape a previous registration profiled within same_pose of where it now stands keeps that
// profile: the shape is the panel's, and its pose has not moved enough to change what it saw.
// Candidates that profiling brings onto one pose are one: the kept profile, else the better outline.
void fit_shapes(std::vector<Refined>& kept, const AntennaScene& s, const RegisterOptions& o) {
  const auto same = [&](const Iso3& T, const Iso3& U) { return same_place(T, U, o.same_pose_deg, o.same_pose_m); };
  std::vector<std::size_t> profiled;
  for (std::size_t i = 0; i < kept.size(); ++i)
    if (i < o.shape_candidates || kept[i].candidate.strategy == Strategy::kCreaseTwin) profiled.push_back(i);
  std::vector<bool> carried(kept.size(), false);
  for (const std::size_t i : profiled) {
    auto& k = kept[i];
    if (k.held()) continue;
    if (k.panel_shape && same(k.candidate.T_board_antenna, k.panel_shape->outline.T_board_antenna)) {
      k.panel_shape->outline = k.outline;
      carried[i] = true;
      continue;
    }
    auto fit = fit_shape(*k.model, k.candidate.T_board_antenna, s.views, s.intrinsics, polish_of(o.refine), o.evidence,
                         o.panel_shape);
    if (!fit.fitted || fit.outline.score >= k.outline.score) {
      if (k.panel_shape) k.panel_shape->outline = k.outline;
      continue;
    }
    k.outline = fit.outline;
    k.candidate.T_board_antenna = fit.outline.T_board_antenna;
    k.model = std::make_shared<const model::AntennaModel>(fit.model);
    k.panel_shape = std::move(fit);
  }
  std::vector<bool> merged(kept.size(), false);
  for (std::size_t a = 0; a < profiled.size(); ++a)
    for (std::size_t b = a + 1; b < profiled.size(); ++b) {
      const std::size_t i = profiled[a], j = profiled[b];
      if (merged[i] || merged[j] || !same(kept[i].candidate.T_board_antenna, kept[j].candidate.T_board_antenna))
        continue;
      const bool keep_j = carried[j] != carried[i] ? carried[j] : kept[j].outline.score < kept[i].outline.score;
      merged[keep_j ? i : j] = true;
    }
  std::vector<Refined> distinct;
  for (std::size_t i = 0; i < kept.size(); ++i)
    if (!merged[i]) distinct.push_back(std::move(kept[i]));
  kept = std::move(distinct);
}

// The best candidate's crease twins (yaw_turns.hpp) with its model, placed by the outline at their
// own turn (refine_all), where they fit the rectangle and no candidate stands yet; their own shape
// is profiled next (fit_shapes).
void add_crease_twins(std::vector<Refined>& kept, const AntennaScene& s, const RegisterOptions& o, Dropped& dropped) {
  if (!o.crease_twins || kept.empty()) return;
  const auto best_it = best_outline(kept);
  const auto with = best_it->model;
  const Iso3 best = best_it->candidate.T_board_antenna;
  std::vector<PoseCandidate> twins;
  for (const Iso3& T : crease_twins(best, model::outline_box(*with), s.viewpoints_board))
    twins.push_back({T, Strategy::kCreaseTwin, {}, 0.0, nullptr});
  auto placed = refine_all(with, s, twins, o);
  std::erase_if(placed, [&](const Refined& m) {
    return stands_among(m.candidate.T_board_antenna, kept, o.same_pose_deg, o.same_pose_m);
  });
  kept.insert(kept.end(), std::make_move_iterator(placed.begin()), std::make_move_iterator(placed.end()));
  kept = distinct_in_rectangle(std::move(kept), *with, s, o, dropped);
}

// The candidates whose outline meets the photos' edges at least faintly (max_faint_outline_score,
// min_outline_views). No stricter cut by a fixed score: where the edges are faint or cluttered, the
// true pose may fit its outline a little worse than a wrong one that meets a neighbour's or the
// background's edges, and only the comparison of the two with its own noise (pose_selection.hpp)
// may rule it out; a candidate cut here could never be the rival that makes the answer ambiguous.
// For that reason, where the best outline meets its edges at least faintly but turns a side face to
// a known mast, the candidates that face the mast stay however faint their outline, marked to be
// weighed only as the mast's rival (PoseCandidate::faint_outline): they fill the rectangle as the
// best does, and the mast speaks for them (pose_selection.hpp).
void keep_fitting_outlines(std::vector<Refined>& kept, const AntennaScene& s, const RegisterOptions& o) {
  const auto best = best_outline(kept);
  const bool contradicted = s.mast && o.face_mast && best != kept.end() &&
                            best->outline.score <= o.max_faint_outline_score &&
                            side_on_to_mast(*s.mast, best->candidate.T_board_antenna, o.selection);
  const auto facing_mast = [&](const Refined& k) {
    return contradicted && mast_bearing(*s.mast, k.candidate.T_board_antenna) &&
           !side_on_to_mast(*s.mast, k.candidate.T_board_antenna, o.selection);
  };
  std::erase_if(kept, [&](const Refined& k) {
    return k.outline.views_used < o.min_outline_views ||
           (k.outline.score > o.max_faint_outline_score && !facing_mast(k));
  });
  for (auto& k : kept) k.candidate.faint_outline = k.outline.score > o.max_faint_outline_score;
}

// A rival's pose turned the way the result's front and back were decided: by the mast where it
// decided them, else facing within 90° of the result.
Iso3 rival_facing(const Iso3& rival, const Iso3& result) {
  return boresight_angle(rival.linear(), result.linear()) <= M_PI / 2 ? rival : turned_round(rival);
}

// The vertical structure behind and before the candidate (reconstruction/mast_search.hpp) as side
// units of its evidence and its twin's: behind the twin is before the candidate.
void add_mount_outline(PoseEvidence& as_is, PoseEvidence& twin, const Refined& k, const AntennaScene& s,
                       const RegisterOptions& o) {
  std::vector<reconstruction::PosedView> views;
  std::vector<std::vector<std::vector<cv::Point2f>>> occluders;
  for (const auto& v : s.views) {
    reconstruction::PosedView& pv = views.emplace_back();
    pv.image = v.image, pv.R_camera_board = v.R_camera_board, pv.t_camera_board = v.t_camera_board;
    auto& here = occluders.emplace_back(v.occluders);
    std::vector<cv::Point2f> corners, hull;
    for (const Vec3& c : model::box_corners(k.model->size_m))
      if (const auto uv = s.intrinsics.project(v.R_camera_board * (k.candidate.T_board_antenna * c) + v.t_camera_board))
        corners.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
    if (corners.size() == 8) cv::convexHull(corners, hull), here.push_back(hull);
  }
  const auto sides = reconstruction::search_mount_sides(views, s.intrinsics, s.up_board, k.candidate.T_board_antenna,
                                                        k.model->size_m, occluders, o.mount_search);
  if (!sides.behind || !sides.before) return;
  as_is.mount_outline = sides.behind->view_costs;
  twin.mount_outline = sides.before->view_costs;
}

// An outline's rotation covariance by its sources (silhouette.hpp OutlineCovarianceParts); a part
// that is nil (the whole outline's dilation, absorbed where the width is free) is left out.
std::vector<UncertaintySource> outline_sources(const SilhouetteResult& outline) {
  const auto& parts = outline.covariance_parts;
  std::vector<UncertaintySource> out{{"outline noise", parts.noise.topLeftCorner<3, 3>()},
                                     {"model shape tolerance", parts.shape.topLeftCorner<3, 3>()},
                                     {"edge bias", parts.edge_bias.topLeftCorner<3, 3>()}};
  if (!parts.dilation.isZero()) out.push_back({"outline width", parts.dilation.topLeftCorner<3, 3>()});
  return out;
}

// The rotation covariance of a refined candidate by its sources: its outline's parts, and the spread
// of the shapes that fit as well where its shape was profiled (shape_fit.hpp).
std::vector<UncertaintySource> rotation_sources(const Refined& k) {
  auto out = outline_sources(k.outline);
  if (k.panel_shape) out.push_back({"panel shape profile", k.panel_shape->spread_board});
  return out;
}

// Each candidate judged with its own model (pose_evidence.hpp), and the selection
// (pose_selection.hpp); the best's front and back also by the vertical structure on its sides.
AntennaRegistration select(const AntennaScene& s, std::vector<Refined> kept, const RegisterOptions& o) {
  EvidenceScene scene{&s.views, s.intrinsics, &s.points_board, s.viewpoints_board, s.up_board};
  std::vector<PoseCandidate> candidates;
  std::vector<PoseEvidence> twins;
  for (auto& k : kept) {
    const EvidenceJudge judge(*k.model, scene, o.evidence);
    candidates.push_back(k.candidate);
    candidates.back().panel_shape = k.panel_shape ? std::make_shared<const ShapeFit>(*k.panel_shape) : nullptr;
    candidates.back().evidence = judge(k.candidate.T_board_antenna);
    candidates.back().score = candidates.back().evidence.score(judge.options());
    twins.push_back(judge(turned_round(k.candidate.T_board_antenna)));
  }
  const auto best_shape = static_cast<std::size_t>(
      std::min_element(candidates.begin(), candidates.end(), ranks_before) - candidates.begin());
  add_mount_outline(candidates[best_shape].evidence, twins[best_shape], kept[best_shape], s, o);
  // Where no shape of the panel explains the best's edges, no comparison with it may take the
  // photos for independent units (pose_evidence.hpp).
  auto evidence = o.evidence;
  evidence.outline_errors_common = kept[best_shape].panel_shape && !kept[best_shape].panel_shape->bracketed;
  AntennaRegistration out;
  out.found = true;
  out.selection = select_pose(candidates, twins, s.mast, evidence, o.selection);
  const auto& sel = out.selection;
  Refined& best = kept[sel.best];
  out.T_board_antenna = sel.turned ? turned_round(best.candidate.T_board_antenna) : best.candidate.T_board_antenna;
  // A parametric panel is a box with brackets alike at both ends: its top is the end up.
  const bool symmetric_ends = best.model->panel != nullptr;
  if (symmetric_ends) out.T_board_antenna = upright(out.T_board_antenna, s.up_board);
  out.rotation_covariance_sources = rotation_sources(best);
  out.dilation_yaw_sigma_rad = best.outline.dilation_yaw_sigma_rad;
  out.outline_score = best.outline.score, out.outline_rms_px = best.outline.rms_px;
  out.outline_shape_sigma_m = best.outline.shape_sigma_m;
  out.outline_views = best.outline.views_used;
  out.panel_shape = std::move(best.panel_shape);
  const auto facing_as_result = [&](std::size_t i) {
    const Iso3 rival = rival_facing(candidates[i].T_board_antenna, out.T_board_antenna);
    return symmetric_ends ? upright(rival, s.up_board) : rival;
  };
  for (const auto i : sel.rivals) out.rivals.push_back(facing_as_result(i));
  for (const auto i : sel.near_rivals) out.near_rivals.push_back(facing_as_result(i));
  if (sel.front_back_open) out.rivals.push_back(turned_round(out.T_board_antenna));
  out.verdict = !sel.rivals.empty()   ? RegistrationVerdict::kAmbiguousShape
                : sel.front_back_open ? RegistrationVerdict::kFrontBackOpen
                                      : RegistrationVerdict::kUnique;
  out.candidates = std::move(candidates);
  return out;
}

// The result's faces against the region's points (face_plane.hpp): each plane that disagrees
// with the outline adds its pose as one the σ covers, and a warning.
void check_faces(AntennaRegistration& out, const model::AntennaModel& model, const AntennaScene& s,
                 const RegisterOptions& o) {
  const double radius = edge_rounding(model);
  out.face_planes = fit_face_planes(s.points_board, out.T_board_antenna, model.size_m, radius, s.viewpoints_board,
                                    out.rotation_covariance_board(), o.face_plane);
  for (const auto& plane : out.face_planes) {
    if (!plane.disagrees) continue;
    Iso3 T = out.T_board_antenna;
    T.linear() = exp_so3(plane.turn_board) * T.linear();
    out.face_rivals.push_back(T);
    out.warnings.push_back(fmt::format(
        "the region's points on the panel's {} face lie at {:.1f}° to the registered face (χ² {:.0f}, more than "
        "its σ and the outline's allow): the outline or the points are biased, and these photos do not say which "
        "(an oblique view of a narrow or ribbed face biases the points; arms and clamps the model lacks bias the "
        "outline); the σ covers both; photos facing that face more squarely would settle it",
        face_name(plane.normal_antenna), rad2deg(plane.turn_board.norm()), plane.chi2));
  }
}

// How the answer is polished and its long edges left out: at full resolution, with the model's box
// as the outline and its width free where RegisterOptions::free_answer_width.
SilhouetteOptions answer_polish(const model::AntennaModel& model, const RegisterOptions& o) {
  auto polish = polish_of(o.refine);
  polish.outline_box_m = model::outline_box(model);
  polish.free_outline_width = o.free_answer_width;
  return polish;
}

// The answer polished with the outline's width free (RegisterOptions::free_answer_width): its pose
// and the outline's parts of its σ follow, where the polish converges, and so does the profiled
// shape's spread: where the width is free, the edge radius (which mostly sets the outline's width)
// turns the pose far less. Not where the profile is open (shape_fit.hpp): no rounding explains
// that outline, whose departure from the model then changes with the view, not alike on every
// side, and the profile's pose and σ, which carry every rounding, stay.
void free_the_width(AntennaRegistration& out, const model::AntennaModel& model, const AntennaScene& s,
                    const RegisterOptions& o) {
  if (!o.free_answer_width || (out.panel_shape && !out.panel_shape->bracketed)) return;
  const auto polish = answer_polish(model, o);
  const auto freed = refine_by_silhouette(model.mesh_antenna, out.T_board_antenna, s.views, s.intrinsics, polish);
  if (!freed.converged && !freed.stopped_at_iteration_limit) return;
  out.T_board_antenna = freed.T_board_antenna;
  out.rotation_covariance_sources = outline_sources(freed);
  if (out.panel_shape)
    out.rotation_covariance_sources.push_back(
        {"panel shape profile",
         spread_of_shapes(*out.panel_shape, model, out.T_board_antenna, s.views, s.intrinsics, polish, o.panel_shape)});
  out.outline_shape_sigma_m = freed.shape_sigma_m;
}

// The result against each of its long edges left out (long_edge_check.hpp): each edge that decides
// the pose against the others adds a warning (the measurement's σ covers the pose without it), and
// one whose absence turns the pose as far as a rival stands makes a unique answer ambiguous.
void judge_long_edges(AntennaRegistration& out, const model::AntennaModel& model, const AntennaScene& s,
                      const RegisterOptions& o) {
  const auto polish = answer_polish(model, o);
  out.long_edges_left_out =
      check_long_edges(model.mesh_antenna, out.T_board_antenna, s.views, s.intrinsics, polish, o.long_edges);
  for (const auto& e : out.long_edges_left_out) {
    if (!e.disagrees) continue;
    out.warnings.push_back(fmt::format(
        "the pose rests on the outline of the panel's {} long edge: without it the other edges put the panel {:.1f}° "
        "turned ({:.1f} σ); a rounded edge before a background of about its own brightness shows its shading, not "
        "its outline, and the σ covers both; photos with that edge against a contrasting background (from another "
        "side, or in other light) would settle it",
        long_edge_name(e.edge), rad2deg(e.turn_rad), e.distance));
  }
  if (out.verdict == RegistrationVerdict::kUnique &&
      leaves_another_pose(out.long_edges_left_out, deg2rad(o.selection.rival_min_deg)))
    out.verdict = RegistrationVerdict::kAmbiguousShape;
}

// An answer whose shape profile presses against the roundest radome (shape_fit.hpp, unbracketed)
// says so: its σ carries the shapes, but only other photos can settle the pose.
void warn_of_open_shape(AntennaRegistration& out) {
  if (!out.panel_shape || out.panel_shape->bracketed) return;
  out.warnings.push_back(fmt::format(
      "the panel's long edges lie further inside its box than the outline of its roundest radome (edge radius "
      "{:.0f} mm): the edges seen are its shading, where the rounded radome turns from the light, not its outline "
      "(a pale radome before a bright background), and the photos cannot tell how round it is; the σ covers every "
      "rounding; photos with its edges against a darker background (from another side, or in other light) would "
      "settle it",
      1000 * out.panel_shape->radius_m));
}

// "Not found", and why.
AntennaRegistration not_found(std::size_t proposed, std::string why) {
  AntennaRegistration none;
  none.proposed = proposed;
  none.why_not = std::move(why);
  return none;
}

void check_scene(const AntennaScene& s) {
  if (s.views.empty() || s.region_view >= s.views.size() || s.areas.size() != s.views.size() ||
      s.viewpoints_board.size() != s.views.size())
    throw std::invalid_argument(
        "register_antenna: no views, a region view out of range, or not one area and viewpoint per view");
}

// The best pose meets too little of its outline to tell the antenna from what stands round it
// (RegisterOptions::max_answer_outline_score).
AntennaRegistration not_seen(const model::AntennaModel& model, double outline_score, std::size_t proposed,
                             const RegisterOptions& o) {
  return not_found(
      proposed,
      fmt::format("the best pose of the model '{}' meets the photos' edges along little of its outline (score {:.2f}; "
                  "an answer needs at most {:.2f}, about a third of its outline on edges): the edges it meets may as "
                  "well be the mount's, the mast's or a neighbour's, and the antenna does not stand out from what is "
                  "round it in these photos; photos with the antenna against a contrasting background (the sky from "
                  "another side, a wall) or from nearer would help",
                  model.name, outline_score, o.max_answer_outline_score));
}

// How far the rivals leave the answer's facing open: the largest angle between a rival's
// boresight and the answer's, the front/back turn left out (a box turned round has its outline).
double facing_open(const AntennaRegistration& r) {
  double open = 0.0;
  for (const Iso3& T : r.rivals) {
    const double angle = boresight_angle(T.linear(), r.T_board_antenna.linear());
    open = std::max(open, std::min(angle, M_PI - angle));
  }
  return open;
}

// The answer meets its outline only faintly and its rivals leave its facing open
// (RegisterOptions::max_faint_open_facing_deg): its downtilt and roll as panels hang, a uniform
// spread's standard deviation (width/√12) about its own x and y axes (left perturbation).
void keep_only_how_panels_hang(AntennaRegistration& out, double open, const RegisterOptions& o) {
  const auto spread = [](const std::array<double, 2>& range) { return deg2rad(range[1] - range[0]) / std::sqrt(12.0); };
  const Mat3& R = out.T_board_antenna.linear();
  const Vec3 variances(std::pow(spread(o.hanging_downtilt_deg), 2), std::pow(spread(o.hanging_roll_deg), 2), 0.0);
  out.rotation_covariance_sources.push_back(
      {"long axis not shown to be the panel's", R * variances.asDiagonal() * R.transpose()});
  out.warnings.push_back(fmt::format(
      "the model meets the photos' edges only faintly and poses turned {:.0f}° from it about its long "
      "axis fit as well: nothing shows that the object is this panel and not a mount's pipe or the mast (a pipe fits "
      "a panel's model at every turn), whose axis would give its downtilt and roll; their σ covers the range panels "
      "hang in ({:.0f}…{:+.0f}° of downtilt, {:.0f}…{:+.0f}° of roll); photos from nearer, over a wider arc round it, "
      "or with the panel against a contrasting background would settle it",
      rad2deg(open), o.hanging_downtilt_deg[0], o.hanging_downtilt_deg[1], o.hanging_roll_deg[0],
      o.hanging_roll_deg[1]));
}

}  // namespace

std::string to_string(RegistrationVerdict verdict) {
  switch (verdict) {
    case RegistrationVerdict::kAmbiguousShape:
      return "ambiguous";
    case RegistrationVerdict::kFrontBackOpen:
      return "front-back-open";
    case RegistrationVerdict::kUnique:
      break;
  }
  return "unique";
}

OptionProblems RegisterOptions::Check() const {
  OptionProblems p;
  p.nest("search", search.Check());
  p.nest("turns", turns.Check());
  p.nest("slide", slide.Check());
  p.nest("refine", refine.Check());
  p.nest("evidence", evidence.Check());
  p.nest("selection", selection.Check());
  p.nest("panel_shape", panel_shape.Check());
  p.nest("mount_search", mount_search.Check());
  p.nest("face_plane", face_plane.Check());
  p.nest("long_edges", long_edges.Check());
  p.require(refine_candidates >= 1, "refine_candidates", "at least 1");
  p.require(same_pose_deg >= 0 && same_pose_m >= 0, "same_pose_deg, same_pose_m", "≥ 0");
  p.require(neighbour_clearance_m >= 0, "neighbour_clearance_m", "≥ 0");
  p.require(std::isfinite(min_mast_gap_m), "min_mast_gap_m", "finite (negative: a panel may reach that far into it)");
  p.require(min_roi_span > 0 && min_roi_span <= 1, "min_roi_span", "in (0, 1]");
  p.require(max_outline_score > 0 && max_outline_score <= max_faint_outline_score && max_faint_outline_score <= 1,
            "max_outline_score, max_faint_outline_score", "0 < max_outline_score ≤ max_faint_outline_score ≤ 1");
  p.require(max_outline_score <= max_answer_outline_score && max_answer_outline_score <= 1, "max_answer_outline_score",
            "in [max_outline_score, 1]");
  p.require(max_faint_open_facing_deg > 0 && max_faint_open_facing_deg <= 90, "max_faint_open_facing_deg",
            "in (0, 90]");
  for (const auto& [range, name] :
       {std::pair{hanging_downtilt_deg, "hanging_downtilt_deg"}, std::pair{hanging_roll_deg, "hanging_roll_deg"}})
    p.require(range[0] < range[1] && range[0] >= -90 && range[1] <= 90, name, "an interval within [-90, 90]");
  return p;
}

std::vector<PoseCandidate> propose_poses(const model::AntennaModel& model, const AntennaScene& s,
                                         const RegisterOptions& o) {
  throw_unless_ok(o.Check(), "RegisterOptions");
  check_scene(s);
  auto proposals = from_outline(model, s, o);
  const auto by_points = from_points(model, s, o);
  proposals.insert(proposals.end(), by_points.begin(), by_points.end());
  return proposals;
}

Mat3 AntennaRegistration::rotation_covariance_board() const {
  Mat3 sum = Mat3::Zero();
  for (const auto& part : rotation_covariance_sources) sum += part.covariance;
  return sum;
}

double mast_gap(const model::AntennaModel& model, const Iso3& T_board_antenna, const reconstruction::Mast& mast) {
  return mast_gap({T_board_antenna, model.size_m}, edge_rounding(model), mast);
}

AntennaRegistration found_only_the_mast(const model::AntennaModel& model, std::size_t proposed) {
  auto none = not_found(
      proposed,
      fmt::format("every pose of the model '{}' that fits an outline in the rectangle hangs against or through the "
                  "mast found behind it: the edges found are the mast's and its clamps', and the panel's own do not "
                  "stand out from the background in these photos; photos with the panel against a contrasting "
                  "background (a wall, or the sky from another side) would help",
                  model.name));
  none.against_mast = true;
  return none;
}

RegisterOptions continuing(RegisterOptions options) {
  options.turns.of_best = 0;
  return options;
}

AntennaRegistration register_antenna(const model::AntennaModel& model, const AntennaScene& s,
                                     const RegisterOptions& o) {
  return register_antenna(model, s, o, propose_poses(model, s, o));
}

AntennaRegistration register_antenna(const model::AntennaModel& model, const AntennaScene& s, const RegisterOptions& o,
                                     const std::vector<PoseCandidate>& proposals) {
  throw_unless_ok(o.Check(), "RegisterOptions");
  check_scene(s);
  const auto shared = std::make_shared<const model::AntennaModel>(model);
  Dropped dropped;
  auto kept = refine_and_turn(shared, s, proposals, o, dropped);
  add_crease_twins(kept, s, o, dropped);
  fit_shapes(kept, s, o);
  keep_fitting_outlines(kept, s, o);
  const auto best = best_outline(kept);
  if ((best == kept.end() || best->outline.score > o.max_outline_score) && dropped.small_score <= o.max_outline_score) {
    return not_found(
        proposals.size(),
        fmt::format("a pose of the model '{}' fits its outline clearly (score {:.2f}) but spans only {:.0f} % of the "
                    "rectangle's longer side (a rectangle drawn around it: at least {:.0f} %), and no pose that spans "
                    "it fits more than faintly: is the rectangle drawn closely around the whole antenna?",
                    model.name, dropped.small_score, 100 * dropped.small_span, 100 * o.min_roi_span));
  }
  if (kept.empty() && dropped.mast_fits) return found_only_the_mast(model, proposals.size());
  if (kept.empty()) {
    return not_found(
        proposals.size(),
        proposals.empty()
            ? fmt::format("nothing in the rectangle fits the outline of the model '{}' in the photos: is the rectangle "
                          "drawn around the antenna, and is the model this antenna's?",
                          model.name)
            : fmt::format("no pose of the model '{}' fits its outline in the photos and spans the rectangle ({} "
                          "tried): is the rectangle drawn closely around the whole antenna, and is the model this "
                          "antenna's?",
                          model.name, proposals.size()));
  }
  auto out = select(s, std::move(kept), o);
  out.proposed = proposals.size();
  if (out.outline_score > o.max_answer_outline_score) return not_seen(model, out.outline_score, proposals.size(), o);
  const auto& answer_model = out.panel_shape ? out.panel_shape->model : model;
  free_the_width(out, answer_model, s, o);
  check_faces(out, answer_model, s, o);
  judge_long_edges(out, answer_model, s, o);
  warn_of_open_shape(out);
  if (const double open = facing_open(out);
      out.outline_score > o.max_outline_score && open > deg2rad(o.max_faint_open_facing_deg))
    keep_only_how_panels_hang(out, open, o);
  if (out.outline_score > o.max_outline_score)
    out.warnings.push_back(fmt::format(
        "the model's outline meets the photos' edges only faintly (score {:.2f}; a clearly seen antenna scores "
        "under {:.2f}): its edges are faint against the background or partly hidden; the σ carries the poor fit, "
        "but check the model drawn over the photos",
        out.outline_score, o.max_outline_score));
  return out;
}

}  // namespace antpose::registration
