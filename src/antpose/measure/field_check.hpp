// The magnetic field at the photos, against the Earth's and against itself along the walk.
//
// A magnetised steel mast adds a dipole-like field to the Earth's, B(p) = B_earth + δB(p), which
// turns the compass (the horizontal part of B) and also moves the field's strength and dip. The
// field at each photo is taken in the world frame through the photo's attitude from the board
// (R_world_board · R_board_camera_i · R_camera_device): the board is fixed, so the photos share
// one heading (the board's, from the compass) and each one's tilt and turn relative to the others
// is the PnP's, to hundredths of a degree. The field's dip, and its horizontal direction at one
// photo against another, are then measured free of the orientation track's errors while walking.
// Five tests:
//  1. against the Earth's field at the site (WMM), photo by photo: strength within
//     `strength_tolerance`, dip within `dip_tolerance`. The limits must allow WMM's error,
//     crustal anomalies (~1 %) and the magnetometer's scale calibration, so a turn of 4–8° by a
//     field perpendicular to B_earth can pass it (simulated: −2.7 % and −1.3° for such turns);
//  2. along the walk: the Earth's field is uniform over a site (nT per km), a mast's falls off as
//     1/r³, so photos taken from a few metres apart see different fields. The spread (largest −
//     smallest) of strength and of dip over the photos is free of WMM's and the calibration's
//     offsets, and its limits can be tighter;
//  3. the part common to all photos, against WMM: the median dip over the photos. From 15–30 m a
//     mast's field hardly changes along the walk, so test 2 is blind to it; the median leaves
//     WMM's error (0.2–0.3° in inclination, 1σ, WMM2025 report), crustal anomalies and the
//     calibration's shape error (a simulated mast turning the compass by 3° left every photo's
//     dip within 2° of WMM's, the median 1.6° above it). The median strength is not tested so tightly: it
//     carries the magnetometer's overall gain, which the calibration does not fix (det S = 1,
//     calibration/magnetometer.hpp);
//  4. a gradient of the strength along the walk: F_i = a + gᵀ h_i over where the phone was (h
//     the horizontal position, least squares). A trend over the positions is the source's
//     fall-off, and the fit averages the noise (a simulated compass turned 4.7°, strength and dip
//     near WMM's everywhere, but a 1.0 % change along the walk, fitted well). Flagged when the
//     fitted change exceeds `strength_trend` and its F statistic `trend_significance`;
//  5. a gradient of the whole field vector: B_i = a + G h_i, the three components at once. Test
//     4 sees only the part of δB's change along B; the vector also sees its part across B, the
//     one that turns the compass, because each photo's horizontal direction comes from the
//     board, not from the compass (a simulated compass turned 4.5–5.2°: the strength's trend
//     0.9 % with F 7.9, the vector's 1.8 % with F 15). Flagged when the fitted change (largest
//     distance between two photos' fitted vectors, over |B|) exceeds `vector_trend` and the F
//     statistic of the 2 × 3 slopes `vector_trend_significance`.
// Each test alone is a box: a disturbance may keep every statistic below its limit and still
// turn the compass by degrees, since each sees another part of one perturbation (its part along
// B, along the dip direction, its change along the walk). Together they are a sixth test: each
// test's statistic over its limit (a two-condition test, 4 or 5, fires only when both are
// exceeded, so its ratio is the smaller), and the root sum of squares of the five ratios against
// `joint_tolerance`. Undisturbed, unrelated errors drive them (noise, WMM's error, the track's
// tilt while walking); under a disturbance they move together.
// No magnetometer sees a perturbation perpendicular to the horizontal field that is the same at
// every photo; the tests catch the disturbances that come with a measurable change.
//
// When a test fails, the heading error is estimated from the perturbation it sees: the largest
// over the photos of its part along B and along the dip direction (against WMM, else against the
// photos' median), and the vector's fitted change along the walk, is taken as the size of the
// unseen horizontal part, over the horizontal field: σ_heading = |δB_seen| / B_h. The
// disturbances that pass test 1 are those mostly perpendicular to B, so this is rather an
// underestimate (simulated: 2.2° for a turn of 3–5°); the warning says so.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/check.hpp"
#include "antpose/geomag/wmm.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::measure {

