#include "antpose/registration/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"
#include "antpose/registration/silhouette_detail.hpp"

namespace antpose::registration {
namespace {

using detail::edge_cost, detail::EdgeMesh, detail::gather_all, detail::Gathered, detail::GatherWhat,
    detail::OutlineCounts, detail::Pose, detail::prepare_views, detail::PreparedView, detail::PreparedViews,
    detail::Sample, detail::weld;

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Tukey weights with the scale from the median absolute residual (in the level's px).
struct Normal {
  Mat6 H = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  double sum_w = 0, sum_wr2 = 0;
  std::size_t inliers = 0, samples = 0;
  double c = 0;  // Tukey's cut-off, full-resolution px
  // With the outline's width free (SilhouetteOptions::free_outline_width): the long edges' samples'
  // robust centre (their weights are taken about it), and the common offset's estimate and their
  // weighted mean Jacobian, by which H and b are reduced (the offset eliminated, a Schur complement).
  double centre = 0, offset = 0;
  Vec6 mean_J = Vec6::Zero();
  double centre_of(const Sample& s) const { return s.on_long_edge ? centre : 0.0; }
  double weight(const Sample& s) const {
    const double r = s.r - centre_of(s);
    if (!(std::abs(r) < c)) return 0.0;
    const double u = r / c;
    return (1 - u * u) * (1 - u * u);
  }
  // The sample's Jacobian as the reduced equations see it: a long edge's less the mean.
  Vec6 J(const Sample& s) const { return s.on_long_edge ? Vec6(s.J.transpose() - mean_J) : Vec6(s.J.transpose()); }
};

// The long edges' samples' median residual, full-resolution px (0 without any): the outline's
// width against the model's, robustly.
double long_edge_median(const Gathered& g) {
  std::vector<double> r;
  for (const auto& v : g.per_view)
    for (const auto& s : v)
      if (s.on_long_edge) r.push_back(s.r);
  return r.empty() ? 0.0 : median(std::move(r));
}

Normal normal_equations(const Gathered& g, double scale, const SilhouetteOptions& o) {
  Normal n;
  if (o.free_outline_width) n.centre = long_edge_median(g);
  std::vector<double> r;
  for (const auto& v : g.per_view)
    for (const auto& s : v) r.push_back((s.r - n.centre_of(s)) / scale);
  n.samples = r.size();
  if (r.empty()) return n;
  const double sigma = std::max(0.5, robust_sigma(std::move(r)));
  n.c = o.tukey_c * sigma * scale;
  double long_w = 0, long_wr = 0;
  Vec6 long_wJ = Vec6::Zero();
  for (const auto& v : g.per_view)
    for (const auto& s : v) {
      const double w = n.weight(s);
      if (w <= 0) continue;
      n.H += w * s.J.transpose() * s.J;
      n.b += w * s.J.transpose() * s.r;
      n.sum_w += w;
      n.sum_wr2 += w * s.r * s.r;
      ++n.inliers;
      if (s.on_long_edge) long_w += w, long_wr += w * s.r, long_wJ += w * s.J.transpose();
    }
  if (o.free_outline_width && long_w > 0) {
    n.mean_J = long_wJ / long_w;
    n.offset = long_wr / long_w;
    n.H -= long_w * n.mean_J * n.mean_J.transpose();
    n.b -= n.mean_J * long_wr;
    n.sum_wr2 -= long_wr * n.offset;
  }
  return n;
}

// Solves the damped normal equations over the free DOF; nullopt when they are singular.
std::optional<Vec6> solve(const Normal& n, const std::array<bool, 6>& free, Mat6* inverse = nullptr) {
  std::vector<int> idx;
  for (int i = 0; i < 6; ++i)
    if (free[i]) idx.push_back(i);
  const int k = static_cast<int>(idx.size());
  Eigen::MatrixXd H(k, k);
  Eigen::VectorXd b(k);
  for (int i = 0; i < k; ++i) {
    b[i] = n.b[idx[i]];
    for (int j = 0; j < k; ++j) H(i, j) = n.H(idx[i], idx[j]);
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * std::max(1.0, H.diagonal().maxCoeff())))
    return std::nullopt;
  Eigen::MatrixXd Hd = H;
  Hd.diagonal() *= 1.0 + 1e-6;  // a touch of Levenberg–Marquardt damping
  const Eigen::VectorXd x = Hd.ldlt().solve(b);
  Vec6 delta = Vec6::Zero();
  for (int i = 0; i < k; ++i) delta[idx[i]] = x[i];
  if (inverse) {
    const Eigen::MatrixXd Hi = ldlt.solve(Eigen::MatrixXd::Identity(k, k));
    inverse->setZero();
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) (*inverse)(idx[i], idx[j]) = Hi(i, j);
  }
  if (!delta.allFinite()) return std::nullopt;
  return delta;
}

// Mean truncated quadratic cost of the outline at full resolution, in [0, 1]: 0 when every
// contour sample lies on an edge, 1 per sample without an edge within score_cutoff_px (fixed, so
// that poses compare; chamfer-like, Barrow et al. 1977). The box's outline, or with
// `with_attachments` the whole outline.
double score(const Gathered& g, const SilhouetteOptions& o, bool with_attachments = false) {
  const OutlineCounts& c = g.counts;
  const std::size_t candidates = c.candidates + (with_attachments ? c.attachment_candidates : 0);
  if (candidates == 0) return 1.0;
  double sum = with_attachments ? c.attachment_cost : 0.0;
  std::size_t found = 0;
  const double centre = o.free_outline_width ? long_edge_median(g) : 0.0;  // the outline's width as found
  for (const auto& v : g.per_view)
    for (const auto& s : v) {
      sum += edge_cost(s.r - (s.on_long_edge ? centre : 0.0), o);
      ++found;
    }
  return (sum + double(c.candidates - found)) / double(candidates);
}

// κ of the file comment: how many samples along the contour share one edge error (blur, JPEG
// blocks), the factor by which their white noise is inflated.
double overlap_inflation(const SilhouetteOptions& o) {
  return std::max(1.0, o.correlation_length_px / o.sample_spacing_px);
}

// Adds the rotation prior to the normal equations as a measurement of the edges' units: its
// information × the edges' residual variance × the correlation inflation (so that it weighs as a
// Gaussian of its own covariance would against theirs). Returns that factor (0 without a prior).
double add_prior(Normal& n, const Mat3& R_board_antenna, const std::optional<RotationPrior>& prior,
                 const SilhouetteOptions& o) {
  if (!prior || n.sum_w <= 0) return 0.0;
  const double sigma2 = std::max(n.sum_wr2 / n.sum_w, 0.25 * 0.25);
  const double weight = sigma2 * overlap_inflation(o);
  const Vec3 r = log_so3(prior->R_board_antenna * R_board_antenna.transpose());
  n.H.topLeftCorner<3, 3>() += weight * prior->information;
  n.b.head<3>() += weight * prior->information * r;
  return weight;
}

struct Descent {
  Pose pose;
  bool converged = false;
  int iterations = 0;
  double score = 1.0;
};

// The descents of one refinement: its prepared photos, stages (level, search in that level's px:
// the coarsest searches wide, every later one ±fine_search_px; a monotone descent also ends on a
// fine stage where the model is too narrow for a pyramid, on the edges the score and the
// covariance use — a narrow panel's own, not the mast's 20 px beyond it) and options.
class Descender {
 public:
  Descender(const EdgeMesh& m, const PreparedViews& ready, const camera::CameraIntrinsics& K,
            const SilhouetteOptions& o, const std::optional<RotationPrior>& prior)
      : m_(m), views_(ready.views), K_(K), o_(o), prior_(prior) {
    for (int level = ready.top; level >= 0; --level)
      stages_.emplace_back(level, level == ready.top
                                      ? std::max(o.fine_search_px, o.search_range_px / std::ldexp(1.0, level))
                                      : o.fine_search_px);
    if (monotone() && stages_.back().second > o.fine_search_px) stages_.emplace_back(0, o.fine_search_px);
  }

