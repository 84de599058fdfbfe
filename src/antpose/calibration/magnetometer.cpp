#include "antpose/calibration/magnetometer.hpp"
#include "antpose/calibration/least_squares.hpp"
#include "antpose/geometry/symmetric3.hpp"

#include <array>
#include <cmath>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Dense>
#include <fmt/format.h>

namespace antpose::calibration {
namespace {

std::string prefix(const std::filesystem::path& source) { return source.empty() ? "" : source.string() + ": "; }

// std/mean of ‖f(m_i)‖.
template <typename F>
std::pair<double, double> norm_stats(const std::vector<Vec3>& m, F&& f) {
  double s = 0.0, ss = 0.0;
  for (const auto& v : m) {
    const double n = f(v).norm();
    s += n;
    ss += n * n;
  }
  const double N = static_cast<double>(m.size());
  const double mean = s / N;
  return {mean, std::sqrt(std::max(0.0, ss / N - mean * mean))};
}

struct EllipsoidResidual {
  explicit EllipsoidResidual(const Vec3& m) : m_(m) {}
  template <typename T>
  bool operator()(const T* const b, const T* const s, const T* const f, T* r) const {
    // s = (s00, s01, s02, s11, s12, s22), symmetric S; det-normalised so F carries the scale.
    const T d0 = T(m_[0]) - b[0], d1 = T(m_[1]) - b[1], d2 = T(m_[2]) - b[2];
    const T det = s[0] * (s[3] * s[5] - s[4] * s[4]) - s[1] * (s[1] * s[5] - s[4] * s[2]) + s[2] * (s[1] * s[4] - s[3] * s[2]);
    const T c = T(1) / ceres::cbrt(det);
    const T v0 = c * (s[0] * d0 + s[1] * d1 + s[2] * d2);
    const T v1 = c * (s[1] * d0 + s[3] * d1 + s[4] * d2);
    const T v2 = c * (s[2] * d0 + s[4] * d1 + s[5] * d2);
    r[0] = ceres::sqrt(v0 * v0 + v1 * v1 + v2 * v2) - f[0];
    return true;
  }
  Vec3 m_;
};

// The 1σ of b and of the normalised S = S_s / ∛det S_s from the refinement's covariance: S_s's
// scale does not change the residual (F carries it), one null direction left out of the inverse;
// dS = (dS_s − ⅓ tr(S_s⁻¹ dS_s) S_s) / ∛det S_s takes s's covariance to S's entries.
void refinement_sigmas(MagnetometerCalibration& c, ceres::Problem& problem, const double* b, const double* s,
                       const Mat3& S_s, double variance) {
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = 1;
  ceres::Covariance covariance(co);
  if (!covariance.Compute({{b, b}, {s, s}}, &problem)) return;
  Mat3 cov_b;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> cov_s;
  covariance.GetCovarianceBlock(b, b, cov_b.data());
  covariance.GetCovarianceBlock(s, s, cov_s.data());
  const auto& e = kSymmetricEntries;
  const Mat3 S_inv = S_s.inverse();
  const double root = std::cbrt(S_s.determinant());
  Eigen::Matrix<double, 6, 6> J;
  for (int k = 0; k < 6; ++k) {
    const double trace = (e[k].row == e[k].col ? 1.0 : 2.0) * S_inv(e[k].row, e[k].col);  // tr(S_s⁻¹ ∂S_s/∂s_k)
    for (int j = 0; j < 6; ++j) J(j, k) = ((j == k ? 1.0 : 0.0) - trace * S_s(e[j].row, e[j].col) / 3.0) / root;
  }
  const Eigen::Matrix<double, 6, 6> cov_n = J * cov_s * J.transpose();
  c.hard_iron_sigma_uT = (variance * cov_b.diagonal()).cwiseMax(0.0).cwiseSqrt();
  Mat3 sigma;
  for (int k = 0; k < 6; ++k)
    sigma(e[k].row, e[k].col) = sigma(e[k].col, e[k].row) = std::sqrt(std::max(0.0, variance * cov_n(k, k)));
  c.soft_iron_sigma = sigma;
}

// Index of the nearest of the 26 directions (±1, 0)³ \ 0.
// â · R m̂ − c, R = exp(w).
struct DotProductResidual {
  DotProductResidual(const Vec3& up, const Vec3& field) : up_(up), field_(field) {}
  template <typename T>
  bool operator()(const T* const w, const T* const c, T* r) const {
    const T m[3] = {T(field_.x()), T(field_.y()), T(field_.z())};
    T Rm[3];
    ceres::AngleAxisRotatePoint(w, m, Rm);
    r[0] = T(up_.x()) * Rm[0] + T(up_.y()) * Rm[1] + T(up_.z()) * Rm[2] - c[0];
    return true;
  }
  Vec3 up_, field_;
};

int direction_bin(const Vec3& u) {
  int best = 0, idx = 0;
  double best_dot = -2.0;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const double d = Vec3(i, j, k).normalized().dot(u);
        if (d > best_dot) best_dot = d, best = idx;
        ++idx;
      }
  return best;
}

}  // namespace

