// antpose's offline smoother (registry name `antpose-smoother`): the whole log is available, so
// the causal filter (antpose_filter.hpp) runs forward and, on the time-reversed log, backward,
// and the two estimates are fused per gyroscope sample.
//
// Backward pass: time t' = −t, samples in reverse order, gyroscope negated (the device turns
// the other way in reversed time) and, for interval-mean gyroscope samples (the default, see
// AntposeFilterParams::gyro_trapezoid), shifted by one sample so that each still covers its own
// interval; accelerometer and magnetometer unchanged. It starts from the
// forward pass's final gyroscope bias (negated), the way offline VQF (Laidig & Seel, Information
// Fusion 91, 2023, §5) reuses information from the other time direction; its error behaves like
// an anti-causal low-pass of the sensor errors, the forward one like a causal one, so their
// weighted mean is a zero-phase (two-sided) estimate, as in the Rauch–Tung–Striebel / two-filter
// smoother (D. C. Fraser, J. E. Potter, "The optimum linear smoother as a combination of two
// optimum linear filters", IEEE TAC 14(4), 1969): x̂ = (P_f⁻¹ + P_b⁻¹)⁻¹ (P_f⁻¹ x̂_f + P_b⁻¹ x̂_b).
// Here per axis of the world-frame error rotation: with δ = log(q_b ⊗ q_f⁻¹) (rotation vector,
// ENU), q = exp(W δ) ⊗ q_f, W = diag(w_i, w_i, w_h), w = σ_f² / (σ_f² + σ_b²) from each pass's
// tilt and heading σ (heuristic, see antpose_filter.hpp); covariance diag(σ_f²σ_b²/(σ_f²+σ_b²)).
// Start (forward unconverged) and end (backward unconverged), and the stretches where one pass
// rejected the magnetometer (its heading σ grows), thus lean on the other pass.
// Heading time constant: each pass, by itself, must correct its heading quickly because a gyroscope
// bias error δb drifts it by δb·τ within one time constant τ. The two passes drift in opposite
// directions (the backward pass integrates −δb), so their fusion cancels that drift to first
// order and can average the magnetometer much longer — which is what removes local field
// errors (BROAD trials 27, 30). The smoother therefore adapts τ to the bias filter's σ_b:
// τ = budget / σ_b within [tau_mag, tau_mag_max] (AntposeFilterParams::mag_drift_budget,
// default kSmootherDriftBudgetDeg). A well-estimated bias (BROAD, rest phases: σ_b ≈ 0.05°/s)
// gives τ ≈ 60 s; a phone walking without rest (Tyrex: σ_b ≈ 0.3°/s) stays at tau_mag.
// Sensitivity on the 10 BROAD trials (mean total RMSE): budget 2° → 1.867°, 2.4° → 1.830°,
// 3° → 1.808°; the Tyrex trials do not change.
// 6-D (mag=0): the two headings are unrelated, so only tilt is fused and heading is the
// forward pass's.
#pragma once

#include "antpose/orientation/antpose_filter.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::orientation {

/// `data` in reversed time (see the file comment); source kept. `interval_mean_gyro`: shift the
/// gyroscope by one sample (interval-mean samples).
ImuData time_reversed(const ImuData& data, bool interval_mean_gyro);

/// Fuses a forward track and the backward track of time_reversed data (same gyroscope samples,
/// reverse order, both with covariances) as the file comment says. std::invalid_argument when
/// the tracks do not match.
OrientationTrack fuse_forward_backward(const OrientationTrack& forward, const OrientationTrack& backward,
                                       bool fuse_heading);

class AntposeSmoother final : public OrientationEstimator {
 public:
  explicit AntposeSmoother(const AntposeFilterParams& params) : p_(params) {}
  std::string name() const override { return "antpose-smoother"; }
  bool causal() const override { return false; }
  OrientationTrack estimate(const ImuData& data, Diagnostics& diagnostics) const override;

 private:
  AntposeFilterParams p_;
};

}  // namespace antpose::orientation