  Gathered gather(const Pose& p, int level, double search_px, GatherWhat what = {}) {
    Gathered g = gather_all(m_, p, views_, K_, level, search_px, o_, what);
    reached_middle_ = reached_middle_ || g.counts.reached_middle;
    return g;
  }
  double full_score(const Pose& p) { return score(gather(p, 0, o_.fine_search_px, {.jacobians = false}), o_); }
  bool reached_middle() const { return reached_middle_; }

  Descent descend(const Pose& start) {
    Descent d;
    d.pose = start;
    std::optional<double> scored;
    for (const auto& [level, search] : stages_) scored = descend_stage(d, level, search);
    d.score = scored ? *scored : full_score(d.pose);
    return d;
  }

 private:
  bool monotone() const { return o_.max_step_halvings >= 0; }

  // The stage's descent from d.pose; where it is checked, the score at the pose it ends on (kept
  // with every step it takes), else nothing.
  std::optional<double> descend_stage(Descent& d, int level, double search) {
    const double scale = std::ldexp(1.0, level);
    // Monotone at full resolution: Gauss–Newton re-associates the edges at every step, and nearer
    // a strong clutter edge than the panel's own it walks off the outline while each step looks
    // good to its own linearisation; the score (which ranks the starts) does not.
    const bool checked = monotone() && level == 0;
    double current = checked ? full_score(d.pose) : 0.0;
    const auto ended = [&]() { return checked ? std::optional<double>(current) : std::nullopt; };
    d.converged = false;
    Vec6 previous_step = Vec6::Zero();
    for (int it = 0; it < o_.max_iterations_per_level; ++it) {
      const Gathered g = gather(d.pose, level, search);
      Normal n = normal_equations(g, scale, o_);
      if (n.inliers < 12) break;
      add_prior(n, d.pose.R, prior_, o_);
      auto delta = solve(n, o_.free);
      if (!delta) break;
      ++d.iterations;
      // The step's weighted RMS image motion, in the level's px.
      const double motion = std::sqrt(std::max(0.0, delta->dot(n.H * *delta)) / n.sum_w) / scale;
      // A trust region on the rotation: where the outline hardly fixes the yaw (a narrow panel on
      // a coarse level, seen face-on from below) the step about the long axis can be 100°+, far
      // beyond the linearisation, and the descent wanders from basin to basin.
      if (const double turn = delta->head<3>().norm(); turn > o_.max_step_rotation_rad)
        *delta *= o_.max_step_rotation_rad / turn;
      // Where the outline hardly fixes a direction (the yaw of a narrow panel seen face-on),
      // samples entering and leaving the robust weights make the steps swing back and forth about
      // the minimum without shrinking: a small step reversing the last one has arrived, and half
      // of it lands between the two poses.
      const bool swinging = motion < o_.swing_motion_px && delta->dot(n.H * previous_step) < 0.0;
      if (swinging) *delta /= 2;
      if (checked && !lowers_score(d, *delta, current)) {  // nothing along Gauss–Newton's direction does: arrived
        d.converged = true;
        return ended();
      }
      d.pose.R = exp_so3(delta->head<3>()) * d.pose.R;
      d.pose.t += delta->tail<3>();
      previous_step = *delta;
      if (motion < 0.01 || swinging) {
        d.converged = true;
        return ended();
      }
    }
    return ended();
  }

