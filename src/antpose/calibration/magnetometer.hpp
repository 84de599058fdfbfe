// Magnetometer hard- and soft-iron calibration from a recording in which the device was turned
// through all orientations (the field vector then sweeps an ellipsoid).
//
// Model (imu::ImuCalibration): m = S (m_raw − b), S symmetric positive definite.
//  1. Algebraic ellipsoid fit: the general quadric pᵀQp + 2uᵀp + k = 0 through the samples by
//     total least squares (smallest eigenvector of DᵀD, D the 10-column design matrix of the
//     centred and scaled samples; cf. Li & Griffiths, "Least squares ellipsoid specific
//     fitting", GMP 2004, without their 4J − I² constraint, which coverage checks replace).
//     Centre b = −Q⁻¹u; M = Q / (bᵀQb − k) must be positive definite (otherwise the samples
//     are no ellipsoid: poor coverage or disturbances).
//  2. S = F · M^½ (symmetric square root), F = det(M)^(−1/6) the geometric mean of the
//     semi-axes, so det S = 1 (S changes the shape, not the volume) and ‖S (m − b)‖ = F, the
//     fitted field strength.
//  3. Optional Ceres (LM) refinement of the geometric residual ‖S (m − b)‖ − F over b, the 6
//     entries of a symmetric S (normalised to det S = 1) and F, with the covariance of b and S
//     (the compass's calibration error, measure::heading_from_field).
// The thesis's hard iron (max + min)/2 is imu::estimate_hard_iron.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::calibration {

struct MagnetometerOptions {
  bool refine = true;               // step 3
  std::size_t min_samples = 50;
  double min_spread = 0.02;         // smallest eigenvalue of E[u uᵀ] of the field directions (1/3 for a full sphere, 0 for a plane)
  double warn_direction_coverage = 0.6;  // warn below this fraction of the 26 direction bins (cube faces, edges, corners)
};

struct MagnetometerCalibration {
  Vec3 hard_iron_uT = Vec3::Zero();     // b
  Mat3 soft_iron = Mat3::Identity();    // S (symmetric, det 1)
  double field_uT = 0.0;                // F
  Vec3 semi_axes_uT = Vec3::Zero();     // of the raw ellipsoid, ascending
  std::size_t samples = 0;
  double direction_coverage = 0.0;      // fraction of the 26 direction bins with samples
  double spread = 0.0;                  // smallest eigenvalue of E[u uᵀ]
  // Residuals: std(|m|)/mean(|m|) raw; after the (max+min)/2 hard iron; after the ellipsoid.
  double residual_rel_raw = 0.0;
  double residual_rel_hard_iron = 0.0;
  double residual_rel = 0.0;            // std(‖S(m − b)‖) / F
  double residual_rms_uT = 0.0;         // RMS(‖S(m − b)‖ − F)
  Vec3 max_min_hard_iron_uT = Vec3::Zero();  // (max + min)/2, for comparison
  /// 1σ of b (µT) and of each entry of S (symmetric), from the refinement's covariance scaled by
  /// its residuals' variance (S's scale, which F carries, left out); none without step 3.
  std::optional<Vec3> hard_iron_sigma_uT;
  std::optional<Mat3> soft_iron_sigma;

  Vec3 correct(const Vec3& raw) const { return soft_iron * (raw - hard_iron_uT); }
};

/// Fits the ellipsoid to a magnetometer stream (µT). Throws MeasurementError naming `source` for
/// too few samples, too little coverage (a rotation about one axis only) or a quadric that is
/// no ellipsoid; warns in `diagnostics` (with `source`) when some directions are missing.
MagnetometerCalibration fit_magnetometer(const Stream& magnetometer, const MagnetometerOptions& options,
                                         Diagnostics& diagnostics, const std::filesystem::path& source = {});

/// The magnetometer's axes against the accelerometer's, by the invariance of the angle between
/// gravity and the Earth's field: wherever the device points, â · R m̂ = sin(−dip) for â the
/// calibrated accelerometer's direction (up, at rest) and m̂ the hard- and soft-iron corrected
/// field (Li & Li, "Effective method for magnetic sensor calibration using the dot product
/// invariance", 2012; Kok & Schön, "Magnetometer calibration using inertial sensors", IEEE Sensors
/// J. 2016, fit the same rotation jointly). A symmetric soft-iron correction cannot turn the axes,
/// and the two chips' axes differ by tenths of a degree, which the compass takes for a heading:
/// on a simulated typical phone (0.17, 0.12, 0.06)° turned the compass 0.07–0.38° at the photos
/// of antenna sites (docs/non-contact.md). Fitted over the samples at which the accelerometer
/// feels gravity alone (| |a| − g | below options.static_tolerance · g), R (angle-axis) and the
/// dip by Levenberg–Marquardt with a Huber loss.
struct MagnetometerAlignmentOptions {
  double static_tolerance = 0.02;  // of g
  std::size_t min_samples = 100;
  double min_spread = 0.02;  // smallest eigenvalue of E[â âᵀ]: gravity seen from enough directions
  double huber_loss = 0.01;  // of the dot product (≈ 0.6°)
};

struct MagnetometerAlignment {
  Mat3 R_calibrated_magnetometer = Mat3::Identity();  // calibrated (accelerometer) frame ← magnetometer's
  double dip_rad = 0.0;                               // of the field at the recording, down positive
  std::size_t samples = 0;
  double spread = 0.0;            // smallest eigenvalue of E[â âᵀ]
  double residual_rms_rad = 0.0;  // of the angle between â and R m̂ about its mean
  Vec3 sigma_rad = Vec3::Zero();  // 1σ per axis of R's rotation vector
};

/// `accelerometer` (m/s²) and `magnetometer` (µT) already corrected by their calibrations; the
/// accelerometer is interpolated at the magnetometer's instants. Throws MeasurementError naming
/// `source` for too few samples at rest-like acceleration or too little variety of attitudes.
MagnetometerAlignment fit_magnetometer_alignment(const Stream& accelerometer, const Stream& magnetometer,
                                                 double gravity, const MagnetometerAlignmentOptions& options,
                                                 const std::filesystem::path& source = {});

}  // namespace antpose::calibration