MagnetometerCalibration fit_magnetometer(const Stream& stream, const MagnetometerOptions& options, Diagnostics& diagnostics,
                                         const std::filesystem::path& source) {
  MagnetometerCalibration c;
  std::vector<Vec3> m;
  m.reserve(stream.size());
  for (std::size_t i = 0; i < stream.size(); ++i) {
    const Vec3 v = stream.xyz(i);
    if (v.allFinite()) m.push_back(v);
  }
  c.samples = m.size();
  if (m.size() < options.min_samples)
    throw MeasurementError(prefix(source) + fmt::format("magnetometer calibration: {} samples, need at least {}; turn the "
                                                        "device slowly through all orientations for about 30 s",
                                                        m.size(), options.min_samples));
  Vec3 lo = m[0], hi = m[0];
  for (const auto& v : m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  c.max_min_hard_iron_uT = 0.5 * (lo + hi);
  {
    const auto [mean, sd] = norm_stats(m, [](const Vec3& v) { return v; });
    c.residual_rel_raw = sd / mean;
    const auto [mean_h, sd_h] = norm_stats(m, [&](const Vec3& v) { return Vec3(v - c.max_min_hard_iron_uT); });
    c.residual_rel_hard_iron = sd_h / mean_h;
  }

  // Coverage around the (max+min)/2 centre: a rotation about one axis leaves the field
  // directions on a cone/plane, from which no ellipsoid (and no soft iron) is determined.
  {
    Mat3 scatter = Mat3::Zero();
    std::array<int, 26> bins{};
    for (const auto& v : m) {
      const Vec3 d = v - c.max_min_hard_iron_uT;
      if (d.norm() <= 0) continue;
      const Vec3 u = d.normalized();
      scatter += u * u.transpose();
      bins[static_cast<std::size_t>(direction_bin(u))] = 1;
    }
    scatter /= static_cast<double>(m.size());
    c.spread = Eigen::SelfAdjointEigenSolver<Mat3>(scatter).eigenvalues()[0];
    int hit = 0;
    for (int b : bins) hit += b;
    c.direction_coverage = hit / 26.0;
    if (c.spread < options.min_spread)
      throw MeasurementError(prefix(source) + fmt::format(
          "magnetometer calibration: poor coverage — the field directions span only {:.0f}% of the sphere's "
          "directions and lie close to a plane (smallest spread {:.3f}, need ≥ {:.3f}; a full sphere gives 0.333); "
          "the device was turned about one axis only. Turn it through all orientations (figure-eight, every face up)",
          100 * c.direction_coverage, c.spread, options.min_spread));
    if (c.direction_coverage < options.warn_direction_coverage)
      diagnostics.warn(source, 0, fmt::format("magnetometer coverage is poor: the field directions reach {:.0f}% of 26 "
                                              "direction bins (want ≥ {:.0f}%); the soft iron may be inaccurate",
                                              100 * c.direction_coverage, 100 * options.warn_direction_coverage));
  }

  // 1. Algebraic fit on centred, scaled samples (conditioning).
  Vec3 centre = Vec3::Zero();
  for (const auto& v : m) centre += v;
  centre /= static_cast<double>(m.size());
  double scale = 0.0;
  for (const auto& v : m) scale += (v - centre).squaredNorm();
  scale = std::sqrt(scale / static_cast<double>(m.size()));
  Eigen::Matrix<double, 10, 10> DtD = Eigen::Matrix<double, 10, 10>::Zero();
  for (const auto& v : m) {
    const Vec3 p = (v - centre) / scale;
    Eigen::Matrix<double, 10, 1> d;
    d << p.x() * p.x(), p.y() * p.y(), p.z() * p.z(), 2 * p.x() * p.y(), 2 * p.x() * p.z(), 2 * p.y() * p.z(), 2 * p.x(),
        2 * p.y(), 2 * p.z(), 1.0;
    DtD += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 10, 10>> es(DtD);
  const Eigen::Matrix<double, 10, 1> v = es.eigenvectors().col(0);
  Mat3 Q;
  Q << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
  const Vec3 u(v[6], v[7], v[8]);
  const Vec3 p0 = -Q.ldlt().solve(u);
  const double r = p0.dot(Q * p0) - v[9];
  Mat3 M = Q / r;
  const Eigen::SelfAdjointEigenSolver<Mat3> em(M);
  if (!(em.eigenvalues().minCoeff() > 0.0) || !std::isfinite(r))
    throw MeasurementError(prefix(source) + fmt::format(
        "magnetometer calibration: the samples do not lie on an ellipsoid (quadric eigenvalues {:.3g}, {:.3g}, {:.3g}); "
        "the coverage is too poor or the field was disturbed (steel, magnets) during the recording",
        em.eigenvalues()[0], em.eigenvalues()[1], em.eigenvalues()[2]));
  c.hard_iron_uT = centre + scale * p0;
  M /= scale * scale;
  const Eigen::SelfAdjointEigenSolver<Mat3> eM(M);
  c.field_uT = std::pow(eM.eigenvalues().prod(), -1.0 / 6.0);
  c.semi_axes_uT = eM.eigenvalues().cwiseSqrt().cwiseInverse().reverse();
  c.soft_iron = c.field_uT * eM.operatorSqrt();

  // 3. Geometric refinement.
  if (options.refine) {
    double b[3] = {c.hard_iron_uT[0], c.hard_iron_uT[1], c.hard_iron_uT[2]};
    double s[6] = {c.soft_iron(0, 0), c.soft_iron(0, 1), c.soft_iron(0, 2), c.soft_iron(1, 1), c.soft_iron(1, 2), c.soft_iron(2, 2)};
    double f = c.field_uT;
    ceres::Problem problem;
    for (const auto& x : m)
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EllipsoidResidual, 1, 3, 6, 1>(new EllipsoidResidual(x)),
                               nullptr, b, s, &f);
    const ceres::Solver::Summary summary = solve_levenberg_marquardt(problem, 50, 1e-10);
    Mat3 S;
    S << s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5];
    const double det = S.determinant();
    if (summary.IsSolutionUsable() && det > 0 && f > 0) {
      c.hard_iron_uT = Vec3(b[0], b[1], b[2]);
      c.soft_iron = S / std::cbrt(det);
      c.field_uT = f;
      const Eigen::SelfAdjointEigenSolver<Mat3> eS(c.soft_iron);
      c.semi_axes_uT = (c.field_uT * eS.eigenvalues().cwiseInverse());
      std::sort(c.semi_axes_uT.data(), c.semi_axes_uT.data() + 3);
      const double variance = 2.0 * summary.final_cost / std::max(1.0, static_cast<double>(m.size()) - 10.0);
      refinement_sigmas(c, problem, b, s, S, variance);
    }
  }
  double ss = 0.0;
  for (const auto& x : m) ss += std::pow(c.correct(x).norm() - c.field_uT, 2);
  c.residual_rms_uT = std::sqrt(ss / static_cast<double>(m.size()));
  const auto [mean_c, sd_c] = norm_stats(m, [&](const Vec3& x) { return c.correct(x); });
  c.residual_rel = sd_c / c.field_uT;
  (void)mean_c;
  return c;
}