  // The step, halved up to max_step_halvings times until it lowers the score (a line search).
  bool lowers_score(const Descent& d, Vec6& delta, double& current) {
    for (int halving = 0; halving <= o_.max_step_halvings; ++halving) {
      const double trial = full_score(Pose{exp_so3(delta.head<3>()) * d.pose.R, d.pose.t + delta.tail<3>()});
      if (trial <= current) {
        current = trial;
        return true;
      }
      delta /= 2;
    }
    return false;
  }

  const EdgeMesh& m_;
  const std::vector<PreparedView>& views_;
  const camera::CameraIntrinsics& K_;
  const SilhouetteOptions& o_;
  const std::optional<RotationPrior>& prior_;
  std::vector<std::pair<int, double>> stages_;
  bool reached_middle_ = false;  // by any search line of any evaluation
};

// σ_shape (file comment): each mesh edge's offset from the outline in metres and its variance
// from what the covariance already holds, the offsets' excess over it over G − 6 degrees of
// freedom, pooled with the prior. That variance is the samples' noise (their scatter about their
// edge's offset, inflated for their overlap as far as the edge has samples to overlap) and the
// edge bias: an offset of edge_bias_px at every sample of the edge moves its offset by
// edge_bias_px Σ w p / Σ w p², and the bias term carries it already.
struct EdgeOffset {  // weighted sums over one mesh edge's samples (w weight, p px per m, r residual)
  double wpr = 0, wp = 0, wpp = 0, w2pp = 0, w = 0, wrr = 0;
  std::size_t count = 0;
  void add(double wi, double p, double r) {
    wpr += wi * p * r, wp += wi * p, wpp += wi * p * p, w2pp += wi * wi * p * p, w += wi, wrr += wi * r * r, ++count;
  }
};

struct ShapeSigma {
  double sigma_m = 0;
  std::size_t edges = 0;
  std::optional<double> scatter_px2;  // the samples' variance about their edge's offset; none: no edge has two
};

ShapeSigma shape_sigma(const std::vector<EdgeOffset>& edge, const SilhouetteOptions& o) {
  const double kappa = overlap_inflation(o);
  double scatter = 0, dof = 0;  // the samples' weighted scatter about their edge's offset
  for (const auto& e : edge)
    if (e.count > 1) scatter += e.wrr - e.wpr * e.wpr / e.wpp, dof += e.w - 1;
  const std::optional<double> sigma2_px = dof > 0 ? std::optional<double>(std::max(0.0, scatter) / dof) : std::nullopt;
  double excess = 0;
  std::size_t edges = 0;
  for (const auto& e : edge) {
    if (e.count < 2) continue;
    const double offset = e.wpr / e.wpp, bias = o.edge_bias_px * e.wp / e.wpp;
    const double noise = sigma2_px.value_or(0.0) * std::min(kappa, double(e.count)) * e.w2pp / (e.wpp * e.wpp);
    excess += offset * offset - noise - bias * bias, ++edges;
  }
  const double nu0 = o.shape_prior_edges, prior2 = o.shape_tolerance_m * o.shape_tolerance_m;
  const double nu = edges > 6 ? double(edges - 6) : 0.0;
  const double measured2 = nu > 0 ? std::max(0.0, excess) / nu : 0.0;
  if (nu0 + nu <= 0) return {o.shape_tolerance_m, edges, sigma2_px};
  return {std::sqrt((nu0 * prior2 + nu * measured2) / (nu0 + nu)), edges, sigma2_px};
}

// The covariance at the solution (file comment): the sandwich H⁻¹ (Σ_white + Σ_bias) H⁻¹ of white
// edge noise (inflated for the samples' overlap), errors shared by all samples of a mesh edge (the
// model's shape error σ_shape and an edge-localisation bias: background, blur, shading, alike in
// every view) and that bias common to the whole outline (a dilation). The white noise is the
// samples' scatter about their own edge's offset: the offsets are what the shared terms carry, and
// the residuals' whole variance would count them twice. The prior counts once as information (in
// H) and once as its own noise (in M).
void covariance_at(SilhouetteResult& result, const Gathered& g, const Normal& n, const Mat6& Hinv, double prior_weight,
                   const std::optional<RotationPrior>& prior, const EdgeMesh& m, const Pose& pose,
                   const SilhouetteOptions& o) {
  result.rms_px = std::sqrt(n.sum_wr2 / n.sum_w);
  // Per mesh edge: b_g for a shape error of 1 m (scaled by σ_shape once it is measured from the
  // same samples' offsets) and for the edge bias.
  std::vector<Vec6> shape(m.edges.size(), Vec6::Zero()), bias(m.edges.size(), Vec6::Zero());
  std::vector<EdgeOffset> offsets(m.edges.size());
  Vec6 dilation = Vec6::Zero();
  for (const auto& view : g.per_view)
    for (const auto& s : view) {
      const double w = n.weight(s);
      if (w <= 0) continue;
      // With the width free, a long edge's sample moves the pose only by its Jacobian's departure
      // from their mean, and its edge's offset is measured beyond their common one.
      const Vec6 J = n.J(s);
      if (s.px_per_m > 0) offsets[s.edge].add(w, s.px_per_m, s.r - (s.on_long_edge ? n.offset : 0.0));
      shape[s.edge] += w * s.px_per_m * J;
      bias[s.edge] += w * o.edge_bias_px * J;
      dilation += w * o.outline_dilation_px * J;
    }
  const ShapeSigma shape_error = shape_sigma(offsets, o);
  result.shape_sigma_m = shape_error.sigma_m;
  result.shape_edges = shape_error.edges;
  const double parameters = o.free_outline_width ? 7.0 : 6.0;
  const double sigma2 = shape_error.scatter_px2.value_or(n.sum_wr2 / std::max(1.0, n.sum_w - parameters));
  const double inflation = overlap_inflation(o);
  Mat6 noise = sigma2 * inflation * n.H;
  if (prior)
    noise.topLeftCorner<3, 3>() +=
        (prior_weight * prior_weight - sigma2 * inflation * prior_weight) * prior->information;
  Mat6 shape_M = Mat6::Zero(), bias_M = Mat6::Zero();
  for (std::size_t e = 0; e < m.edges.size(); ++e)
    shape_M += shape[e] * shape[e].transpose(), bias_M += bias[e] * bias[e].transpose();
  shape_M *= shape_error.sigma_m * shape_error.sigma_m;
  auto& parts = result.covariance_parts;
  parts.noise = Hinv * noise * Hinv;
  parts.shape = Hinv * shape_M * Hinv;
  parts.edge_bias = Hinv * bias_M * Hinv;
  parts.dilation = Hinv * (dilation * dilation.transpose()) * Hinv;
  result.covariance = parts.noise + parts.shape + parts.edge_bias + parts.dilation;
  result.dilation_yaw_sigma_rad = std::abs((Hinv * dilation).head<3>().dot(pose.R.col(2)));
}

// The checks of the result (SilhouetteOptions' acceptance), each failure a warning; whether it
// passed them all but the iteration limit, which is judged last: alone, it leaves a descent a
// search may continue.
bool passes_checks(SilhouetteResult& result, bool solvable, const OutlineCounts& counts, const Descent& best,
                   const std::optional<Descent>& rival, const Pose& start, const SilhouetteOptions& o) {
  bool ok = solvable;
  auto fail = [&](std::string why) { ok = false, result.warnings.push_back(std::move(why)); };
  if (!solvable)
    result.warnings.push_back("silhouette: too few contour samples found an edge to fix the pose");
  else if (!best.converged)
    result.warnings.push_back(
        fmt::format("silhouette: no convergence within {} iterations at full resolution", o.max_iterations_per_level));
  const double outside = counts.candidates ? double(counts.outside) / double(counts.candidates) : 0.0;
  if (outside > o.max_outside_fraction)
    fail(
        fmt::format("silhouette: {:.0f} % of the model's outline falls outside the photos or their regions of interest",
                    100 * outside));
  if (static_cast<int>(result.views_used) < o.min_views)
    fail(fmt::format("silhouette: only {} view(s) show the model's outline (at least {} needed)", result.views_used,
                     o.min_views));
  if (result.inlier_fraction < o.min_inlier_fraction)
    fail(
        fmt::format("silhouette: only {:.0f} % of the model's outline meets an image edge (at least {:.0f} % "
                    "expected); is the antenna in the photos and the start close?",
                    100 * result.inlier_fraction, 100 * o.min_inlier_fraction));
  if (solvable && result.rms_px > o.max_rms_px)
    fail(fmt::format("silhouette: edge RMS {:.2f} px (more than {:.2f} px)", result.rms_px, o.max_rms_px));
  if (rival && rival->score < best.score) {
    result.left_start = rival->pose.T();
    fail(
        fmt::format("silhouette: a pose turned {:.1f}° from the result fits the outline better (score {:.3f} vs "
                    "{:.3f}) but lies more than {:.0f}° from the start: the start is probably wrong",
                    rad2deg(result.rival_rotation_rad), rival->score, best.score, rad2deg(o.max_rotation_change_rad)));
  } else if (rival && rival->score < best.score + o.rival_margin) {
    fail(
        fmt::format("silhouette: ambiguous yaw: a pose turned {:.1f}° fits the outline nearly as well (score {:.3f} "
                    "vs {:.3f}); photograph the antenna over a wider arc",
                    rad2deg(result.rival_rotation_rad), rival->score, best.score));
  }
  if (const double turned = rotation_distance(start.R, best.pose.R); turned > o.max_rotation_change_rad) {
    if (!result.left_start) result.left_start = result.T_board_antenna;
    fail(
        fmt::format("silhouette: the pose turned {:.1f}° from the start (more than {:.1f}°): probably another local "
                    "minimum",
                    rad2deg(turned), rad2deg(o.max_rotation_change_rad)));
  }
  return ok;
}

// One descent from `start` on photos prepared for it (up to at least this run's coarsest level).
SilhouetteResult refine_prepared(const EdgeMesh& m, const Pose& start, const PreparedViews& prepared,
                                 const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options,
                                 const std::optional<RotationPrior>& prior) {
  SilhouetteResult result;
  result.T_board_antenna = start.T();
  PreparedViews ready = prepared;  // shares the images
  ready.top = std::min(ready.top, std::max(0, options.max_level));
  Descender descender(m, ready, intrinsics, options, prior);

  Descent best = descender.descend(start);
  result.iterations = best.iterations;
  // A panel's outline is nearly the same at two yaws (the width w|cos θ| + d|sin θ| repeats
  // about θ = atan(d/w)) when the views span little: descend again from starts turned about the
  // long axis and keep the best score; a distinct rival that scores nearly as well is reported.
  std::optional<Descent> rival;
  for (const double offset : options.rival_yaw_offsets_rad) {
    Descent d = descender.descend(Pose{exp_so3(offset * best.pose.R.col(2)) * best.pose.R, best.pose.t});
    result.iterations += d.iterations;
    if (rotation_distance(d.pose.R, best.pose.R) < deg2rad(2.0)) continue;
    if (d.score < best.score && rotation_distance(d.pose.R, start.R) <= options.max_rotation_change_rad)
      std::swap(d, best);
    if (!rival || d.score < rival->score) rival = d;
  }
  result.score = best.score;
  if (rival) {
    result.rival_score = rival->score;
    result.rival_rotation_rad = rotation_distance(rival->pose.R, best.pose.R);
  }

  // Statistics and covariance at the solution (full resolution, fine search).
  const Gathered g = descender.gather(best.pose, 0, options.fine_search_px, {.attachments = true});
  result.search_reached_middle = descender.reached_middle();
  result.score_with_attachments = score(g, options, true);
  Normal n = normal_equations(g, 1.0, options);
  const double prior_weight = n.inliers > 12 ? add_prior(n, best.pose.R, prior, options) : 0.0;
  result.T_board_antenna = best.pose.T();
  result.views_used = g.views_with_samples;
  result.samples = n.inliers;
  result.inlier_fraction = g.counts.candidates ? double(n.inliers) / double(g.counts.candidates) : 0.0;
  Mat6 Hinv;
  const bool solvable = n.inliers > 12 && solve(n, options.free, &Hinv).has_value();
  if (solvable) covariance_at(result, g, n, Hinv, prior_weight, prior, m, best.pose, options);
  const bool ok = passes_checks(result, solvable, g.counts, best, rival, start, options);
  result.stopped_at_iteration_limit = ok && !best.converged;
  result.converged = ok && best.converged;
  return result;
}

// Whether two runs prepare their photos alike (prepare_views), but for the coarsest level.
bool prepared_alike(const SilhouetteOptions& a, const SilhouetteOptions& b) {
  return a.roi_margin_px == b.roi_margin_px && a.gamma == b.gamma && a.smoothing_sigma_px == b.smoothing_sigma_px &&
         a.mask_guard_px == b.mask_guard_px && a.min_coarse_width_px == b.min_coarse_width_px;
}

}  // namespace

