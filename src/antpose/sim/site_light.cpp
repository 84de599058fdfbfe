#include "antpose/sim/site_light.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/random.hpp"

namespace antpose::sim {

std::string to_string(LightMode mode) {
  switch (mode) {
    case LightMode::kSun:
      return "sun";
    case LightMode::kLowSun:
      return "low-sun";
    case LightMode::kOvercast:
      return "overcast";
    case LightMode::kShade:
      return "shade";
  }
  return "unknown";
}

LightMode parse_light_mode(const std::string& name) {
  for (const auto m : {LightMode::kSun, LightMode::kLowSun, LightMode::kOvercast, LightMode::kShade})
    if (to_string(m) == name) return m;
  throw InputError("--light", fmt::format("'{}' is not sun, low-sun, overcast or shade", name));
}

SiteLight draw_site_light(std::optional<LightMode> mode, std::mt19937_64& rng) {
  SiteLight s;
  const int drawn = uniform_int(rng, 0, 3);
  s.mode = mode.value_or(static_cast<LightMode>(drawn));
  s.sun_elevation = deg2rad(s.mode == LightMode::kLowSun ? uniform(rng, 5.0, 20.0) : uniform(rng, 25.0, 70.0));
  s.sun_azimuth = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  const double direct = uniform(rng, 0.5, 0.75), ambient = uniform(rng, 0.25, 0.45);  // sequenced draws
  switch (s.mode) {
    case LightMode::kSun:
    case LightMode::kLowSun:
      s.direct = direct, s.ambient = ambient;
      break;
    case LightMode::kOvercast:
      s.direct = uniform(rng, 0.0, 0.08), s.ambient = uniform(rng, 0.85, 1.0);
      break;
    case LightMode::kShade:
      s.direct = 0.0, s.ambient = uniform(rng, 0.35, 0.6);
      break;
  }
  s.sky_horizon = uniform(rng, 0.6, 1.0);
  const double ratio = s.mode == LightMode::kOvercast ? uniform(rng, 1.0, 1.25) : uniform(rng, 0.65, 0.95);
  s.sky_zenith = std::clamp(s.sky_horizon * ratio, 0.6, 1.0);
  const double clouds = uniform(rng, 0.0, 1.0), contrast = uniform(rng, 0.015, 0.05);
  s.cloud_contrast = clouds < 0.5 ? contrast : 0.0;
  s.cloud_seed = rng();
  // A phone meters the whole frame, mostly sky here: the brighter end of the sky at 75–90 % of
  // the range, within what the sensor's gain allows.
  s.gain = std::clamp(uniform(rng, 0.75, 0.9) / std::max(s.sky_horizon, s.sky_zenith), 0.6, 0.95);
  return s;
}

Vec3 towards_sun(const SiteLight& s) {
  return {std::cos(s.sun_elevation) * std::sin(s.sun_azimuth), std::cos(s.sun_elevation) * std::cos(s.sun_azimuth),
          std::sin(s.sun_elevation)};
}

Lighting site_lighting(const SiteLight& s) {
  Lighting L;
  L.towards_light_world = towards_sun(s);
  L.ambient = s.ambient, L.direct = s.direct;
  SkyDome dome;
  dome.zenith = s.sky_zenith, dome.horizon = s.sky_horizon;
  // A 4 km tile of band-limited noise on the layer (1 km up): cloud features of 0.1–1 km.
  if (s.cloud_contrast > 0.0) dome.clouds = procedural_texture(s.cloud_seed, 4000.0, 512, 0.5, 0.5 * s.cloud_contrast);
  L.sky = dome.horizon;
  L.dome = dome;
  return L;
}

}  // namespace antpose::sim
