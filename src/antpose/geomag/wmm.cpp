#include "antpose/geomag/wmm.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <ctime>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/text_file.hpp"

namespace antpose::embedded {
extern const char* const kWmm2025Cof;
}

namespace antpose::geomag {
namespace {

std::size_t triangle_index(int n, int m) { return static_cast<std::size_t>(n * (n + 1) / 2 + m); }

std::vector<std::string_view> split_whitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

int parse_int(std::string_view text, const std::filesystem::path& source, std::size_t line, std::string_view column) {
  int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size())
    throw InputError(source, line, fmt::format("column '{}': '{}' is not an integer", column, text));
  return value;
}

bool is_terminator(std::string_view first_token) { return first_token.starts_with("9999"); }

// Reduces an angle in degrees to (−180, 180].
double wrap_180(double deg) {
  double x = std::fmod(deg, 360.0);
  if (x <= -180.0) x += 360.0;
  if (x > 180.0) x -= 360.0;
  return x;
}

bool is_leap(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int days_in_month(int year, int month) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return month == 2 && is_leap(year) ? 29 : kDays[month - 1];
}

}  // namespace

MagneticModel MagneticModel::from_cof_text(std::string_view text, const std::filesystem::path& source) {
  MagneticModel model;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  bool have_header = false;
  bool terminated = false;
  int expect_n = 1;
  int expect_m = 0;
  std::size_t last_line = 0;
  while (pos < text.size() && !terminated) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const auto tokens = split_whitespace(line);
    if (tokens.empty()) continue;
    last_line = line_no;

    if (!have_header) {
      if (tokens.size() < 2 || tokens.size() > 3)
        throw InputError(source, line_no,
                         fmt::format("bad header '{}': expected 'epoch model-name [release-date]', e.g. "
                                     "'2025.0 WMM-2025 11/13/2024'",
                                     line));
      model.epoch_ = io::parse_number(tokens[0], source, line_no, "epoch");
      model.name_ = std::string(tokens[1]);
      if (tokens.size() == 3) model.release_date_ = std::string(tokens[2]);
      have_header = true;
      continue;
    }

    if (is_terminator(tokens[0])) {
      if (expect_m != 0)
        throw InputError(source, line_no,
                         fmt::format("coefficients end inside degree {}: missing lines from n={} m={} to m={}",
                                     expect_n, expect_n, expect_m, expect_n));
      if (expect_n == 1) throw InputError(source, line_no, "no coefficient lines before the closing line of 9s");
      terminated = true;
      break;
    }
    if (tokens.size() != 6)
      throw InputError(source, line_no,
                       fmt::format("{} fields, expected 6 ('n m g h gdot hdot') in '{}'", tokens.size(), line));
    const int n = parse_int(tokens[0], source, line_no, "n");
    const int m = parse_int(tokens[1], source, line_no, "m");
    if (n != expect_n || m != expect_m)
      throw InputError(source, line_no,
                       fmt::format("unexpected degree/order n={} m={}: expected n={} m={} (lines must run "
                                   "n = 1, 2, ... with m = 0..n; a line may be missing)",
                                   n, m, expect_n, expect_m));
    GaussCoefficient c;
    c.g = io::parse_number(tokens[2], source, line_no, "g");
    c.h = io::parse_number(tokens[3], source, line_no, "h");
    c.g_dot = io::parse_number(tokens[4], source, line_no, "gdot");
    c.h_dot = io::parse_number(tokens[5], source, line_no, "hdot");
    if (m == 0 && (c.h != 0.0 || c.h_dot != 0.0))
      throw InputError(source, line_no,
                       fmt::format("h and hdot must be 0 for m=0 (n={}), found {} and {}", n, tokens[3], tokens[5]));
    if (model.coefficients_.empty()) model.coefficients_.push_back({});  // n = 0 has no term
    model.coefficients_.push_back(c);
    model.max_degree_ = n;
    if (++expect_m > expect_n) {
      ++expect_n;
      expect_m = 0;
    }
  }
  if (!have_header)
    throw InputError(source, "empty coefficient file, expected a header 'epoch model-name release-date'");
  if (!terminated)
    throw InputError(source, last_line,
                     fmt::format("missing lines: the file ends after n={} m={} without the closing line of 9s "
                                 "(truncated file?)",
                                 expect_m == 0 ? expect_n - 1 : expect_n, expect_m == 0 ? expect_n - 1 : expect_m - 1));
  return model;
}

MagneticModel MagneticModel::from_file(const std::filesystem::path& file) {
  return from_cof_text(io::read_text(file), file);
}

MagneticModel MagneticModel::wmm2025() {
  return from_cof_text(embedded::kWmm2025Cof, "WMM2025.COF (built in)");
}

const GaussCoefficient& MagneticModel::coefficient(int n, int m) const {
  if (n < 1 || n > max_degree_ || m < 0 || m > n)
    throw std::out_of_range(fmt::format("{}: no coefficient n={} m={} (degree 1..{})", name_, n, m, max_degree_));
  return coefficients_[triangle_index(n, m)];
}

bool MagneticModel::valid_for(double year) const { return year >= epoch_ && year < valid_until(); }

