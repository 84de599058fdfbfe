#include "antpose/geomag/earth_model.hpp"

#include <cmath>

namespace antpose::geomag {

double normal_gravity(double lat_deg, double alt_m) {
  // WGS84 (NIMA TR8350.2): γ = γe (1 + k sin²φ) / sqrt(1 − e² sin²φ).
  constexpr double gamma_e = 9.7803253359, k = 0.00193185265241, e2 = 6.69437999013e-3;
  const double s2 = std::pow(std::sin(deg2rad(lat_deg)), 2);
  return gamma_e * (1.0 + k * s2) / std::sqrt(1.0 - e2 * s2) - 3.086e-6 * alt_m;
}

Vec3 earth_rate_enu(double lat_deg) {
  constexpr double omega_e = 7.292115e-5;  // rad/s, WGS84
  const double phi = deg2rad(lat_deg);
  return {0.0, omega_e * std::cos(phi), omega_e * std::sin(phi)};
}

}  // namespace antpose::geomag