MagnetometerAlignment fit_magnetometer_alignment(const Stream& accelerometer, const Stream& magnetometer,
                                                 double gravity, const MagnetometerAlignmentOptions& o,
                                                 const std::filesystem::path& source) {
  // Pairs (â, m̂) at the magnetometer's instants where the accelerometer feels gravity alone.
  std::vector<Vec3> up, field;
  Mat3 spread = Mat3::Zero();
  std::size_t k = 0;
  const auto& ta = accelerometer.t;
  for (std::size_t i = 0; i < magnetometer.size() && ta.size() > 1; ++i) {
    const double t = magnetometer.t[i];
    while (k + 2 < ta.size() && ta[k + 1] <= t) ++k;
    if (t < ta[k] || t > ta[k + 1]) continue;
    const double u = (t - ta[k]) / (ta[k + 1] - ta[k]);
    const Vec3 a = (1.0 - u) * accelerometer.xyz(k) + u * accelerometer.xyz(k + 1);
    const Vec3 m = magnetometer.xyz(i);
    if (!a.allFinite() || !m.allFinite() || !(m.norm() > 0.0)) continue;
    if (std::abs(a.norm() - gravity) > o.static_tolerance * gravity) continue;
    up.push_back(a.normalized());
    field.push_back(m.normalized());
    spread += up.back() * up.back().transpose();
  }
  MagnetometerAlignment out;
  out.samples = up.size();
  if (up.size() < o.min_samples)
    throw MeasurementError(prefix(source) + fmt::format("magnetometer alignment: {} samples at rest-like acceleration "
                                                        "(within {:.0f} % of g), need at least {}",
                                                        up.size(), 100 * o.static_tolerance, o.min_samples));
  out.spread = Eigen::SelfAdjointEigenSolver<Mat3>(spread / static_cast<double>(up.size())).eigenvalues()(0);
  if (out.spread < o.min_spread)
    throw MeasurementError(prefix(source) + fmt::format("magnetometer alignment: gravity was seen from too few "
                                                        "directions (spread {:.3f}, need {}); turn the device through "
                                                        "all orientations",
                                                        out.spread, o.min_spread));
  double w[3] = {0.0, 0.0, 0.0}, c = 0.0;
  for (std::size_t i = 0; i < up.size(); ++i) c += up[i].dot(field[i]) / static_cast<double>(up.size());
  ceres::Problem problem;
  for (std::size_t i = 0; i < up.size(); ++i)
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<DotProductResidual, 1, 3, 1>(new DotProductResidual(up[i], field[i])),
        new ceres::HuberLoss(o.huber_loss), w, &c);
  const auto summary = solve_levenberg_marquardt(problem, 50, 1e-12);
  if (!summary.IsSolutionUsable())
    throw MeasurementError(prefix(source) + "magnetometer alignment: the fit did not converge");
  out.R_calibrated_magnetometer = exp_so3(Vec3(w[0], w[1], w[2]));
  out.dip_rad = std::asin(std::clamp(-c, -1.0, 1.0));
  double ss = 0.0;
  for (std::size_t i = 0; i < up.size(); ++i) {
    const double angle = std::acos(std::clamp(up[i].dot(out.R_calibrated_magnetometer * field[i]), -1.0, 1.0));
    ss += std::pow(angle - (M_PI / 2 + out.dip_rad), 2);
  }
  out.residual_rms_rad = std::sqrt(ss / static_cast<double>(up.size()));
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(co);
  const std::vector<std::pair<const double*, const double*>> blocks = {{w, w}};
  if (covariance.Compute(blocks, &problem)) {
    double cov[9];
    covariance.GetCovarianceBlock(w, w, cov);
    // Ceres' covariance takes unit residual variance; scale by the residuals' own.
    const double variance = 2.0 * summary.final_cost / std::max<double>(1.0, static_cast<double>(up.size()) - 4.0);
    out.sigma_rad = Vec3(std::sqrt(cov[0] * variance), std::sqrt(cov[4] * variance), std::sqrt(cov[8] * variance));
  }
  return out;
}

}  // namespace antpose::calibration