OptionProblems SilhouetteOptions::Check() const {
  OptionProblems p;
  p.require(search_range_px > 0 && fine_search_px > 0, "search_range_px, fine_search_px", "positive");
  p.require(sample_spacing_px > 0, "sample_spacing_px", "positive");
  p.require(min_edge_gradient >= 0 && smoothing_sigma_px >= 0 && gamma >= 0,
            "min_edge_gradient, smoothing_sigma_px, gamma", "≥ 0");
  p.require(max_level >= 0 && max_level <= 12, "max_level", "in [0, 12]");
  p.require(min_coarse_width_px > 0, "min_coarse_width_px", "positive");
  p.require(max_iterations_per_level >= 0 && max_step_halvings >= -1, "max_iterations_per_level, max_step_halvings",
            "≥ 0 and ≥ −1");
  p.require(swing_motion_px >= 0, "swing_motion_px", "≥ 0");
  p.require(max_step_rotation_rad > 0 && max_rotation_change_rad > 0, "max_step_rotation_rad, max_rotation_change_rad",
            "positive");
  p.require(tukey_c > 0, "tukey_c", "positive");
  p.require(roi_margin_px >= 0 && mask_guard_px >= 0 && correlation_length_px >= 0,
            "roi_margin_px, mask_guard_px, correlation_length_px", "≥ 0");
  p.require(shape_tolerance_m >= 0 && shape_prior_edges >= 0, "shape_tolerance_m, shape_prior_edges", "≥ 0");
  p.require(edge_bias_px >= 0 && outline_dilation_px >= 0, "edge_bias_px, outline_dilation_px", "≥ 0");
  p.require((outline_box_m.array() >= 0).all() && box_tolerance_m >= 0, "outline_box_m, box_tolerance_m", "each ≥ 0");
  p.require(std::any_of(free.begin(), free.end(), [](bool f) { return f; }), "free", "at least one degree of freedom");
  p.require(std::all_of(rival_yaw_offsets_rad.begin(), rival_yaw_offsets_rad.end(),
                        [](double a) { return std::abs(a) <= M_PI; }),
            "rival_yaw_offsets_rad", "each within ±π");
  p.require(score_cutoff_px > 0 && rival_margin >= 0, "score_cutoff_px, rival_margin", "cutoff positive, margin ≥ 0");
  p.require(
      min_inlier_fraction >= 0 && min_inlier_fraction <= 1 && max_outside_fraction >= 0 && max_outside_fraction <= 1,
      "min_inlier_fraction, max_outside_fraction", "in [0, 1]");
  p.require(max_rms_px > 0, "max_rms_px", "positive");
  p.require(min_views >= 1, "min_views", "at least 1");
  return p;
}

