#include "antpose/calibration/gyroscope.hpp"
#include "antpose/calibration/least_squares.hpp"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>
#include <fmt/format.h>

#include "antpose/geometry/rotation.hpp"

namespace antpose::calibration {
namespace {

// Quaternion (w, x, y, z) helpers for any scalar (double or ceres::Jet).
template <typename T>
void qdot(const T* q, const T* w, T* out) {  // ½ q ⊗ (0, ω)
  out[0] = T(-0.5) * (q[1] * w[0] + q[2] * w[1] + q[3] * w[2]);
  out[1] = T(0.5) * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1]);
  out[2] = T(0.5) * (q[0] * w[1] + q[3] * w[0] - q[1] * w[2]);
  out[3] = T(0.5) * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]);
}

template <typename T>
void rk4_step(T* q, const T* w0, const T* w1, double dt) {
  T wm[3], k1[4], k2[4], k3[4], k4[4], tmp[4];
  for (int i = 0; i < 3; ++i) wm[i] = T(0.5) * (w0[i] + w1[i]);
  qdot(q, w0, k1);
  for (int i = 0; i < 4; ++i) tmp[i] = q[i] + T(0.5 * dt) * k1[i];
  qdot(tmp, wm, k2);
  for (int i = 0; i < 4; ++i) tmp[i] = q[i] + T(0.5 * dt) * k2[i];
  qdot(tmp, wm, k3);
  for (int i = 0; i < 4; ++i) tmp[i] = q[i] + T(dt) * k3[i];
  qdot(tmp, w1, k4);
  for (int i = 0; i < 4; ++i) q[i] += T(dt / 6.0) * (k1[i] + T(2) * k2[i] + T(2) * k3[i] + k4[i]);
  const T n = ceres::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 4; ++i) q[i] /= n;
}

// v_end = R(q)ᵀ v_start, with q = q_start_end.
template <typename T>
void rotate_inverse(const T* q, const T* v, T* out) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  const T R[3][3] = {{T(1) - T(2) * (y * y + z * z), T(2) * (x * y - w * z), T(2) * (x * z + w * y)},
                     {T(2) * (x * y + w * z), T(1) - T(2) * (x * x + z * z), T(2) * (y * z - w * x)},
                     {T(2) * (x * z - w * y), T(2) * (y * z + w * x), T(1) - T(2) * (x * x + y * y)}};
  for (int i = 0; i < 3; ++i) out[i] = R[0][i] * v[0] + R[1][i] * v[1] + R[2][i] * v[2];
}

struct Transition {
  std::vector<double> t;
  std::vector<Vec3> y;  // bias-free raw rates
  Vec3 u_start, u_end;  // measured gravity directions (calibrated accelerometer frame)
};

struct GravityDirectionResidual {
  GravityDirectionResidual(const Transition* tr, bool misalignment) : tr_(tr), misalignment_(misalignment) {}
  template <typename T>
  bool operator()(const T* const p, T* r) const {
    // p = (t01, t02, t10, t12, t20, t21, k0, k1, k2)
    const T zero(0);
    const T t01 = misalignment_ ? p[0] : zero, t02 = misalignment_ ? p[1] : zero, t10 = misalignment_ ? p[2] : zero,
            t12 = misalignment_ ? p[3] : zero, t20 = misalignment_ ? p[4] : zero, t21 = misalignment_ ? p[5] : zero;
    auto omega = [&](std::size_t i, T* w) {
      const Vec3& y = tr_->y[i];
      const T u0 = p[6] * T(y[0]), u1 = p[7] * T(y[1]), u2 = p[8] * T(y[2]);
      w[0] = u0 + t01 * u1 + t02 * u2;
      w[1] = t10 * u0 + u1 + t12 * u2;
      w[2] = t20 * u0 + t21 * u1 + u2;
    };
    T q[4] = {T(1), T(0), T(0), T(0)};
    T w0[3], w1[3];
    omega(0, w0);
    for (std::size_t i = 0; i + 1 < tr_->t.size(); ++i) {
      omega(i + 1, w1);
      rk4_step(q, w0, w1, tr_->t[i + 1] - tr_->t[i]);
      std::copy(w1, w1 + 3, w0);
    }
    const T us[3] = {T(tr_->u_start[0]), T(tr_->u_start[1]), T(tr_->u_start[2])};
    T pred[3];
    rotate_inverse(q, us, pred);
    for (int i = 0; i < 3; ++i) r[i] = T(tr_->u_end[i]) - pred[i];
    return true;
  }
  const Transition* tr_;
  bool misalignment_;
};

double rms_angle(const std::vector<Transition>& trs, const Mat3& C) {
  double ss = 0.0;
  for (const auto& tr : trs) {
    std::vector<Vec3> w(tr.y.size());
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = C * tr.y[i];
    const Mat3 R = integrate_rotation(tr.t, w);
    ss += std::pow(angle_between(R.transpose() * tr.u_start, tr.u_end), 2);
  }
  return trs.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(trs.size()));
}

std::string prefix(const std::string& source) { return source.empty() ? "" : source + ": "; }

}  // namespace

