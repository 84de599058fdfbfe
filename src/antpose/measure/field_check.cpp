#include "antpose/measure/field_check.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"

namespace antpose::measure {
namespace {

double spread(const std::vector<double>& v) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

}  // namespace

std::vector<Vec3> field_at_photos(const orientation::ImuData& data, const orientation::OrientationTrack& track,
                                  const std::vector<double>& t_photos, double half_window_s) {
  std::vector<Vec3> out;
  const auto& m = data.magnetometer;
  for (const double t : t_photos) {
    Vec3 sum = Vec3::Zero();
    int n = 0;
    for (std::size_t i = 0; i < m.size(); ++i)
      if (std::abs(m.t[i] - t) <= half_window_s && track.contains(m.t[i]))
        sum += track.at(m.t[i]).q_world_device * m.v[i], ++n;
    if (n > 0) out.push_back(sum / n);
  }
  return out;
}

FieldCheck check_field(const std::vector<Vec3>& field_world_uT, const std::optional<geomag::SiteField>& site,
                       const FieldCheckOptions& o) {
  FieldCheck c;
  for (const Vec3& b : field_world_uT) {
    if (!(b.norm() > 0.0)) continue;
    c.strength_uT.push_back(b.norm());
    c.dip_rad.push_back(std::asin(std::clamp(-b.z() / b.norm(), -1.0, 1.0)));
  }
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

  const bool off_earth = c.worst_strength_fraction > o.strength_tolerance || c.worst_dip_rad > o.dip_tolerance;
  const bool uneven = c.strength_spread_fraction > o.strength_spread || c.dip_spread_rad > o.dip_spread;
  c.disturbed = off_earth || uneven;
  if (!c.disturbed) return c;
  const double horizontal = f_ref * std::cos(dip_ref);
  c.heading_sigma_rad = seen / std::max(horizontal, 1e-3 * f_ref);
  const std::string limits =
      fmt::format("limits {:.0f} % and {:.1f}° against WMM, {:.1f} % and {:.1f}° over the photos",
                  100 * o.strength_tolerance, rad2deg(o.dip_tolerance), 100 * o.strength_spread, rad2deg(o.dip_spread));
  const std::string against =
      site ? fmt::format("differs from the WMM's at the site by up to {:.1f} % in strength and {:.1f}° in dip, and ",
                         100 * c.worst_strength_fraction, rad2deg(c.worst_dip_rad))
           : std::string();
  c.warnings.push_back(fmt::format(
      "magnetic disturbance: at the photos the field {}varies between them by {:.1f} % in strength and {:.1f}° in dip "
      "({}): steel nearby turns the compass; the azimuth's σ includes an estimated {:.1f}°, but the error may be "
      "larger",
      against, 100 * c.strength_spread_fraction, rad2deg(c.dip_spread_rad), limits, rad2deg(c.heading_sigma_rad)));
  return c;
}

}  // namespace antpose::measure
