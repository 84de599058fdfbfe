#include "antpose/registration/shape_fit.hpp"

#include <algorithm>
#include <cmath>

namespace antpose::registration {
namespace {

// The panel with another edge radius and end caps' rim (no caps for rim 0); brackets narrowed
// where rounder edges leave less of the back plate flat.
model::AntennaModel reshaped(const model::AntennaModel& base, double radius_m, double rim_m, double cap_height_m) {
  model::PanelSpec spec = *base.panel;
  spec.edge_radius_m = radius_m;
  spec.end_cap_rim_m = rim_m;
  spec.end_cap_height_m = rim_m > 0 ? std::min(cap_height_m, 0.25 * spec.height_m) : 0.0;
  const double flat = spec.width_m - 2 * radius_m;
  if (spec.bracket && spec.bracket_width_m >= flat - 0.01) spec.bracket_width_m = std::max(0.01, flat - 0.02);
  model::AntennaModel m = model::parametric_panel(spec);
  m.name = base.name;
  return m;
}

// The photos each shape's pose is refined in, and how.
struct Photos {
  const std::vector<SilhouetteView>* views;
  camera::CameraIntrinsics K;
  SilhouetteOptions polish;  // outline_box_m set per model
};

SilhouetteOptions for_model(SilhouetteOptions o, const model::AntennaModel& m) {
  o.outline_box_m = model::outline_box(m);
  return o;
}

// The shapes tried (radius, rim), each with its pose refined.
struct Profile {
  std::vector<double> radii, rims, scores;
  std::vector<model::AntennaModel> models;
  std::vector<SilhouetteResult> results;
  std::size_t best = 0;

