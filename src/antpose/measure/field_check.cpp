#include "antpose/measure/field_check.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/SVD>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"

namespace antpose::measure {
namespace {

double spread(const std::vector<double>& v) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

// Tests 4 and 5: least squares y_i = a + G(h_i − h̄) for the rows y_i (k components) over the
// horizontal positions h. A walk along a line leaves one slope per component; the SVD's rank says
// how many the positions fix.
struct GradientFit {
  double change = 0.0;       // largest distance between two photos' fitted values
  double slope_norm = 0.0;   // |G| (Frobenius), per metre
  double f_statistic = 0.0;  // of the slopes against the residual
};

std::optional<GradientFit> fit_gradient(const Eigen::MatrixXd& y_rows, const std::vector<Vec3>& p_world_m) {
  const auto n = y_rows.rows(), k = y_rows.cols();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Vec3& p : p_world_m) mean += p.head<2>() / static_cast<double>(n);
  Eigen::MatrixXd A(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) A.row(i) = (p_world_m[static_cast<std::size_t>(i)].head<2>() - mean).transpose();
  const Eigen::MatrixXd y = y_rows.rowwise() - y_rows.colwise().mean();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
  svd.setThreshold(1e-3);  // slopes along less than ~0.1 % of the walk's extent are not fitted
  const auto slopes = svd.rank();
  const auto dof = n - 1 - slopes;
  if (slopes == 0 || dof < 3) return std::nullopt;
  const Eigen::MatrixXd G = svd.solve(y);  // 2 × k
  const Eigen::MatrixXd fitted = A * G;
  const double rss0 = y.squaredNorm(), rss1 = (y - fitted).squaredNorm();
  GradientFit fit;
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j) fit.change = std::max(fit.change, (fitted.row(i) - fitted.row(j)).norm());
  fit.slope_norm = G.norm();
  const double numerator = (rss0 - rss1) / static_cast<double>(slopes * k);
  fit.f_statistic = numerator / std::max(rss1 / static_cast<double>(dof * k), 1e-12 * rss0 + 1e-300);
  return fit;
}

}  // namespace

OptionProblems FieldCheckOptions::Check() const {
  OptionProblems p;
  for (const auto& [name, value] : {std::pair{"strength_tolerance", strength_tolerance},
                                    {"dip_tolerance", dip_tolerance},
                                    {"strength_spread", strength_spread},
                                    {"dip_spread", dip_spread},
                                    {"median_dip_tolerance", median_dip_tolerance},
                                    {"strength_trend", strength_trend},
                                    {"trend_significance", trend_significance},
                                    {"vector_trend", vector_trend},
                                    {"vector_trend_significance", vector_trend_significance},
                                    {"joint_tolerance", joint_tolerance},
                                    {"half_window_s", half_window_s}})
    p.require(value > 0, name, "positive");
  return p;
}

std::vector<std::optional<Vec3>> field_at_photos(const orientation::ImuData& data,
                                                 const orientation::OrientationTrack& track,
                                                 const std::vector<double>& t_photos,
                                                 const std::vector<Mat3>& R_world_device, double half_window_s) {
  if (R_world_device.size() != t_photos.size())
    throw std::invalid_argument(
        fmt::format("field_at_photos: {} attitudes for {} photos", R_world_device.size(), t_photos.size()));
  std::vector<std::optional<Vec3>> out;
  const auto& m = data.magnetometer;
  for (std::size_t k = 0; k < t_photos.size(); ++k) {
    const double t = t_photos[k];
    if (!track.contains(t)) {
      out.emplace_back(std::nullopt);
      continue;
    }
    // Each sample in the device frame at the photo's instant: R_device(t)ᵀ R_device(t_i) m_i.
    const Eigen::Quaterniond q_photo_world = track.at(t).q_world_device.conjugate();
    Vec3 sum = Vec3::Zero();
    int n = 0;
    for (std::size_t i = 0; i < m.size(); ++i)
      if (std::abs(m.t[i] - t) <= half_window_s && track.contains(m.t[i]))
        sum += q_photo_world * (track.at(m.t[i]).q_world_device * m.v[i]), ++n;
    out.push_back(n > 0 ? std::optional<Vec3>(R_world_device[k] * sum / n) : std::nullopt);
  }
  return out;
}