struct FieldCheckOptions {
  double strength_tolerance = 0.04;     // against WMM, fraction
  double dip_tolerance = deg2rad(2.0);  // against WMM
  // Over the photos. On 12 undisturbed simulated sites the spreads reached 0.64 % and 1.54° (the
  // dip carries the track's tilt error while walking), on the disturbed ones 2.2–8.1 %.
  double strength_spread = 0.015;  // fraction of the median
  double dip_spread = deg2rad(2.5);
  // Test 3. On 42 undisturbed simulated sites the median dip was within 0.24° of WMM's.
  double median_dip_tolerance = deg2rad(1.0);
  // Test 4. On 42 undisturbed simulated sites the change fitted along the walk reached 0.50 %
  // and the F statistic 5.3 (not on the same site); on 18 of 19 disturbed ones 0.86–8.6 %, F ≥ 19.
  double strength_trend = 0.005;     // fraction of the median
  double trend_significance = 10.0;  // F(2, n − 3); 8.0 is p = 0.01 for 12 photos
  // Test 5. On 80 undisturbed simulated sites (the field through the true attitudes)
  // the vector's fitted change reached 0.70 % and its F 4.4; on all 40 disturbed ones
  // 1.34–13.8 % with F 13.9–186 (through the pipeline: 0.55–0.71 % and F ≤ 5.3 undisturbed).
  double vector_trend = 0.010;             // fraction of the median strength
  double vector_trend_significance = 8.0;  // F(6, 3(n − 3)); 8.0 is p ≈ 4·10⁻⁵ for 12 photos
  // The joint test (file comment). On 128 undisturbed simulated sites the root sum of squares
  // reached 0.91; a compass turned 3.5° at every photo, with every test between 0.4 and 0.85 of
  // its limit, gave 1.43; the other 63 disturbed sites 3.0–22.
  double joint_tolerance = 1.2;
  double half_window_s = 0.25;  // magnetometer samples averaged around each photo

  OptionProblems Check() const;
};

struct FieldCheck {
  std::vector<Vec3> field_world_uT, p_world_m;  // per photo with magnetometer data (p: if given)
  std::vector<double> strength_uT, dip_rad;     // per photo with magnetometer data
  std::optional<double> wmm_strength_uT, wmm_dip_rad;
  double worst_strength_fraction = 0.0, worst_dip_rad = 0.0;  // against WMM (0 without a site)
  double strength_spread_fraction = 0.0, dip_spread_rad = 0.0;
  double median_dip_offset_rad = 0.0;  // median dip − WMM's (0 without a site)
  // Test 4 (0 without positions): the fitted change of the strength over the photos, the slope's
  // size and the fit's F statistic.
  double strength_trend_fraction = 0.0, strength_gradient_uT_per_m = 0.0, trend_f_statistic = 0.0;
  // Test 5 (0 without positions): the vector's fitted change over the photos (fraction of the
  // median strength) and the fit's F statistic.
  double vector_trend_fraction = 0.0, vector_trend_f_statistic = 0.0;
  // Each test's statistic over its limit (tests 1–5; 0 where a test was skipped), and their root
  // sum of squares, the joint test's statistic.
  std::array<double, 5> test_ratios{};
  double joint_ratio = 0.0;
  bool disturbed = false;
  double heading_sigma_rad = 0.0;  // the disturbance's estimated heading error (file comment), 0 when not disturbed
  std::vector<std::string> warnings;
};

/// The field (µT, world frame) at each photo: the magnetometer's samples within ±half_window_s of
/// the photo's instant `t_photos[i]` (capture clock, IMU time), each carried to that instant by the
/// track's rotation between the two (the gyroscope's, over a fraction of a second), averaged and
/// turned into the world by the photo's own attitude `R_world_device[i]` (from the board, see the
/// file comment); nullopt where no sample lies inside the track.
std::vector<std::optional<Vec3>> field_at_photos(const orientation::ImuData& data,
                                                 const orientation::OrientationTrack& track,
                                                 const std::vector<double>& t_photos,
                                                 const std::vector<Mat3>& R_world_device, double half_window_s);

/// The five tests of the file comment and their joint test, on the photos' fields (µT, world
/// frame). `p_world_m` holds where each photo was taken (world axes, any origin, m) in the same
/// order, or is empty: then tests 4 and 5 are skipped.
FieldCheck check_field(const std::vector<Vec3>& field_world_uT, const std::optional<geomag::SiteField>& site,
                       const FieldCheckOptions& options, const std::vector<Vec3>& p_world_m = {});

}  // namespace antpose::measure