  // From `from`: a neighbouring shape's pose, whose descent has done most of the work.
  void refine(double radius, double rim, const model::AntennaModel& base, const ShapeOptions& o, const Photos& photos,
              const Iso3& from) {
    auto m = reshaped(base, radius, rim, o.cap_height_m);
    results.push_back(refine_by_silhouette(m.mesh_antenna, from, *photos.views, photos.K, for_model(photos.polish, m)));
    radii.push_back(radius), rims.push_back(rim), scores.push_back(results.back().score);
    models.push_back(std::move(m));
    if (scores.back() < scores[best]) best = scores.size() - 1;
  }
};

// 0, step, .. (steps values).
std::vector<double> grid(double largest, std::size_t steps) {
  std::vector<double> out;
  for (std::size_t k = 0; k < steps; ++k)
    out.push_back(largest * static_cast<double>(k) / static_cast<double>(steps - 1));
  return out;
}

// The vertex of the parabola through the scores a, b, c of three evenly spaced values (b's at
// `at`), where it is convex; else `at`.
double parabola_vertex(double at, double step, double a, double b, double c) {
  const double curvature = a - 2 * b + c;
  return curvature > 0 ? at + 0.5 * step * (a - c) / curvature : at;
}

// Into fit: the shapes the photos do not rule out (pose_evidence.hpp's paired test against the
// best), each shape's likelihood relative to the best's, exp(−z²/2), z the paired difference over
// its standard error, and the second moment of the kept shapes' poses' rotations about the best's
// (rad², board frame) weighted by those likelihoods (z is the signed root of the likelihood ratio,
// about N(0, 1)): the pose averaged over the nuisance shape with its posterior on the grid under a
// flat prior. Counted alike, the shapes would spread the attitude over the test's whole acceptance
// region (out to decisive_z), not its one-σ extent. The shapes ruled out stay out: their poses may
// have slid into another basin, and a z from the units' scatter has no Gaussian tails to give them
// their due. A difference below min_difference is no evidence however small its scatter, so the
// standard error is taken as at least the one that makes min_difference borderline. Unbracketed
// (shape_fit.hpp), the photos misread the outline alike and count as one unit
// (EvidenceOptions::outline_errors_common).
void weigh_shapes(const Profile& p, const Photos& photos, const EvidenceOptions& evidence, ShapeFit& fit) {
  const auto outline = [&](std::size_t k) {
    PoseEvidence e;
    e.outline = evaluate_outline(p.models[k].mesh_antenna, p.results[k].T_board_antenna, *photos.views, photos.K,
                                 for_model(photos.polish, p.models[k]))
                    .cost;
    return e;
  };
  EvidenceOptions weighed = evidence;
  weighed.outline_errors_common = !fit.bracketed;
  const PoseEvidence at_best = outline(p.best);
  const Mat3& R_best = p.results[p.best].T_board_antenna.linear();
  const double least_error = evidence.min_difference / evidence.decisive_z;
  double weights = 0.0;
  for (std::size_t k = 0; k < p.results.size(); ++k) {
    const auto c = k == p.best ? Comparison{} : compare_shape(at_best, outline(k), weighed);
    const double z = std::max(c.difference, 0.0) / std::max(c.standard_error, least_error);
    fit.likelihoods.push_back(std::exp(-0.5 * z * z));
    if (c.decisive) continue;
    fit.within.push_back(k);
    const Vec3 d = log_so3(p.results[k].T_board_antenna.linear() * R_best.transpose());
    fit.spread_board += fit.likelihoods.back() * d * d.transpose();
    weights += fit.likelihoods.back();
  }
  fit.spread_board /= weights;
}

}  // namespace

OptionProblems ShapeOptions::Check() const {
  OptionProblems p;
  p.require(steps >= 2, "steps", "at least 2");
  p.require(largest_m > 0, "largest_m", "positive");
  p.require(rim_steps == 0 || rim_steps >= 2, "rim_steps", "0 (no end caps) or at least 2");
  p.require(largest_rim_m > 0 && largest_rim_m <= 0.05, "largest_rim_m", "in (0, 0.05] m");
  p.require(cap_height_m > 0, "cap_height_m", "positive");
  return p;
}

ShapeFit fit_shape(const model::AntennaModel& model, const Iso3& T_board_antenna,
                   const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& K,
                   const SilhouetteOptions& polish, const EvidenceOptions& evidence, const ShapeOptions& o) {
  throw_unless_ok(o.Check(), "ShapeOptions");
  ShapeFit fit;
  if (!o.enabled || !model.panel) return fit;
  const double largest = std::min(o.largest_m, 0.5 * std::min(model.size_m.x(), model.size_m.y()) - 0.005);
  if (!(largest > 0)) return fit;
  const Photos photos{&views, K, polish};
  const auto radii = grid(largest, o.steps);
  const auto rims = o.rim_steps > 0 ? grid(o.largest_rim_m, o.rim_steps) : std::vector<double>{0.0};
  Profile p;
  const std::size_t n = radii.size();
  for (std::size_t j = 0; j < rims.size(); ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const Iso3& from = i > 0   ? p.results.back().T_board_antenna
                         : j > 0 ? p.results[(j - 1) * n].T_board_antenna
                                 : T_board_antenna;
      p.refine(radii[i], rims[j], model, o, photos, from);
    }
  // Between the grid's values: the vertices of the profile's parabolas through the best cell.
  const std::size_t b = p.best, i = b % n, j = b / n;
  double r = radii[i], rim = rims[j];
  if (i > 0 && i + 1 < n) r = parabola_vertex(r, radii[1] - radii[0], p.scores[b - 1], p.scores[b], p.scores[b + 1]);
  if (j > 0 && j + 1 < rims.size())
    rim = parabola_vertex(rim, rims[1] - rims[0], p.scores[b - n], p.scores[b], p.scores[b + n]);
  if (r != radii[i] || rim != rims[j]) p.refine(r, rim, model, o, photos, p.results[b].T_board_antenna);
  if (p.results[p.best].views_used == 0) return fit;
  fit.fitted = true;
  fit.radius_m = p.radii[p.best], fit.rim_m = p.rims[p.best];
  fit.model = p.models[p.best];
  fit.outline = p.results[p.best];
  fit.radii_m = p.radii, fit.rims_m = p.rims, fit.scores = p.scores;
  fit.bracketed = i + 1 < n;
  weigh_shapes(p, photos, evidence, fit);
  return fit;
}

Mat3 spread_of_shapes(const ShapeFit& fit, const model::AntennaModel& model, const Iso3& T_board_antenna,
                      const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                      const SilhouetteOptions& polish, const ShapeOptions& options) {
  if (!fit.fitted || !model.panel) return Mat3::Zero();
  Mat3 spread = Mat3::Zero();
  double weights = 0.0;
  for (const std::size_t k : fit.within) {
    weights += fit.likelihoods[k];
    if (fit.radii_m[k] == fit.radius_m && fit.rims_m[k] == fit.rim_m) continue;  // the pose itself
    const auto m = reshaped(model, fit.radii_m[k], fit.rims_m[k], options.cap_height_m);
    const auto r = refine_by_silhouette(m.mesh_antenna, T_board_antenna, views, intrinsics, for_model(polish, m));
    const Vec3 d = log_so3(r.T_board_antenna.linear() * T_board_antenna.linear().transpose());
    spread += fit.likelihoods[k] * d * d.transpose();
  }
  return weights > 0 ? Mat3(spread / weights) : Mat3::Zero();
}

}  // namespace antpose::registration
