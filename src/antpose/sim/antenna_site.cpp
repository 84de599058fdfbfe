#include "antpose/sim/antenna_site.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/geometry/attitude.hpp"
#include "antpose/sim/antenna_mounts.hpp"
#include "antpose/sim/capture_geometry.hpp"
#include "antpose/sim/random.hpp"

namespace antpose::sim {

namespace {

constexpr std::uint32_t kSiteStreams = 0x51e5u;  // make_rng's salt

double round_to_cm(double m) { return std::round(m * 100.0) / 100.0; }

PhotoDraw draw_photo(const WideSiteOptions& o, std::mt19937_64& rng) {
  PhotoDraw p;
  // Megapixels uniform in [2, min(12, native)]: a phone's resolution setting, or a resized copy.
  const double native_mp = o.native.width * static_cast<double>(o.native.height) / 1e6;
  const double hi = std::min(12.0, native_mp), lo = std::min(2.0, hi);
  const double mp = uniform(rng, lo, hi);
  p.scale = o.fixes.photo_scale.value_or(std::min(1.0, std::sqrt(mp / native_mp)));
  // The same sensor read at a lower resolution (camera::rescaled_intrinsics), as the measurement
  // assumes of photos smaller than the calibration's.
  p.camera = *camera::rescaled_intrinsics(o.native, static_cast<int>(std::lround(o.native.width * p.scale)),
                                          static_cast<int>(std::lround(o.native.height * p.scale)));
  const int jpeg = uniform_int(rng, 75, 95);
  const double blur = uniform(rng, 0.4, 1.2), noise = uniform(rng, 0.7, 2.0), exposure = uniform(rng, 0.001, 0.008);
  p.jpeg_quality = o.fixes.jpeg_quality.value_or(jpeg);
  p.blur_sigma_px = o.fixes.blur_sigma_px.value_or(blur);
  p.noise_scale = o.fixes.noise_scale.value_or(noise);
  p.exposure_s = o.fixes.exposure_s.value_or(exposure);
  return p;
}

// The radome colours of the market (grey renders of white, light grey, beige, mid and dark grey).
constexpr double kRadomeColours[] = {0.85, 0.7, 0.65, 0.5, 0.3};

// A panel: the datasheet box (the model the user names) and the hardware as it is rendered.
SimAntenna draw_panel(int k, RadomeLook look, std::mt19937_64& rng) {
  SimAntenna a;
  a.name = fmt::format("antenna-{}", k + 1);
  const double h = round_to_cm(uniform(rng, 0.6, 2.7)), w = round_to_cm(uniform(rng, 0.2, 0.5));
  const double d = std::min(round_to_cm(uniform(rng, 0.1, 0.25)), std::floor(0.9 * w * 100.0) / 100.0);
  a.model_name = fmt::format("panel-{}x{}x{}", std::lround(h * 1000), std::lround(w * 1000), std::lround(d * 1000));
  model::PanelSpec& s = a.spec;
  s.height_m = h, s.width_m = w, s.depth_m = d;
  s.edge_radius_m = uniform(rng, 0.0, std::min(0.045, 0.5 * std::min(w, d) - 0.005));
  s.bracket_width_m = uniform(rng, 0.06, std::min(0.16, w - 2 * s.edge_radius_m - 0.02));
  s.bracket_depth_m = uniform(rng, 0.04, 0.10);
  s.bracket_end_fraction = uniform(rng, 0.15, 0.30);
  const double f = s.bracket_end_fraction;
  s.bracket_height_m = uniform(rng, 0.08, std::min({0.20, (1 - 2 * f) * h - 0.02, 2 * f * h - 0.02}));
  PanelFinish& fin = a.finish;
  fin.look = look;
  fin.radome_albedo = kRadomeColours[uniform_int(rng, 0, 4)] + uniform(rng, -0.03, 0.03);
  fin.cap_reflectance = uniform(rng, 0.7, 1.05);
  fin.rib_period_m = uniform(rng, 0.02, 0.06), fin.rib_contrast = uniform(rng, 0.03, 0.12);
  // End caps on most panels, clear of the brackets by a centimetre.
  const double cap_room = f * h - s.bracket_height_m / 2 - 0.01;
  const double cap_height = uniform(rng, 0.02, 0.05), cap_thickness = uniform(rng, 0.0, 0.008);
  if (uniform(rng, 0.0, 1.0) < 0.7 && cap_room >= 0.02) {
    fin.end_cap_height_m = std::min(cap_height, cap_room);
    fin.end_cap_thickness_m = cap_thickness;
  }
  a.downtilt = deg2rad(uniform(rng, -10.0, 15.0));
  a.roll = deg2rad(uniform(rng, -5.0, 5.0));
  return a;
}

void set_azimuth(SimAntenna& a, double azimuth) {
  a.azimuth_magnetic = wrap_2pi(azimuth);
  a.R_world_antenna = rotation_from_attitude(a.azimuth_magnetic, a.downtilt, a.roll);
}

// Sectors: ~360/N apart (two panels: 180° or 120°), ±15°, each on its own arms, their centres
// ±5 cm about z_c within the setting's range.
void arrange_sectors(AntennaLayout& L, double az0, double z_c, const std::array<double, 2>& z_range,
                     std::mt19937_64& rng) {
  const int n = static_cast<int>(L.antennas.size());
  const double spacing = deg2rad(n == 2 && uniform(rng, 0.0, 1.0) < 0.5 ? 180.0 : 120.0);
  std::vector<double> arms, heights;
  for (int k = 0; k < n; ++k) {
    const double jitter = k == 0 ? 0.0 : deg2rad(uniform(rng, -15.0, 15.0));
    set_azimuth(L.antennas[static_cast<std::size_t>(k)], az0 + k * spacing + jitter);
    arms.push_back(uniform(rng, 0.08, 0.5));
    heights.push_back(std::clamp(z_c + uniform(rng, -0.05, 0.05), z_range[0], z_range[1]));
  }
  mount_sectors(L, arms, heights);
}

// Side by side on a frame: azimuths within 10° of each other, pipes 0.3–1.0 m apart and never
// closer than the panels' half widths plus 5 cm. False when the draw is impossible.
bool arrange_side_by_side(AntennaLayout& L, double az0, double z_c, std::mt19937_64& rng) {
  const std::size_t n = L.antennas.size();
  std::vector<double> az{az0};
  for (std::size_t k = 1; k < n; ++k) az.push_back(az0 + deg2rad(uniform(rng, -10.0, 10.0)));
  const auto [lo, hi] = std::minmax_element(az.begin(), az.end());
  if (*hi - *lo > deg2rad(10.0)) return false;
  FrameSpec f;
  f.offsets_m = {0.0};
  for (std::size_t k = 1; k < n; ++k) {
    const double min_gap = 0.5 * (L.antennas[k - 1].spec.width_m + L.antennas[k].spec.width_m) + 0.05;
    f.offsets_m.push_back(f.offsets_m.back() + uniform(rng, std::max(0.3, min_gap), 1.0));
  }
  const double middle = 0.5 * (f.offsets_m.front() + f.offsets_m.back());
  for (double& o : f.offsets_m) o -= middle;
  double sum = 0.0;
  for (std::size_t k = 0; k < n; ++k) set_azimuth(L.antennas[k], az[k]), sum += az[k];
  f.facing = sum / static_cast<double>(n);
  f.standoff_m = uniform(rng, 0.15, 0.6);
  f.pipe_radius_m = uniform(rng, 0.025, 0.045), f.bar_radius_m = uniform(rng, 0.025, 0.04);
  f.z_m = z_c;
  std::vector<double> arms;
  for (std::size_t k = 0; k < n; ++k) arms.push_back(uniform(rng, 0.08, 0.25));
  return mount_side_by_side(L, f, arms);
}

// The mast, the panels and how they hang; nullopt when parts would intersect.
std::optional<AntennaLayout> draw_layout(const WideSiteOptions& o, std::mt19937_64& rng) {
  AntennaLayout L;
  L.setting = o.setting;
  const bool roof = o.setting == AntennaSetting::kRooftop;
  // A rooftop pipe of 60–160 mm or a ground monopole of 0.4–0.9 m.
  L.mast_radius_m = roof ? uniform(rng, 0.03, 0.08) : uniform(rng, 0.2, 0.45);
  L.building_height_m = roof ? uniform(rng, 15.0, 30.0) : 0.0;
  const std::array<double, 2> z_range = roof ? std::array<double, 2>{1.5, 4.0} : std::array<double, 2>{8.0, 30.0};
  const double z_c = uniform(rng, z_range[0], z_range[1]);
  L.metal_albedo = uniform(rng, 0.35, 0.55);
  const auto arrangement = static_cast<Arrangement>(uniform_int(rng, 0, 1));
  const auto look = static_cast<RadomeLook>(uniform_int(rng, 0, 2));
  for (int k = 0; k < o.antennas; ++k) L.antennas.push_back(draw_panel(k, o.fixes.radome.value_or(look), rng));
  const double az0 = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  if (o.fixes.arrangement.value_or(arrangement) == Arrangement::kSectors)
    arrange_sectors(L, az0, z_c, z_range, rng);
  else if (!arrange_side_by_side(L, az0, z_c, rng))
    return std::nullopt;
  if (layout_collides(L, 0.01, 0.3)) return std::nullopt;
  double top = 0.0;
  for (const auto& a : L.antennas) top = std::max(top, a.p_world_antenna.z() + a.spec.height_m / 2);
  L.mast_top_m = top + (roof ? 0.3 : 1.0);
  return L;
}

// The walk: its distance from the antenna 1's target width in the photos, the board before its
// middle; nullopt when the distance leaves the setting's range (rooftop 3–20 m, ground 10–60 m)
// or the board would not stand 1.5 m before the mast.
std::optional<WalkDraw> draw_walk(const WideSiteOptions& o, const AntennaLayout& L, const PhotoDraw& photo,
                                  std::mt19937_64& rng) {
  const bool roof = o.setting == AntennaSetting::kRooftop;
  WalkDraw w;
  w.target_width_px = std::exp(uniform(rng, std::log(60.0), std::log(400.0)));
  w.azimuth = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  w.height_m = uniform(rng, 1.4, 1.7);
  // Range r to antenna 1 for its width to span the target: fx · width / r.
  const SimAntenna& a = L.antennas.front();
  const double range = photo.camera.fx * a.spec.width_m / w.target_width_px;
  const double rise = a.p_world_antenna.z() - w.height_m;
  if (range <= std::abs(rise)) return std::nullopt;
  const double horizontal = std::sqrt(range * range - rise * rise);
  // The walk's middle D u at that horizontal distance from the antenna: |D u − p| = horizontal.
  const Vec3 u = heading(w.azimuth);
  const Vec3 p(a.p_world_antenna.x(), a.p_world_antenna.y(), 0.0);
  const double along = u.dot(p), across2 = p.squaredNorm() - along * along;
  if (horizontal * horizontal <= across2) return std::nullopt;
  w.distance_m = along + std::sqrt(horizontal * horizontal - across2);
  if (w.distance_m < (roof ? 3.0 : 10.0) || w.distance_m > (roof ? 20.0 : 60.0)) return std::nullopt;
  const double board_max = uniform(rng, 3.5, 6.0);
  w.board_max_m = o.fixes.board_max_distance_m.value_or(board_max);
  const double ahead = w.board_max_m * uniform(rng, 0.55, 0.85), lateral = uniform(rng, -0.3, 0.3);
  const double board_z = roof ? uniform(rng, 1.2, 1.6) : uniform(rng, 1.5, 1.9);
  if (w.distance_m - ahead < 1.5) return std::nullopt;
  w.board_centre = (w.distance_m - ahead) * u + lateral * u.cross(Vec3::UnitZ());
  w.board_centre.z() = board_z;
  for (int k = 0; k < o.photos; ++k) {
    w.holds_s.push_back(uniform(rng, 0.3, 2.0));
    w.instants.push_back(uniform(rng, 0.15, 0.85));
  }
  w.walk_speed_m_s = uniform(rng, 0.5, 1.3);
  w.bob.frequency_hz = uniform(rng, 1.6, 2.2);
  w.bob.amplitude_m = uniform(rng, 0.01, 0.03);
  w.tremor_deg = uniform(rng, 0.03, 0.15);
  return w;
}

}  // namespace

Vec3 walk_middle(const WalkDraw& w) { return w.distance_m * heading(w.azimuth) + Vec3(0.0, 0.0, w.height_m); }

void validate(const WideSiteFixes& f) {
  const auto check = [](const auto& value, double lo, double hi, const char* flag, const char* unit) {
    if (value && !(*value >= lo && *value <= hi))
      throw InputError(flag, fmt::format("{}{} is outside {}..{}", *value, unit, lo, hi));
  };
  check(f.photo_scale, 0.25, 1.0, "--photo-scale", " (of the native size)");
  check(f.board_max_distance_m, 2.5, 15.0, "--board-max-distance", " m");
  check(f.time_offset_s, -1.0, 1.0, "--time-offset-ms", " s");
  check(f.jpeg_quality, 1, 100, "--jpeg-quality", "");
  check(f.blur_sigma_px, 0.0, 20.0, "--blur-px", " px");
  check(f.noise_scale, 0.0, 100.0, "--noise", "");
  check(f.exposure_s, 0.0, 0.2, "--exposure-ms", " s");
}

SiteDraw draw_wide_site(std::uint64_t seed, const WideSiteOptions& o, int attempt) {
  validate(o.fixes);
  if (o.antennas < 1 || o.antennas > 3) throw std::invalid_argument(fmt::format("{} antennas: 1..3", o.antennas));
  if (const auto why = o.native.invalid_reason()) throw std::invalid_argument("draw_wide_site: native camera " + *why);
  auto rng = make_rng(seed, static_cast<std::uint64_t>(attempt), kSiteStreams);
  for (int draw = 0; draw < 1000; ++draw) {
    SiteDraw s;
    s.attempt = attempt;
    s.photo = draw_photo(o, rng);
    s.light = draw_site_light(o.fixes.light, rng);
    auto layout = draw_layout(o, rng);
    if (!layout) continue;
    s.layout = std::move(*layout);
    // The walk again for the same site first: a small photo or a low panel rules out only part of
    // the target widths, and redrawing the whole site would skew the photo sizes towards 12 MP.
    std::optional<WalkDraw> walk;
    for (int tries = 0; tries < 20 && !walk; ++tries) walk = draw_walk(o, s.layout, s.photo, rng);
    if (!walk) continue;
    s.walk = *walk;
    const bool roof = o.setting == AntennaSetting::kRooftop;
    s.roof_half_m = roof ? s.walk.distance_m + 6.0 : 0.0;
    Vec3 antennas_centre = Vec3::Zero();
    for (const auto& a : s.layout.antennas) antennas_centre += a.p_world_antenna / static_cast<double>(o.antennas);
    const BackgroundSite where{o.setting, s.layout.building_height_m, s.roof_half_m,
                               walk_middle(s.walk), antennas_centre};
    const auto kind = static_cast<BackgroundKind>(uniform_int(rng, 0, 2));
    s.background = draw_background(o.fixes.background.value_or(kind), where, rng);
    if (s.background.kind == BackgroundKind::kTrees && s.background.trees.empty()) continue;  // none shows
    for (int k = 0; k < o.antennas; ++k) {
      RoiDraw r;
      for (double& m : r.margin_fraction) m = uniform(rng, 0.03, 0.15);
      r.pick = uniform(rng, 0.0, 1.0);
      s.roi.push_back(r);
    }
    const double offset = uniform(rng, -0.15, 0.15);
    s.time_offset_s = o.fixes.time_offset_s.value_or(offset);
    return s;
  }
  throw std::runtime_error(fmt::format(
      "no wide {} site fits in 1000 draws ({} x {} px native{}, {} antennas): in photos this small no antenna is "
      "60-400 px wide at the setting's distances (rooftop 3-20 m, ground 10-60 m), or the fixed choices exclude "
      "each other",
      to_string(o.setting), o.native.width, o.native.height,
      o.fixes.photo_scale ? fmt::format(", photos {} of it", *o.fixes.photo_scale) : std::string(), o.antennas));
}

}  // namespace antpose::sim