FieldCheck check_field(const std::vector<Vec3>& field_world_uT, const std::optional<geomag::SiteField>& site,
                       const FieldCheckOptions& o, const std::vector<Vec3>& p_world_m) {
  if (!p_world_m.empty() && p_world_m.size() != field_world_uT.size())
    throw std::invalid_argument(
        fmt::format("check_field: {} positions for {} fields", p_world_m.size(), field_world_uT.size()));
  throw_unless_ok(o.Check(), "FieldCheckOptions");
  FieldCheck c;
  for (std::size_t i = 0; i < field_world_uT.size(); ++i) {
    const Vec3& b = field_world_uT[i];
    if (!(b.norm() > 0.0)) continue;
    c.field_world_uT.push_back(b);
    c.strength_uT.push_back(b.norm());
    c.dip_rad.push_back(std::asin(std::clamp(-b.z() / b.norm(), -1.0, 1.0)));
    if (!p_world_m.empty()) c.p_world_m.push_back(p_world_m[i]);
  }
  const auto& positions = c.p_world_m;
  if (c.strength_uT.empty()) return c;
  const double f_median = median(c.strength_uT), dip_median = median(c.dip_rad);
  if (site) {
    c.wmm_strength_uT = site->elements.f_nT / 1000.0;
    c.wmm_dip_rad = site->inclination;
  }
  const double f_ref = c.wmm_strength_uT.value_or(f_median), dip_ref = c.wmm_dip_rad.value_or(dip_median);
  double seen = 0.0;
  for (std::size_t i = 0; i < c.strength_uT.size(); ++i) {
    const double df = c.strength_uT[i] - f_ref, ddip = c.dip_rad[i] - dip_ref;
    if (site) {
      c.worst_strength_fraction = std::max(c.worst_strength_fraction, std::abs(df) / f_ref);
      c.worst_dip_rad = std::max(c.worst_dip_rad, std::abs(ddip));
    }
    seen = std::max(seen, std::hypot(df, c.strength_uT[i] * ddip));  // along B, along the dip direction
  }
  c.strength_spread_fraction = spread(c.strength_uT) / f_median;
  c.dip_spread_rad = spread(c.dip_rad);
  if (site) c.median_dip_offset_rad = dip_median - site->inclination;
  std::optional<GradientFit> vector_fit;
  if (!positions.empty()) {
    const auto n = static_cast<Eigen::Index>(positions.size());
    Eigen::MatrixXd strength(n, 1), vectors(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      strength(i, 0) = c.strength_uT[static_cast<std::size_t>(i)];
      vectors.row(i) = c.field_world_uT[static_cast<std::size_t>(i)].transpose();
    }
    if (const auto fit = fit_gradient(strength, positions)) {
      c.strength_trend_fraction = fit->change / f_median;
      c.strength_gradient_uT_per_m = fit->slope_norm;
      c.trend_f_statistic = fit->f_statistic;
    }
    if ((vector_fit = fit_gradient(vectors, positions))) {
      c.vector_trend_fraction = vector_fit->change / f_median;
      c.vector_trend_f_statistic = vector_fit->f_statistic;
    }
  }

  const double wmm_ratio =
      std::max(c.worst_strength_fraction / o.strength_tolerance, c.worst_dip_rad / o.dip_tolerance);
  const double spread_ratio = std::max(c.strength_spread_fraction / o.strength_spread, c.dip_spread_rad / o.dip_spread);
  c.test_ratios = {
      wmm_ratio, spread_ratio, std::abs(c.median_dip_offset_rad) / o.median_dip_tolerance,
      std::min(c.strength_trend_fraction / o.strength_trend, c.trend_f_statistic / o.trend_significance),
      std::min(c.vector_trend_fraction / o.vector_trend, c.vector_trend_f_statistic / o.vector_trend_significance)};
  c.joint_ratio = Eigen::Map<const Eigen::Matrix<double, 5, 1>>(c.test_ratios.data()).norm();
  const bool one_test = std::ranges::any_of(c.test_ratios, [](double r) { return r > 1.0; });
  const bool jointly = c.joint_ratio > o.joint_tolerance;
  c.disturbed = one_test || jointly;
  if (!c.disturbed) return c;
  const double horizontal = f_ref * std::cos(dip_ref);
  if (vector_fit) seen = std::max(seen, vector_fit->change);
  c.heading_sigma_rad = seen / std::max(horizontal, 1e-3 * f_ref);
  const bool trend = c.test_ratios[3] > 1.0, vector_trend = c.test_ratios[4] > 1.0;
  const std::string limits = fmt::format(
      "limits {:.0f} % and {:.1f}° against WMM ({:.1f}° for the median dip), {:.1f} % and {:.1f}° over the photos",
      100 * o.strength_tolerance, rad2deg(o.dip_tolerance), rad2deg(o.median_dip_tolerance), 100 * o.strength_spread,
      rad2deg(o.dip_spread));
  const std::string against =
      site ? fmt::format(
                 "differs from the WMM's at the site by up to {:.1f} % in strength and {:.1f}° in dip (median dip "
                 "{:+.1f}°), and ",
                 100 * c.worst_strength_fraction, rad2deg(c.worst_dip_rad), rad2deg(c.median_dip_offset_rad))
           : std::string();
  std::string along =
      trend ? fmt::format(", its strength changing by {:.1f} % along the walk ({:.2f} µT/m, limit {:.1f} %)",
                          100 * c.strength_trend_fraction, c.strength_gradient_uT_per_m, 100 * o.strength_trend)
            : std::string();
  if (vector_trend)
    along += fmt::format(", the field vector changing by {:.1f} % of its strength along the walk (limit {:.1f} %)",
                         100 * c.vector_trend_fraction, 100 * o.vector_trend);
  if (!one_test)
    along += fmt::format(
        "; every test is within its limit, but together they are not (root sum of squares of each test's statistic "
        "over its limit {:.2f}, limit {:.2f})",
        c.joint_ratio, o.joint_tolerance);
  c.warnings.push_back(fmt::format(
      "magnetic disturbance: at the photos the field {}varies between them by {:.1f} % in strength and {:.1f}° in dip "
      "({}){}: steel nearby turns the compass; the azimuth's σ includes an estimated {:.1f}°, but the error may be "
      "larger",
      against, 100 * c.strength_spread_fraction, rad2deg(c.dip_spread_rad), limits, along,
      rad2deg(c.heading_sigma_rad)));
  return c;
}

}  // namespace antpose::measure