std::vector<SilhouetteResult> refine_by_silhouette_runs(const model::Mesh& mesh_antenna,
                                                        const Iso3& T_board_antenna_initial,
                                                        const std::vector<SilhouetteView>& views,
                                                        const camera::CameraIntrinsics& intrinsics,
                                                        const std::vector<SilhouetteOptions>& runs,
                                                        const std::optional<RotationPrior>& prior) {
  if (mesh_antenna.triangles.empty()) throw std::invalid_argument("refine_by_silhouette: the mesh has no triangles");
  if (runs.empty()) return {};
  for (const auto& run : runs) {
    throw_unless_ok(run.Check(), "SilhouetteOptions");
    if (!prepared_alike(run, runs.front()))
      throw std::invalid_argument(
          "refine_by_silhouette_runs: the runs must prepare the photos alike (roi_margin_px, gamma, "
          "smoothing_sigma_px, mask_guard_px, min_coarse_width_px)");
  }
  const EdgeMesh m = weld(mesh_antenna);
  const Pose start{T_board_antenna_initial.linear(), T_board_antenna_initial.translation()};
  int max_level = 0;
  for (const auto& run : runs) max_level = std::max(max_level, run.max_level);
  std::vector<std::string> warnings;
  const PreparedViews ready = prepare_views(m, {start}, views, intrinsics, runs.front(), max_level, warnings);
  std::vector<SilhouetteResult> out;
  for (const auto& run : runs) {
    out.push_back(refine_prepared(m, start, ready, intrinsics, run, prior));
    out.back().warnings.insert(out.back().warnings.begin(), warnings.begin(), warnings.end());
  }
  return out;
}

