// The World Magnetic Model (WMM): main field and secular variation from a spherical-harmonic
// coefficient file (WMM.COF), evaluated as in
//   Chulliat, A. et al., "The US/UK World Magnetic Model for 2025-2030: Technical Report",
//   NOAA NCEI / British Geological Survey (the WMM2020 report uses the same equations), §1.2:
//   - geodetic (WGS84) → geocentric spherical coordinates: R_c = a/sqrt(1 − e² sin²φ),
//     p = (R_c + h) cos φ, z = (R_c(1 − e²) + h) sin φ, r = sqrt(p² + z²), φ' = asin(z/r);
//   - time-adjusted Gauss coefficients g(t) = g(t0) + (t − t0) ġ, h(t) likewise;
//   - field in spherical coordinates, reference radius 6371.2 km, Schmidt semi-normalised
//     associated Legendre functions P_n^m(sin φ') and dP_n^m/dφ':
//       X' = −Σ (a/r)^(n+2) Σ (g cos mλ + h sin mλ) dP_n^m/dφ'
//       Y' =  Σ (a/r)^(n+2) Σ m (g sin mλ − h cos mλ) P_n^m / cos φ'
//       Z' = −Σ (n+1)(a/r)^(n+2) Σ (g cos mλ + h sin mλ) P_n^m
//     and the same sums with (ġ, ḣ) for the secular variation;
//   - rotation to the geodetic frame: X = X' cos(φ'−φ) − Z' sin(φ'−φ),
//     Z = X' sin(φ'−φ) + Z' cos(φ'−φ);
//   - H, F, D, I and their rates: Ḣ = (XẊ + YẎ)/H, Ḟ = (XẊ + YẎ + ZŻ)/F, Ḋ = (XẎ − YẊ)/H²,
//     İ = (HŻ − ZḢ)/F²; grid variation GV = D ∓ λ for φ ≥ 55° / φ ≤ −55°.
// At the geographic poles P_n^m / cos φ' is the report's singular Y' term. It is computed
// here from its own recursion (P_n^m / cos φ' obeys the same recursion in n), which is finite
// everywhere and equals the report's special pole formula in the limit.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "antpose/geometry/rotation.hpp"

namespace antpose {
struct Site;
}

namespace antpose::geomag {

/// WGS84 ellipsoid and the model's reference radius (km).
inline constexpr double kWgs84SemiMajorKm = 6378.137;
inline constexpr double kWgs84InverseFlattening = 298.257223563;
inline constexpr double kWmmReferenceRadiusKm = 6371.2;
/// Heights the WMM is specified for (km above the WGS84 ellipsoid).
inline constexpr double kMinAltitudeKm = -1.0;
inline constexpr double kMaxAltitudeKm = 850.0;
/// Latitude from which the grid variation is defined (polar stereographic regions).
inline constexpr double kGridVariationMinLatDeg = 55.0;

/// The magnetic elements at one place and time. Components in the local geodetic frame:
/// x north, y east, z down (nT). Angles in degrees (the model's interface), positive
/// declination east, positive inclination down. `*_dot_*` are the secular variations.
struct GeomagneticElements {
  double x_nT = 0.0;
  double y_nT = 0.0;
  double z_nT = 0.0;
  double h_nT = 0.0;  // horizontal intensity
  double f_nT = 0.0;  // total intensity
  double declination_deg = 0.0;
  double inclination_deg = 0.0;
  std::optional<double> grid_variation_deg;  // only for |lat| ≥ 55°, in (−180°, 180°]

  double x_dot_nT_per_yr = 0.0;
  double y_dot_nT_per_yr = 0.0;
  double z_dot_nT_per_yr = 0.0;
  double h_dot_nT_per_yr = 0.0;
  double f_dot_nT_per_yr = 0.0;
  double declination_dot_deg_per_yr = 0.0;  // NaN where H = 0
  double inclination_dot_deg_per_yr = 0.0;
  std::optional<double> grid_variation_dot_deg_per_yr;
};

/// One line of the coefficient file: Gauss coefficients at the epoch (nT) and their
/// secular variation (nT/yr), Schmidt semi-normalised.
struct GaussCoefficient {
  double g = 0.0;
  double h = 0.0;
  double g_dot = 0.0;
  double h_dot = 0.0;
};

class MagneticModel {
 public:
  /// Parses the text of a WMM.COF file: header "epoch name release-date", then lines
  /// "n m g h gdot hdot" for n = 1..N, m = 0..n in order, closed by a line of 9s.
  /// Throws InputError naming `source` and the 1-based line on a bad header, a malformed
  /// number, an unexpected n/m, h_n^0 ≠ 0, or missing lines.
  static MagneticModel from_cof_text(std::string_view text, const std::filesystem::path& source);
  /// Reads a COF file (e.g. WMM2020's); errors as from_cof_text, plus missing/unreadable file.
  static MagneticModel from_file(const std::filesystem::path& file);
  /// WMM2025, compiled into the library.
  static MagneticModel wmm2025();

