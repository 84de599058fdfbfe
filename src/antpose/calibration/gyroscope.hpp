// Gyroscope calibration from a multi-position recording (Tedaldi, Pretto, Menegatti, ICRA 2014,
// §III-C): the bias is the mean rate over the static frames; misalignment T (full, unit
// diagonal: 6 angles, because the gyroscope is aligned to the calibrated accelerometer frame)
// and scale k are fitted with Ceres (Levenberg–Marquardt) so that integrating the corrected rate
//   ω = T · diag(k) · (y − b)
// from the end of each (trimmed) static frame to the start of the next one, with quaternion kinematics
// q̇ = ½ q ⊗ (0, ω) and fourth-order Runge–Kutta (ω linear between samples), rotates the
// gravity direction measured by the calibrated accelerometer in the first frame into the one
// measured in the next: r = u_{k+1} − R(q)ᵀ u_k (unit vectors, so |r| ≈ the angle in rad).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "antpose/calibration/accelerometer.hpp"
#include "antpose/calibration/static_frames.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::calibration {

struct GyroscopeOptions {
  double max_transition_s = 60.0;  // longer moves between static frames are not used (drift)
  bool fit_misalignment = true;    // false: scale only (T = I)
};

struct GyroscopeCalibration {
  Vec3 bias = Vec3::Zero();              // b, rad/s, raw sensor frame
  Vec3 scale = Vec3::Ones();             // k
  Mat3 misalignment = Mat3::Identity();  // T (unit diagonal)
  std::size_t frames = 0;                // static frames used for the bias
  std::size_t transitions = 0;           // moves used in the fit
  double rms_raw = 0.0;                  // RMS gravity-direction error (rad): no correction at all
  double rms_bias_only = 0.0;            //   bias removed only
  double rms_after = 0.0;                //   full correction
  /// 1σ of (t01, t02, t10, t12, t20, t21, k0, k1, k2) from the fit covariance.
  Eigen::Matrix<double, 9, 1> sigma = Eigen::Matrix<double, 9, 1>::Zero();

  Mat3 correction() const { return misalignment * scale.asDiagonal(); }
  Vec3 correct(const Vec3& raw) const { return correction() * (raw - bias); }
};

/// Sample-weighted mean raw gyroscope rate over the static frames (rad/s). Throws
/// MeasurementError naming `source` when no frame has gyroscope samples.
Vec3 gyroscope_bias(const std::vector<StaticFrame>& frames, const std::string& source = {});

/// The fit above. `accelerometer` calibrates the static means into gravity directions. Throws
/// MeasurementError (naming `source`) with fewer than 2 + 9/2 usable moves (5) between frames.
GyroscopeCalibration fit_gyroscope(const Stream& gyroscope, const std::vector<StaticFrame>& frames,
                                   const AccelerometerCalibration& accelerometer, const GyroscopeOptions& options = {},
                                   const std::string& source = {});

/// Rotation R_start_end (body at the start → body at the end) from integrating corrected rates
/// ω_i at times t_i with RK4 (as in the fit).
Mat3 integrate_rotation(const std::vector<double>& t, const std::vector<Vec3>& omega);

/// T (unit diagonal) and k of a gyroscope correction matrix C = T diag(k): k_j = C_jj.
void canonical_gyroscope(const Mat3& correction, Mat3& misalignment, Vec3& scale);

}  // namespace antpose::calibration