std::optional<std::string> MagneticModel::validity_warning(double year) const {
  if (valid_for(year)) return std::nullopt;
  return fmt::format("date {:.3f} is outside the validity of {} ({:.1f} to {:.1f}); its declination is extrapolated "
                     "and may be off by more than the model's stated uncertainty",
                     year, name_, epoch_, valid_until());
}

GeomagneticElements MagneticModel::evaluate(double lat_deg, double lon_deg, double alt_km, double year) const {
  if (!std::isfinite(lat_deg) || lat_deg < -90.0 || lat_deg > 90.0)
    throw std::invalid_argument(fmt::format("latitude {} deg is outside [-90, 90]", lat_deg));
  // Beyond one turn either way a longitude is a typing error, and at 1e16° its sine is noise.
  if (!std::isfinite(lon_deg) || lon_deg < -360.0 || lon_deg > 360.0)
    throw std::invalid_argument(fmt::format("longitude {} deg is outside [-360, 360]", lon_deg));
  if (!std::isfinite(alt_km) || alt_km < kMinAltitudeKm || alt_km > kMaxAltitudeKm)
    throw std::invalid_argument(fmt::format("height {} km is outside the model's range [{}, {}] km above the WGS84 "
                                            "ellipsoid",
                                            alt_km, kMinAltitudeKm, kMaxAltitudeKm));
  if (!std::isfinite(year)) throw std::invalid_argument(fmt::format("decimal year {} is not finite", year));

  // Geodetic → geocentric spherical (WGS84).
  const double lat = deg2rad(lat_deg);
  const double lon = deg2rad(lon_deg);
  const double flattening = 1.0 / kWgs84InverseFlattening;
  const double e2 = flattening * (2.0 - flattening);
  const double sin_lat = std::sin(lat);
  const double cos_lat = std::cos(lat);
  const double rc = kWgs84SemiMajorKm / std::sqrt(1.0 - e2 * sin_lat * sin_lat);
  const double p = (rc + alt_km) * cos_lat;
  const double z = (rc * (1.0 - e2) + alt_km) * sin_lat;
  const double r = std::hypot(p, z);
  const double s = z / r;  // sin φ'
  const double c = p / r;  // cos φ' (≥ 0; ~1e-17 at the poles, never divided by)
  const double psi = std::atan2(z, p) - lat;  // φ' − φ

  const double dt = year - epoch_;
  const double ratio = kWmmReferenceRadiusKm / r;
  const double cos_lon = std::cos(lon);
  const double sin_lon = std::sin(lon);

  double xs = 0, ys = 0, zs = 0;        // X', Y', Z'
  double xs_d = 0, ys_d = 0, zs_d = 0;  // their rates
  double cos_ml = 1.0, sin_ml = 0.0;    // cos mλ, sin mλ
  double p_mm = 1.0;                    // P_m^m (Schmidt), starting at P_0^0
  double pow_m = ratio * ratio;         // (a/r)^(m+2)
  for (int m = 0; m <= max_degree_; ++m) {
    // Sectoral seeds. Q = P / cos φ' (m ≥ 1) carries the 1/cos φ' of Y' without dividing.
    double q_mm = 0.0, d_mm = 0.0;
    if (m >= 1) {
      const double k = m == 1 ? 1.0 : std::sqrt((2.0 * m - 1.0) / (2.0 * m));
      q_mm = k * p_mm;  // P_m^m = k cos φ' P_{m−1}^{m−1}
      p_mm = c * q_mm;
      d_mm = -m * s * q_mm;  // d/dφ' of const·cos^m φ'
    }
    double p1 = p_mm, d1 = d_mm, q1 = q_mm;  // degree n−1 after the first step
    double p2 = 0.0, d2 = 0.0, q2 = 0.0;     // degree n−2
    double pw = pow_m;
    for (int n = m; n <= max_degree_; ++n) {
      double pn = p_mm, dn = d_mm, qn = q_mm;
      if (n > m) {
        const double nn = n, mm = m;
        const double denom = std::sqrt(nn * nn - mm * mm);
        const double a = (2.0 * nn - 1.0) / denom;
        const double b = std::sqrt((nn - 1.0) * (nn - 1.0) - mm * mm) / denom;
        pn = a * s * p1 - b * p2;
        dn = a * (c * p1 + s * d1) - b * d2;
        qn = a * s * q1 - b * q2;
        p2 = p1, d2 = d1, q2 = q1;
        p1 = pn, d1 = dn, q1 = qn;
      }
      if (n >= 1) {
        const GaussCoefficient& k = coefficients_[triangle_index(n, m)];
        const double g = k.g + dt * k.g_dot;
        const double h = k.h + dt * k.h_dot;
        const double a_main = g * cos_ml + h * sin_ml;
        const double a_sv = k.g_dot * cos_ml + k.h_dot * sin_ml;
        xs -= pw * a_main * dn;
        xs_d -= pw * a_sv * dn;
        zs -= (n + 1) * pw * a_main * pn;
        zs_d -= (n + 1) * pw * a_sv * pn;
        if (m >= 1) {
          ys += pw * m * (g * sin_ml - h * cos_ml) * qn;
          ys_d += pw * m * (k.g_dot * sin_ml - k.h_dot * cos_ml) * qn;
        }
      }
      pw *= ratio;
    }
    pow_m *= ratio;
    const double cos_next = cos_ml * cos_lon - sin_ml * sin_lon;
    sin_ml = sin_ml * cos_lon + cos_ml * sin_lon;
    cos_ml = cos_next;
  }

  // Spherical → geodetic frame.
  const double cp = std::cos(psi);
  const double sp = std::sin(psi);
  GeomagneticElements e;
  e.x_nT = xs * cp - zs * sp;
  e.y_nT = ys;
  e.z_nT = xs * sp + zs * cp;
  e.x_dot_nT_per_yr = xs_d * cp - zs_d * sp;
  e.y_dot_nT_per_yr = ys_d;
  e.z_dot_nT_per_yr = xs_d * sp + zs_d * cp;

  const double X = e.x_nT, Y = e.y_nT, Z = e.z_nT;
  const double dX = e.x_dot_nT_per_yr, dY = e.y_dot_nT_per_yr, dZ = e.z_dot_nT_per_yr;
  const double H = std::hypot(X, Y);
  const double F = std::hypot(H, Z);
  e.h_nT = H;
  e.f_nT = F;
  e.declination_deg = rad2deg(std::atan2(Y, X));
  e.inclination_deg = rad2deg(std::atan2(Z, H));
  e.h_dot_nT_per_yr = H > 0.0 ? (X * dX + Y * dY) / H : 0.0;
  e.f_dot_nT_per_yr = (X * dX + Y * dY + Z * dZ) / F;
  e.declination_dot_deg_per_yr =
      H > 0.0 ? rad2deg((X * dY - Y * dX) / (H * H)) : std::numeric_limits<double>::quiet_NaN();
  e.inclination_dot_deg_per_yr = rad2deg((H * dZ - Z * e.h_dot_nT_per_yr) / (F * F));

  if (lat_deg >= kGridVariationMinLatDeg) {
    e.grid_variation_deg = wrap_180(e.declination_deg - lon_deg);
  } else if (lat_deg <= -kGridVariationMinLatDeg) {
    e.grid_variation_deg = wrap_180(e.declination_deg + lon_deg);
  }
  if (e.grid_variation_deg) e.grid_variation_dot_deg_per_yr = e.declination_dot_deg_per_yr;
  return e;
}

