// The magnetic field at the photos, against the Earth's and against itself along the walk.
//
// A magnetised steel mast adds a dipole-like field to the Earth's, B(p) = B_earth + δB(p), which
// turns the compass (the horizontal part of B) and also moves the field's strength and dip. Four
// tests, on the field at each photo in the world frame (tilt from gravity, so dip is measurable;
// heading from the magnetometer itself, so the horizontal direction is not):
//  1. against the Earth's field at the site (WMM): strength within `strength_tolerance`, dip
//     within `dip_tolerance`. The limits must allow WMM's error, crustal anomalies (~1 %) and the
//     magnetometer's scale calibration, so a turn of 4–8° by a field perpendicular to B_earth
//     can pass it (acceptance sites 703, 706: −2.7 % and −1.3° at most);
//  2. along the walk: the Earth's field is uniform over a site (nT per km), a mast's falls off as
//     1/r³, so photos taken from a few metres apart see different fields. The spread (largest −
//     smallest) of strength and of dip over the photos is free of WMM's and the calibration's
//     offsets, and its limits can be tighter.
//  3. the part common to all photos, against WMM: the median dip over the photos. From 15–30 m a
//     mast's field hardly changes along the walk, so test 2 is blind to it, and test 1's dip limit
//     must allow one photo's tilt error while walking. The median averages that out, leaving
//     WMM's error (0.2–0.3° in inclination, 1σ, WMM2025 report) and the calibration's shape error,
//     so `median_dip_tolerance` can be half of test 1's (acceptance site 1612: the median dip
//     1.6° above WMM's, every photo within 2°, the compass turned 3°). The median strength is not
//     tested so tightly: it carries the magnetometer's overall gain, which the calibration does
//     not fix (det S = 1, calibration/magnetometer.hpp).
//  4. a gradient along the walk: the strength fitted as a linear function of where the phone was,
//     F_i = a + gᵀ h_i (h the horizontal position, least squares). Test 2's spread also carries
//     the calibration's orientation-dependent error; a trend over the positions is the source's
//     fall-off, and the fit averages the noise (acceptance site 1306: the compass turned 4.7°,
//     strength and dip within 0.8 % and 0.5° of WMM's everywhere, spread 1.3 %, but 1.0 % change
//     along the walk, fitted well). Flagged when the fitted change over the photos exceeds
//     `strength_trend` and the fit is significant (F statistic of the 2 slopes against the
//     residual, above `trend_significance`).
// No magnetometer sees a perturbation perpendicular to the horizontal field that is the same at
// every photo; the tests catch the disturbances that come with a measurable change.
//
// When either test fails, the heading error is estimated from the perturbation it sees: the
// largest over the photos of its part along B and along the dip direction (against WMM, else
// against the photos' median) is taken as the size of the unseen horizontal part, over the
// horizontal field: σ_heading = max_photos |δB_seen| / B_h. The disturbances that pass test 1 are
// those mostly perpendicular to B, so this is rather an underestimate (site 703: 2.2° for a turn
// of 3–5°); the warning says so.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "antpose/geomag/wmm.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {

struct FieldCheckOptions {
  double strength_tolerance = 0.04;     // against WMM, fraction
  double dip_tolerance = deg2rad(2.0);  // against WMM
  // Over the photos. On the undisturbed acceptance sites 701–712 the spreads reached 0.64 % and
  // 1.54° (the dip carries the track's tilt error while walking), on the disturbed 2.2–8.1 %.
  double strength_spread = 0.015;  // fraction of the median
  double dip_spread = deg2rad(2.5);
  // Test 3. On the 42 undisturbed sites 601–1604 the median dip was within 0.24° of WMM's.
  double median_dip_tolerance = deg2rad(1.0);
  // Test 4. On the 42 undisturbed sites 601–1604 the change fitted along the walk reached 0.50 %
  // and the F statistic 5.3 (not on the same site); on 18 of 19 disturbed ones 0.86–8.6 %, F ≥ 19.
  double strength_trend = 0.005;     // fraction of the median
  double trend_significance = 10.0;  // F(2, n − 3); 8.0 is p = 0.01 for 12 photos
  double half_window_s = 0.25;       // magnetometer samples averaged around each photo
};

struct FieldCheck {
  std::vector<double> strength_uT, dip_rad;  // per photo with magnetometer data
  std::optional<double> wmm_strength_uT, wmm_dip_rad;
  double worst_strength_fraction = 0.0, worst_dip_rad = 0.0;  // against WMM (0 without a site)
  double strength_spread_fraction = 0.0, dip_spread_rad = 0.0;
  double median_dip_offset_rad = 0.0;  // median dip − WMM's (0 without a site)
  // Test 4 (0 without positions): the fitted change of the strength over the photos, the slope's
  // size and the fit's F statistic.
  double strength_trend_fraction = 0.0, strength_gradient_uT_per_m = 0.0, trend_f_statistic = 0.0;
  bool disturbed = false;
  double heading_sigma_rad = 0.0;  // the disturbance's estimated heading error (file comment), 0 when not disturbed
  std::vector<std::string> warnings;
};

/// The field (µT, world frame) at each photo: the mean of the magnetometer's samples within
/// ±half_window_s of each instant (capture clock, IMU time), rotated by the track; nullopt where
/// no sample lies inside the track.
std::vector<std::optional<Vec3>> field_at_photos(const orientation::ImuData& data,
                                                 const orientation::OrientationTrack& track,
                                                 const std::vector<double>& t_photos, double half_window_s);

/// The four tests of the file comment on the photos' fields (µT, world frame). `p_world_m` holds
/// where each photo was taken (world axes, any origin, m) in the same order, or is empty: then
/// test 4 is skipped.
FieldCheck check_field(const std::vector<Vec3>& field_world_uT, const std::optional<geomag::SiteField>& site,
                       const FieldCheckOptions& options, const std::vector<Vec3>& p_world_m = {});

}  // namespace antpose::measure