  /// Field and secular variation at geodetic latitude/longitude (deg, WGS84), height above the
  /// WGS84 ellipsoid (km) and decimal year. Does not check the date against the model's
  /// validity (see valid_for). Throws std::invalid_argument for a latitude outside [−90, 90],
  /// a height outside [−1, 850] km, or a non-finite input.
  GeomagneticElements evaluate(double lat_deg, double lon_deg, double alt_km, double decimal_year) const;

  /// True when `decimal_year` lies in [epoch, epoch + 5), the span the model is issued for.
  bool valid_for(double decimal_year) const;
  /// A warning text for a date outside the validity span, or nothing when valid.
  std::optional<std::string> validity_warning(double decimal_year) const;

  const std::string& name() const { return name_; }          // e.g. "WMM-2025"
  const std::string& release_date() const { return release_date_; }  // as in the header
  double epoch() const { return epoch_; }                    // decimal year t0
  double valid_until() const { return epoch_ + kValidityYears; }
  int max_degree() const { return max_degree_; }
  /// Coefficient of degree n (1..max_degree) and order m (0..n); throws std::out_of_range.
  const GaussCoefficient& coefficient(int n, int m) const;

  static constexpr double kValidityYears = 5.0;

 private:
  MagneticModel() = default;

  std::string name_;
  std::string release_date_;
  double epoch_ = 0.0;
  int max_degree_ = 0;
  std::vector<GaussCoefficient> coefficients_;  // index n(n+1)/2 + m
};

/// Decimal year as the WMM software computes it: year + (day_of_year − 1) / days_in_year
/// (so 2025-01-01 is 2025.0 and 2024-07-02 is 2024.5). Throws std::invalid_argument for a
/// month outside 1..12, a day outside the month (leap years included) or a year outside 1..9999.
double decimal_year(int year, int month, int day);
/// Same from "YYYY-MM-DD"; throws std::invalid_argument quoting the text and what was expected.
double decimal_year_from_iso(std::string_view date);
/// Today's date (UTC) as "YYYY-MM-DD".
std::string today_utc_iso();

/// The field of `elements` in the world frame ENU (x east, y north, z up; true north), in µT:
/// (Y, X, −Z) / 1000. This is what a calibrated magnetometer at rest should measure.
Vec3 field_enu_uT(const GeomagneticElements& elements);

/// What a measurement at a capture site needs from the model.
struct SiteField {
  double declination = 0.0;  // rad, positive east: true azimuth = magnetic azimuth + declination
  double declination_sigma = 0.0;  // rad, 1σ of the model's declination (declination_sigma())
  double inclination = 0.0;  // rad, positive down
  Vec3 field_enu_uT = Vec3::Zero();  // expected field, ENU true north, µT
  double decimal_year = 0.0;
  GeomagneticElements elements;
  /// Set when the site's date is outside the model's validity; the caller shows it as a warning.
  std::optional<std::string> validity_warning;
};

/// 1σ of WMM's declination (rad) where the horizontal intensity is H: the WMM2025 technical
/// report's error model (§3), σ_D = sqrt(0.26² + (5417 nT / H)²) degrees (≈ 0.37° at H = 21 µT).
double declination_sigma(double horizontal_intensity_nT);

/// Evaluates the model at a capture site (lat/lon deg, alt_m above the WGS84 ellipsoid, date
/// "YYYY-MM-DD"). Throws std::invalid_argument for a bad date or position; callers turn it into
/// an InputError naming their file.
SiteField site_field(const MagneticModel& model, const Site& site);

}  // namespace antpose::geomag
