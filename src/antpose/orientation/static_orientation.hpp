// Static orientation of the phone from averaged accelerometer and magnetometer (thesis §4.4,
// the "eCompass"), built TRIAD-style so that no attitude is singular:
//   up    = f / |f|                 (specific force at rest points up: f_device = R_device_world (0, 0, +g))
//   east  = (m × up) / |m × up|     (m = mean magnetic field, device frame)
//   north = up × east
//   R_world_device = [east; north; up]   (rows; world = ENU with y along MAGNETIC north)
// This is Android's SensorManager.getRotationMatrix (rows H, M, A) and TRIAD (Shuster & Oh,
// J. Guidance 4(1), 1981) with gravity as the exact and the field as the secondary vector.
// It only fails when the field is parallel to gravity (magnetic pole, or a disturbance).
//
// The thesis reports the result as Android's azimuth/pitch/roll (SensorManager.getOrientation):
//   azimuth = atan2(R01, R11), pitch = asin(−R21), roll = atan2(−R20, R22)   (R = R_world_device)
// which has a singularity at pitch = ±90° — the phone upright, the normal contact pose. Those
// angles are reported for comparison only; nothing downstream uses them.
//
// Uncertainty (1σ, per axis): the window is cut into B ≈ √N equal time blocks (batch means,
// e.g. Flegal & Jones, Ann. Statist. 38(2), 2010): the variance of the block results over B
// is the variance of the window mean even when samples are correlated (tremor, low-pass
// filtered sensors). We take the larger of that and the white-noise value σ²/N, so the
// effective sample count N_eff = σ²/var(mean) never exceeds N. To the scatter part we add
// floors for errors the window cannot show:
//   tilt:    residual accelerometer bias b_a (per axis)  → b_a/g rad (0.02 m/s² → 0.12°);
//   heading: residual hard iron of magnitude r, random direction, east component r/√3
//            → r/(√3 H) rad (1 µT at H = 20 µT → 1.65°), plus the tilt error leaking into
//            heading through the vertical field, σ_tilt · tan(dip).
#pragma once

#include <cstddef>

#include "antpose/io/capture.hpp"

namespace antpose::orientation {

struct StaticOrientationOptions {
  double acc_bias_floor_mps2 = 0.02;  // residual accelerometer bias per axis (1σ)
  double mag_residual_uT = 1.0;       // magnitude of the residual hard iron after calibration
  std::size_t min_samples = 5;        // per stream inside the window
  double min_horizontal_fraction = 0.02;  // H/|m| below this: heading undefined → MeasurementError
};

/// Android SensorManager.getOrientation angles of the phone (rad), formulas in the header comment.
struct AndroidOrientation {
  double azimuth = 0.0;  // [0, 2π), clockwise from (magnetic) north of the device y axis
  double pitch = 0.0;    // [−π/2, π/2], negative when the top of the phone points up
  double roll = 0.0;     // (−π, π]
};

struct StaticOrientation {
  double t0 = 0.0, t1 = 0.0;  // window, s
  Mat3 R_world_device = Mat3::Identity();  // world = ENU, magnetic north
  Vec3 acc_mean_mps2 = Vec3::Zero();       // device frame
  Vec3 mag_mean_uT = Vec3::Zero();         // device frame
  std::size_t acc_samples = 0, mag_samples = 0;
  double acc_n_eff = 0.0, mag_n_eff = 0.0;  // effective independent samples (see header)
  double acc_direction_std = 0.0;  // rad, RMS angle of single samples from the mean direction
  double mag_direction_std = 0.0;  // rad
  double gravity_mps2 = 0.0;       // |mean f|
  double field_uT = 0.0;           // |mean m|
  double horizontal_field_uT = 0.0;
  double dip = 0.0;                // rad, angle of the field below the horizontal (positive down)
  double tilt_sigma = 0.0;         // rad, 1σ per tilt axis (scatter ⊕ floor)
  double heading_sigma = 0.0;      // rad, 1σ (scatter ⊕ floors)
  double tilt_sigma_scatter = 0.0;     // scatter part only
  double heading_sigma_scatter = 0.0;
  double max_block_tilt = 0.0;     // rad, largest deviation of a block's up direction from the mean
  double max_block_heading = 0.0;  // rad, largest deviation of a block's heading from the mean
  std::size_t blocks = 0;
  AndroidOrientation android;      // thesis output only
};

/// R_world_device (world = ENU magnetic) from a specific force and a magnetic field, both in
/// the device frame. Throws MeasurementError when either is zero or they are parallel.
Mat3 triad_world_device(const Vec3& specific_force, const Vec3& magnetic_field);

/// Android getOrientation angles of R_world_device.
AndroidOrientation android_orientation(const Mat3& R_world_device);

/// Static orientation over [t0, t1] (capture clock) from the accelerometer and magnetometer
/// streams (asynchronous streams fine). InputError when a stream is missing; MeasurementError
/// when the window has too few samples or the field is (nearly) vertical.
StaticOrientation estimate_static_orientation(const Capture& capture, double t0, double t1,
                                              const StaticOrientationOptions& options = {});

}  // namespace antpose::orientation