Mat3 integrate_rotation(const std::vector<double>& t, const std::vector<Vec3>& omega) {
  double q[4] = {1, 0, 0, 0};
  for (std::size_t i = 0; i + 1 < t.size(); ++i) rk4_step(q, omega[i].data(), omega[i + 1].data(), t[i + 1] - t[i]);
  return Quat(q[0], q[1], q[2], q[3]).toRotationMatrix();
}

Vec3 gyroscope_bias(const std::vector<StaticFrame>& frames, const std::string& source) {
  Vec3 sum = Vec3::Zero();
  std::size_t n = 0;
  for (const auto& f : frames) {
    sum += f.gyro_mean * static_cast<double>(f.gyro_samples);
    n += f.gyro_samples;
  }
  if (n == 0)
    throw MeasurementError(prefix(source) + fmt::format("gyroscope bias: none of the {} static frames has gyroscope "
                                                        "samples (is the gyroscope stream missing?)",
                                                        frames.size()));
  return sum / static_cast<double>(n);
}

GyroscopeCalibration fit_gyroscope(const Stream& gyro, const std::vector<StaticFrame>& frames,
                                   const AccelerometerCalibration& acc, const GyroscopeOptions& options,
                                   const std::string& source) {
  GyroscopeCalibration c;
  c.bias = gyroscope_bias(frames, source);
  c.frames = frames.size();
  std::vector<Transition> trs;
  for (std::size_t k = 0; k + 1 < frames.size(); ++k) {
    // From the end of one static frame to the start of the next. The frames are trimmed
    // (StaticFrameOptions::trim_s), so the slow start and end of the move, which the detector
    // may accept as still, are integrated too; rotation missed there would be absorbed by a too
    // large scale. Integrating from the frame middles instead adds long still stretches (50 s
    // in the Xsens recording) in which only the bias error accumulates.
    const double ts = frames[k].t1, te = frames[k + 1].t0;
    if (te - ts > options.max_transition_s) continue;
    auto b = std::upper_bound(gyro.t.begin(), gyro.t.end(), ts);
    if (b != gyro.t.begin()) --b;
    auto e = std::lower_bound(gyro.t.begin(), gyro.t.end(), te);
    if (e == gyro.t.end()) continue;
    Transition tr;
    for (auto it = b; it <= e; ++it) {
      const auto i = static_cast<std::size_t>(it - gyro.t.begin());
      tr.t.push_back(gyro.t[i]);
      tr.y.push_back(gyro.xyz(i) - c.bias);
    }
    if (tr.t.size() < 3) continue;
    tr.u_start = acc.correct(frames[k].acc_mean).normalized();
    tr.u_end = acc.correct(frames[k + 1].acc_mean).normalized();
    trs.push_back(std::move(tr));
  }
  c.transitions = trs.size();
  const std::size_t need = options.fit_misalignment ? 5 : 2;
  if (trs.size() < need)
    throw MeasurementError(prefix(source) + fmt::format("gyroscope calibration: found {} usable moves between static "
                                                        "frames ({} static frames), need at least {}; rotate the device "
                                                        "between still poses about every axis",
                                                        trs.size(), frames.size(), need));
  {
    // Raw: undo the bias removal (y + b).
    double ss = 0.0;
    for (const auto& tr : trs) {
      std::vector<Vec3> w(tr.y.size());
      for (std::size_t i = 0; i < w.size(); ++i) w[i] = tr.y[i] + c.bias;
      const Mat3 R = integrate_rotation(tr.t, w);
      ss += std::pow(angle_between(R.transpose() * tr.u_start, tr.u_end), 2);
    }
    c.rms_raw = std::sqrt(ss / static_cast<double>(trs.size()));
  }
  c.rms_bias_only = rms_angle(trs, Mat3::Identity());

  double p[9] = {0, 0, 0, 0, 0, 0, 1, 1, 1};
  ceres::Problem problem;
  for (const auto& tr : trs)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GravityDirectionResidual, 3, 9>(
                                 new GravityDirectionResidual(&tr, options.fit_misalignment)),
                             nullptr, p);
  if (!options.fit_misalignment) problem.SetManifold(p, new ceres::SubsetManifold(9, {0, 1, 2, 3, 4, 5}));
  const ceres::Solver::Summary summary = solve_levenberg_marquardt(problem, 100, 1e-12);
  if (!summary.IsSolutionUsable())
    throw MeasurementError(prefix(source) + "gyroscope fit failed: " + summary.message);
  c.misalignment << 1, p[0], p[1], p[2], 1, p[3], p[4], p[5], 1;
  c.scale = Vec3(p[6], p[7], p[8]);
  c.rms_after = rms_angle(trs, c.correction());
  const std::size_t dof = 2 * trs.size();  // each residual is a unit-vector difference: 2 degrees of freedom
  const std::size_t params = options.fit_misalignment ? 9 : 3;
  if (dof > params) parameter_sigmas(problem, p, summary.final_cost, static_cast<double>(dof - params), c.sigma);
  return c;
}

void canonical_gyroscope(const Mat3& C, Mat3& T, Vec3& k) {
  k = C.diagonal();
  T = C * k.cwiseInverse().asDiagonal();
}

}  // namespace antpose::calibration
