// antpose wmm: magnetic declination and field of the World Magnetic Model at one place and date.
#include <charconv>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/geomag/wmm.hpp"
#include "antpose/io/text_file.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"

namespace antpose::cli {
namespace {

struct WmmOptions {
  std::string lat;
  std::string lon;
  std::string alt_km = "0";
  std::string date;
  std::string cof;
  std::string json;
};

double parse_option_number(const std::string& option, const std::string& text, const char* expected) {
  double value = 0.0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (text.empty() || ec != std::errc() || ptr != last || !std::isfinite(value))
    throw InputError({}, fmt::format("{} '{}' is not a number (expected {})", option, text, expected));
  return value;
}

nlohmann::json optional_json(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(); }

void run_wmm(const WmmOptions& o, const CLI::App& verb) {
  const double lat = parse_option_number("--lat", o.lat, "degrees in [-90, 90], north positive");
  const double lon = parse_option_number("--lon", o.lon, "degrees, east positive");
  const double alt_km = parse_option_number("--alt-km", o.alt_km, "km above the WGS84 ellipsoid");
  if (lat < -90.0 || lat > 90.0)
    throw InputError({}, fmt::format("--lat {}: latitude must be within [-90, 90] degrees", o.lat));
  if (lon < -360.0 || lon > 360.0)  // one turn either way; beyond, a typing error
    throw InputError({}, fmt::format("--lon {}: longitude must be within [-360, 360] degrees (east positive)", o.lon));
  if (alt_km < geomag::kMinAltitudeKm || alt_km > geomag::kMaxAltitudeKm)
    throw InputError({}, fmt::format("--alt-km {}: height must be within [{}, {}] km above the WGS84 ellipsoid",
                                     o.alt_km, geomag::kMinAltitudeKm, geomag::kMaxAltitudeKm));
  const std::string date = o.date.empty() ? geomag::today_utc_iso() : o.date;
  double year = 0.0;
  try {
    year = geomag::decimal_year_from_iso(date);
  } catch (const std::invalid_argument& e) {
    throw InputError({}, fmt::format("--date: {}", e.what()));
  }

  const auto model = o.cof.empty() ? geomag::MagneticModel::wmm2025() : geomag::MagneticModel::from_file(o.cof);
  const auto e = model.evaluate(lat, lon, alt_km, year);

  Diagnostics diagnostics;
  if (auto w = model.validity_warning(year)) diagnostics.warn(*w);

  fmt::print("model:            {} (epoch {:.1f}, valid {:.1f} to {:.1f}; {})\n", model.name(), model.epoch(),
             model.epoch(), model.valid_until(), o.cof.empty() ? std::string("built in") : o.cof);
  fmt::print("site:             lat {} deg, lon {} deg, {} km above the WGS84 ellipsoid\n", lat, lon, alt_km);
  fmt::print("date:             {} (decimal year {:.4f})\n", date, year);
  fmt::print("declination D:    {:9.2f} deg    ({:+.2f} deg/yr; positive east)\n", e.declination_deg,
             e.declination_dot_deg_per_yr);
  fmt::print("inclination I:    {:9.2f} deg    ({:+.2f} deg/yr; positive down)\n", e.inclination_deg,
             e.inclination_dot_deg_per_yr);
  fmt::print("horizontal H:     {:9.1f} nT     ({:+.1f} nT/yr)\n", e.h_nT, e.h_dot_nT_per_yr);
  fmt::print("total F:          {:9.1f} nT     ({:+.1f} nT/yr)\n", e.f_nT, e.f_dot_nT_per_yr);
  fmt::print("north X:          {:9.1f} nT     ({:+.1f} nT/yr)\n", e.x_nT, e.x_dot_nT_per_yr);
  fmt::print("east Y:           {:9.1f} nT     ({:+.1f} nT/yr)\n", e.y_nT, e.y_dot_nT_per_yr);
  fmt::print("down Z:           {:9.1f} nT     ({:+.1f} nT/yr)\n", e.z_nT, e.z_dot_nT_per_yr);
  if (e.grid_variation_deg)
    fmt::print("grid variation:   {:9.2f} deg\n", *e.grid_variation_deg);
  else
    fmt::print("grid variation:   not defined (|lat| < {} deg)\n", geomag::kGridVariationMinLatDeg);

  if (!o.json.empty()) {
    nlohmann::json j;
    j["model"] = {{"name", model.name()},
                  {"epoch_year", model.epoch()},
                  {"valid_until_year", model.valid_until()},
                  {"source", o.cof.empty() ? std::string("built in") : o.cof}};
    j["site"] = {{"lat_deg", lat}, {"lon_deg", lon}, {"alt_km", alt_km}, {"date", date}, {"decimal_year", year}};
    j["valid_date"] = model.valid_for(year);
    j["declination_deg"] = e.declination_deg;
    j["inclination_deg"] = e.inclination_deg;
    j["grid_variation_deg"] = optional_json(e.grid_variation_deg);
    j["h_nT"] = e.h_nT;
    j["f_nT"] = e.f_nT;
    j["x_nT"] = e.x_nT;
    j["y_nT"] = e.y_nT;
    j["z_nT"] = e.z_nT;
    j["per_year"] = {{"declination_deg", e.declination_dot_deg_per_yr},
                     {"inclination_deg", e.inclination_dot_deg_per_yr},
                     {"grid_variation_deg", optional_json(e.grid_variation_dot_deg_per_yr)},
                     {"h_nT", e.h_dot_nT_per_yr},
                     {"f_nT", e.f_dot_nT_per_yr},
                     {"x_nT", e.x_dot_nT_per_yr},
                     {"y_nT", e.y_dot_nT_per_yr},
                     {"z_nT", e.z_dot_nT_per_yr}};
    j["warnings"] = nlohmann::json::array();
    for (const auto& w : diagnostics.warnings()) j["warnings"].push_back(w.to_string());
    store::Provenance provenance = provenance_of(verb);
    if (!o.cof.empty()) provenance.input("coefficients", o.cof);
    write_json(o.json, j, provenance);
  }
  print_warnings(diagnostics);
}

}  // namespace

void add_wmm_command(CLI::App& app) {
  auto opts = std::make_shared<WmmOptions>();
  auto* cmd = app.add_subcommand("wmm", "Magnetic declination and field from the World Magnetic Model (WMM2025)");
  cmd->add_option("--lat", opts->lat, "Geodetic latitude, degrees north (WGS84)")->required();
  cmd->add_option("--lon", opts->lon, "Longitude, degrees east")->required();
  cmd->add_option("--alt-km", opts->alt_km, "Height above the WGS84 ellipsoid, km (default 0)");
  cmd->add_option("--date", opts->date, "Date YYYY-MM-DD (default: today, UTC)");
  cmd->add_option("--cof", opts->cof, "Coefficient file (WMM.COF) instead of the built-in WMM2025");
  add_json_option(cmd, opts->json, "also write the result");
  cmd->callback([opts, cmd] { run_wmm(*opts, *cmd); });
}

}  // namespace antpose::cli