SilhouetteResult refine_by_silhouette(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna_initial,
                                      const std::vector<SilhouetteView>& views,
                                      const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options,
                                      const std::optional<RotationPrior>& prior) {
  return refine_by_silhouette_runs(mesh_antenna, T_board_antenna_initial, views, intrinsics, {options}, prior).front();
}

std::vector<OutlineEvaluation> evaluate_outlines(const model::Mesh& mesh_antenna, const std::vector<Iso3>& poses,
                                                 const std::vector<SilhouetteView>& views,
                                                 const camera::CameraIntrinsics& intrinsics,
                                                 const SilhouetteOptions& options) {
  if (mesh_antenna.triangles.empty()) throw std::invalid_argument("evaluate_outline: the mesh has no triangles");
  throw_unless_ok(options.Check(), "SilhouetteOptions");
  if (poses.empty()) return {};
  const EdgeMesh m = weld(mesh_antenna);
  std::vector<Pose> at;
  for (const Iso3& T : poses) at.push_back({T.linear(), T.translation()});
  std::vector<std::string> warnings;
  const PreparedViews ready = prepare_views(m, at, views, intrinsics, options, 0, warnings);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<OutlineEvaluation> out;
  for (const Pose& pose : at) {
    const Gathered g =
        gather_all(m, pose, ready.views, intrinsics, 0, options.fine_search_px, options, {.jacobians = false});
    OutlineEvaluation& e = out.emplace_back();
    for (std::size_t i = 0; i < views.size(); ++i) {
      const OutlineCounts& c = g.per_view_counts[i];
      double sum = 0.0;
      for (const auto& smp : g.per_view[i]) sum += edge_cost(smp.r, options);
      const double unfound = static_cast<double>(c.candidates - g.per_view[i].size());
      e.cost.push_back(c.candidates ? (sum + unfound) / static_cast<double>(c.candidates) : nan);
      const auto found = static_cast<double>(g.per_view[i].size());
      e.placement.push_back(found > 0 ? sum / found : nan);
      e.samples.push_back(c.candidates);
    }
    e.score = score(g, options);
  }
  return out;
}

OutlineEvaluation evaluate_outline(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                   const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                                   const SilhouetteOptions& options) {
  return evaluate_outlines(mesh_antenna, {T_board_antenna}, views, intrinsics, options).front();
}

std::optional<int> long_edge_of(const Vec3& a_antenna, const Vec3& b_antenna) {
  const Vec3 d = b_antenna - a_antenna;
  if (!(std::abs(d.z()) >= 0.9 * d.norm()) || d.norm() == 0) return std::nullopt;
  const Vec3 middle = 0.5 * (a_antenna + b_antenna);
  return static_cast<int>(middle.x() > 0) + 2 * static_cast<int>(middle.y() > 0);
}

}  // namespace antpose::registration
