#include "antpose/registration/shape_fit.hpp"

#include <algorithm>
#include <cmath>

namespace antpose::registration {
namespace {

// The panel with another edge radius; brackets narrowed where the rounder edges leave less of the
// back plate flat.
model::AntennaModel with_radius(const model::AntennaModel& base, double radius_m) {
  model::PanelSpec spec = *base.panel;
  spec.edge_radius_m = radius_m;
  const double flat = spec.width_m - 2 * radius_m;
  if (spec.bracket && spec.bracket_width_m >= flat - 0.01) spec.bracket_width_m = std::max(0.01, flat - 0.02);
  model::AntennaModel m = model::parametric_panel(spec);
  m.name = base.name;
  return m;
}

PoseEvidence outline_evidence(const model::AntennaModel& m, const Iso3& T, const std::vector<SilhouetteView>& views,
                              const camera::CameraIntrinsics& K, const SilhouetteOptions& o) {
  PoseEvidence e;
  e.outline = evaluate_outline(m.mesh_antenna, T, views, K, o).cost;
  return e;
}

}  // namespace

OptionProblems EdgeRadiusOptions::Check() const {
  OptionProblems p;
  p.require(steps >= 2, "steps", "at least 2");
  p.require(largest_m > 0, "largest_m", "positive");
  return p;
}

EdgeRadiusFit fit_edge_radius(const model::AntennaModel& model, const Iso3& T_board_antenna,
                              const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& K,
                              const SilhouetteOptions& polish, const EvidenceOptions& evidence,
                              const EdgeRadiusOptions& o) {
  throw_unless_ok(o.Check(), "EdgeRadiusOptions");
  EdgeRadiusFit fit;
  if (!o.enabled || !model.panel) return fit;
  const double largest = std::min(o.largest_m, 0.5 * std::min(model.size_m.x(), model.size_m.y()) - 0.005);
  if (!(largest > 0)) return fit;
  auto refine = polish;
  refine.outline_box_m = model.size_m;
  std::vector<model::AntennaModel> models;
  std::vector<SilhouetteResult> results;
  for (std::size_t k = 0; k < o.steps; ++k) {
    const double r = largest * static_cast<double>(k) / static_cast<double>(o.steps - 1);
    models.push_back(with_radius(model, r));
    results.push_back(refine_by_silhouette(models.back().mesh_antenna, T_board_antenna, views, K, refine));
    fit.radii_m.push_back(r);
    fit.scores.push_back(results.back().score);
  }
  auto best = static_cast<std::size_t>(std::min_element(fit.scores.begin(), fit.scores.end()) - fit.scores.begin());
  // Between the grid's radii: the vertex of the parabola through the best and its neighbours.
  if (best > 0 && best + 1 < fit.scores.size()) {
    const double a = fit.scores[best - 1], b = fit.scores[best], c = fit.scores[best + 1];
    const double step = fit.radii_m[1] - fit.radii_m[0], curvature = a - 2 * b + c;
    if (curvature > 0) {
      const double r = fit.radii_m[best] + 0.5 * step * (a - c) / curvature;
      models.push_back(with_radius(model, r));
      results.push_back(refine_by_silhouette(models.back().mesh_antenna, T_board_antenna, views, K, refine));
      fit.radii_m.push_back(r);
      fit.scores.push_back(results.back().score);
      if (fit.scores.back() < b) best = fit.scores.size() - 1;
    }
  }
  if (results[best].views_used == 0) return fit;
  fit.fitted = true;
  fit.radius_m = fit.radii_m[best];
  fit.model = models[best];
  fit.outline = results[best];
  // The radii the photos do not rule out, and the spread of their poses about the best's.
  const PoseEvidence at_best = outline_evidence(models[best], results[best].T_board_antenna, views, K, refine);
  const Mat3& R_best = results[best].T_board_antenna.linear();
  std::size_t n = 0;
  for (std::size_t k = 0; k < results.size(); ++k) {
    if (k != best) {
      const auto other = outline_evidence(models[k], results[k].T_board_antenna, views, K, refine);
      if (compare_shape(at_best, other, evidence).decisive) continue;
    }
    fit.within_m.push_back(fit.radii_m[k]);
    const Vec3 d = log_so3(results[k].T_board_antenna.linear() * R_best.transpose());
    fit.spread_board += d * d.transpose();
    ++n;
  }
  fit.spread_board /= static_cast<double>(n);
  return fit;
}

}  // namespace antpose::registration
