// The light of a wide antenna site (`antpose simulate capture --scenario antenna --distribution
// wide`): sun, low sun, overcast or shade, a sky brighter towards the horizon (or the zenith)
// with optional low-contrast clouds, and the phone's auto-exposure.
//
// Radiances are relative: 1 is a white Lambertian surface lit with ambient + direct = 1. A clear
// sky is darker at the zenith than at the horizon; an overcast one brighter (the CIE standard
// overcast sky, L(θ) ∝ 1 + 2 sin θ, Moon & Spencer 1942), flattened here to the 0.6–1 range of
// a phone's metered frame.
#pragma once

#include <optional>
#include <random>
#include <string>

#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

enum class LightMode { kSun, kLowSun, kOvercast, kShade };
std::string to_string(LightMode mode);
/// "sun" | "low-sun" | "overcast" | "shade"; InputError naming --light otherwise.
LightMode parse_light_mode(const std::string& name);

/// The drawn light of a site.
struct SiteLight {
  LightMode mode = LightMode::kSun;
  double sun_elevation = 0.0, sun_azimuth = 0.0;  // rad; azimuth clockwise from magnetic north
  double ambient = 0.6, direct = 0.4;
  double sky_zenith = 0.9, sky_horizon = 0.9;
  double cloud_contrast = 0.0;  // 1σ relative modulation of the sky; 0: clear
  std::uint64_t cloud_seed = 0;
  /// Auto-exposure: the fraction of the full well a radiance of 1 fills (SensorModel::gain),
  /// 0.6–0.95, chosen so that the metered sky lands at 75–90 % of the range.
  double gain = 0.85;
};

/// Draws the light (the mode unless `mode` fixes it):
///   sun       elevation 25–70°, direct 0.5–0.75, ambient 0.25–0.45;
///   low-sun   elevation 5–20°, direct and ambient as sun;
///   overcast  direct 0–0.08, ambient 0.85–1.0 (sun position as sun, hidden);
///   shade     direct 0 (the site in a building's shadow), ambient 0.35–0.6;
/// sun azimuth uniform; horizon 0.6–1.0 and the zenith darker (clear) or brighter (overcast);
/// clouds on half of the sites, 1.5–5 % contrast.
SiteLight draw_site_light(std::optional<LightMode> mode, std::mt19937_64& rng);

/// The unit vector towards the sun, world (ENU, magnetic north).
Vec3 towards_sun(const SiteLight& light);

/// The renderer's Lighting of a drawn light: the sun, and a SkyDome with the clouds' texture.
Lighting site_lighting(const SiteLight& light);

}  // namespace antpose::sim