double decimal_year(int year, int month, int day) {
  if (year < 1 || year > 9999) throw std::invalid_argument(fmt::format("year {} is outside 1..9999", year));
  if (month < 1 || month > 12) throw std::invalid_argument(fmt::format("month {} is outside 1..12", month));
  const int dim = days_in_month(year, month);
  if (day < 1 || day > dim)
    throw std::invalid_argument(fmt::format("day {} is outside 1..{} for {:04d}-{:02d}", day, dim, year, month));
  int day_of_year = day;
  for (int k = 1; k < month; ++k) day_of_year += days_in_month(year, k);
  const double days_in_year = is_leap(year) ? 366.0 : 365.0;
  return year + (day_of_year - 1) / days_in_year;
}

double decimal_year_from_iso(std::string_view date) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument(fmt::format("'{}' is not a valid date: {} (expected YYYY-MM-DD)", date, why));
  };
  const bool shape_ok = date.size() == 10 && date[4] == '-' && date[7] == '-';
  if (!shape_ok) throw bad("wrong format");
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 8, 9})
    if (date[i] < '0' || date[i] > '9') throw bad("wrong format");
  const auto num = [&](std::size_t at, std::size_t len) {
    int v = 0;
    std::from_chars(date.data() + at, date.data() + at + len, v);
    return v;
  };
  try {
    return decimal_year(num(0, 4), num(5, 2), num(8, 2));
  } catch (const std::invalid_argument& e) {
    throw bad(e.what());
  }
}

std::string today_utc_iso() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  return fmt::format("{:04d}-{:02d}-{:02d}", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday);
}

Vec3 field_enu_uT(const GeomagneticElements& e) { return Vec3(e.y_nT, e.x_nT, -e.z_nT) / 1000.0; }

double declination_sigma(double horizontal_intensity_nT) {
  return deg2rad(std::hypot(0.26, 5417.0 / std::max(horizontal_intensity_nT, 1.0)));
}

SiteField site_field(const MagneticModel& model, const Site& site) {
  if (site.date.empty()) throw std::invalid_argument("the site has no date (YYYY-MM-DD) for the magnetic model");
  SiteField out;
  out.decimal_year = decimal_year_from_iso(site.date);
  out.elements = model.evaluate(site.lat_deg, site.lon_deg, site.alt_m / 1000.0, out.decimal_year);
  out.declination = deg2rad(out.elements.declination_deg);
  out.declination_sigma = declination_sigma(out.elements.h_nT);
  out.inclination = deg2rad(out.elements.inclination_deg);
  out.field_enu_uT = field_enu_uT(out.elements);
  out.validity_warning = model.validity_warning(out.decimal_year);
  return out;
}

}  // namespace antpose::geomag
