// Accelerometer calibration from static frames: at rest the corrected specific force has the
// magnitude of gravity, ‖a‖ = g, in every orientation.
//
// Correction model (imu::ImuCalibration; Tedaldi, Pretto, Menegatti, ICRA 2014, eq. 8):
//   a = T · diag(k) · (y − b),   T = [[1, t01, t02], [0, 1, t12], [0, 0, 1]]
// y the raw reading (sensor frame, m/s²), b bias, k per-axis scale. T upper triangular: the
// calibrated frame keeps the accelerometer's x axis and xy plane, and the three angles
// t01, t02, t12 (rad) are the non-orthogonality; a rotation of the frame is unobservable from
// ‖a‖ alone, so this is the whole identifiable part of the seed's y = T_m K_m x + b.
//
//  - thesis normalization (§4.3): T = I; Σ_k k_k² (y_k − b_k)² = g² is linear in
//    θ = (k²/G, −2k²b/G) with G = g² − Σ k²b², so 6 unknowns by linear least squares from
//    ≥ 6 frames; then b_k = −θ_{3+k}/(2θ_k), G = g²/(1 + Σ θ_k b_k²), k_k = sqrt(θ_k G).
//  - full 9-parameter fit: Ceres Levenberg–Marquardt on r_i = ‖T diag(k)(y_i − b)‖ − g
//    from the thesis solution; needs ≥ 9 frames (10 for a noise estimate). The parameter
//    covariance is σ̂² (JᵀJ)⁻¹ with σ̂² = Σ r²/(n − 9) (Ceres Covariance).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "antpose/io/capture.hpp"

namespace antpose::calibration {

struct AccelerometerCalibration {
  std::string method;                    // "thesis" | "full"
  Vec3 bias = Vec3::Zero();              // b, m/s², sensor frame
  Vec3 scale = Vec3::Ones();             // k
  Mat3 misalignment = Mat3::Identity();  // T (upper unit triangular)
  double gravity = 0.0;                  // g used, m/s²
  std::size_t frames = 0;
  double rms_before = 0.0;               // RMS(‖y‖ − g), m/s²
  double rms_after = 0.0;                // RMS(‖a‖ − g), m/s²
  double max_after = 0.0;                // max |‖a‖ − g|
  /// 1σ of (t01, t02, t12, k0, k1, k2, b0, b1, b2) from the full fit's covariance; zero for
  /// the thesis fit and when there are no spare frames.
  Eigen::Matrix<double, 9, 1> sigma = Eigen::Matrix<double, 9, 1>::Zero();

  Mat3 correction() const { return misalignment * scale.asDiagonal(); }
  Vec3 correct(const Vec3& raw) const { return correction() * (raw - bias); }
};

/// Thesis §4.3 normalization from the mean raw readings of static frames. Throws
/// MeasurementError (naming `source`) with fewer than 6 frames or a degenerate pose set.
AccelerometerCalibration fit_accelerometer_thesis(const std::vector<Vec3>& static_means, double gravity,
                                                  const std::string& source = {});

/// The 9-parameter fit (see the file comment), started from `start` (usually the thesis fit).
AccelerometerCalibration fit_accelerometer_full(const std::vector<Vec3>& static_means, double gravity,
                                                const AccelerometerCalibration& start, const std::string& source = {});

/// RMS and max of ‖correct(y_i)‖ − g.
std::pair<double, double> gravity_residual(const AccelerometerCalibration& c, const std::vector<Vec3>& static_means);

/// Canonical (T upper unit triangular, k) of a general correction matrix C (x = C (y − b)):
/// C = Q·U (QR), U = T diag(k); Q is the rotation from the calibrated to the original frame
/// (returned in `rotation`). Used to compare any model (e.g. the simulator's) with the fit.
void canonical_accelerometer(const Mat3& correction, Mat3& misalignment, Vec3& scale, Mat3* rotation = nullptr);

}  // namespace antpose::calibration
