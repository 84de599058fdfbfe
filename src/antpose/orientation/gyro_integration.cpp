#include "antpose/orientation/gyro_integration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace antpose::orientation {

Mat3 right_jacobian_so3(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = skew(phi);
  if (theta < 1e-6) return Mat3::Identity() - 0.5 * K + K * K / 6.0;
  const double t2 = theta * theta;
  return Mat3::Identity() - (1.0 - std::cos(theta)) / t2 * K + (theta - std::sin(theta)) / (t2 * theta) * K * K;
}

GyroIntegration::GyroIntegration(const SensorSeries& g, double t0, double t1, const Vec3& bias, bool trapezoid)
    : bias_(bias) {
  if (g.size() < 2) throw std::invalid_argument("GyroIntegration: fewer than 2 gyroscope samples");
  if (!(t1 >= t0)) throw std::invalid_argument("GyroIntegration: t1 < t0");
  t0 = std::clamp(t0, g.t.front(), g.t.back());
  t1 = std::clamp(t1, g.t.front(), g.t.back());
  // Rate acting over the sample interval that ends at sample j (the estimators'
  // convention).
  auto acting = [&](std::size_t j) -> Vec3 {
    const Vec3 w = trapezoid && j > 0 ? Vec3(0.5 * (g.v[j] + g.v[j - 1])) : g.v[j];
    return w - bias_;
  };
  // First sample at or after a time: the one whose interval contains it.
  auto sample_ending_at_or_after = [&](double t) {
    return static_cast<std::size_t>(std::lower_bound(g.t.begin(), g.t.end(), t) - g.t.begin());
  };
  t_.push_back(t0);
  w_.push_back(Vec3::Zero());
  R_.push_back(Mat3::Identity());
  J_.push_back(Mat3::Zero());
  std::size_t j = sample_ending_at_or_after(t0);
  if (j < g.size() && g.t[j] == t0) ++j;
  while (t_.back() < t1) {
    const double end = j < g.size() ? std::min(g.t[j], t1) : t1;
    const Vec3 w = acting(std::min(j, g.size() - 1));
    const double dt = end - t_.back();
    const Vec3 phi = w * dt;
    const Mat3 step = exp_so3(phi);
    // Forster et al. eq. 38/44 in recursive form: J_{k+1} = stepᵀ J_k − J_r(ω
    // Δt) Δt.
    J_.push_back(step.transpose() * J_.back() - right_jacobian_so3(phi) * dt);
    R_.push_back(R_.back() * step);
    if (dt > longest_step_) longest_step_ = dt, longest_at_ = t_.back();
    t_.push_back(end);
    w_.push_back(w);
    if (j < g.size() && end == g.t[j]) ++j;
  }
}

GyroIntegration::Sample GyroIntegration::at(double t) const {
  t = std::clamp(t, t_.front(), t_.back());
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
  if (k >= t_.size()) return {R_.back(), J_.back()};
  // Partial step from t_{k−1} with the rate of the interval (t_{k−1}, t_k].
  const double dt = t - t_[k - 1];
  const Vec3 phi = w_[k] * dt;
  const Mat3 step = exp_so3(phi);
  return {R_[k - 1] * step, step.transpose() * J_[k - 1] - right_jacobian_so3(phi) * dt};
}

Vec3 GyroIntegration::rate(double t) const {
  if (t_.size() < 2) return Vec3::Zero();
  t = std::clamp(t, t_.front(), t_.back());
  std::size_t k = static_cast<std::size_t>(std::lower_bound(t_.begin(), t_.end(), t) - t_.begin());
  k = std::clamp<std::size_t>(k, 1, t_.size() - 1);
  return w_[k];
}

}  // namespace antpose::orientation
