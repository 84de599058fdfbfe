// The Earth's gravity and rotation on the WGS84 ellipsoid: what a still phone's accelerometer
// and gyroscope should read at a site (calibration checks and the simulator alike).
#pragma once

#include "antpose/geometry/rotation.hpp"

namespace antpose::geomag {

/// Normal gravity on the WGS84 ellipsoid (Somigliana) with the free-air correction
/// −3.086e-6 s^-2 · h; m/s^2 (NIMA TR8350.2 §4.2).
double normal_gravity(double lat_deg, double alt_m);

/// Earth's rotation rate in ENU at a latitude: Ω (0, cos φ, sin φ), rad/s.
Vec3 earth_rate_enu(double lat_deg);

}  // namespace antpose::geomag
