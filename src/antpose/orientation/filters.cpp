#include "antpose/orientation/filters.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <fmt/core.h>

#include "antpose/core/statistics.hpp"
#include "antpose/orientation/static_orientation.hpp"

namespace antpose::orientation {
namespace {

using Vec4 = Eigen::Vector4d;

Quat to_quat(const Vec4& q) { return Quat(q[0], q[1], q[2], q[3]); }
Vec4 to_vec4(const Quat& q) { return Vec4(q.w(), q.x(), q.y(), q.z()); }

// Hamilton product a ⊗ b of (w, x, y, z) 4-vectors.
Vec4 qmul(const Vec4& a, const Vec4& b) {
  return Vec4(a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
              a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
              a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
              a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]);
}

bool usable(const Vec3* v) { return v && v->squaredNorm() > 0.0 && v->allFinite(); }

}  // namespace

Quat q_enu_nwu() { return Quat(std::numbers::sqrt2 / 2.0, 0.0, 0.0, std::numbers::sqrt2 / 2.0); }

// ---- Madgwick (report equations) ---------------------------------------------------------

MadgwickFilter::MadgwickFilter(const MadgwickParams& params) : p_(params) {
  if (!(p_.beta >= 0.0) || !(p_.zeta >= 0.0))
    throw std::invalid_argument(fmt::format("madgwick: beta ({}) and zeta ({}) must be >= 0", p_.beta, p_.zeta));
}

void MadgwickFilter::reset(const Quat& q_world_device) {
  q_ = to_vec4((q_enu_nwu().conjugate() * q_world_device).normalized());
  bias_.setZero();
}

Quat MadgwickFilter::q_world_device() const { return (q_enu_nwu() * to_quat(q_)).normalized(); }

void MadgwickFilter::update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) {
  const double q0 = q_[0], q1 = q_[1], q2 = q_[2], q3 = q_[3];
  Vec4 step = Vec4::Zero();
  bool corrected = false;
  if (usable(acc)) {
    const Vec3 a = acc->normalized();
    // f_g and J_g (report eq. 25, 26): gravity (0, 0, 1) predicted in the sensor frame.
    const Vec3 fg(2.0 * (q1 * q3 - q0 * q2) - a.x(), 2.0 * (q0 * q1 + q2 * q3) - a.y(),
                  2.0 * (0.5 - q1 * q1 - q2 * q2) - a.z());
    Eigen::Matrix<double, 3, 4> Jg;
    Jg << -2.0 * q2, 2.0 * q3, -2.0 * q0, 2.0 * q1,  //
        2.0 * q1, 2.0 * q0, 2.0 * q3, 2.0 * q2,      //
        0.0, -4.0 * q1, -4.0 * q2, 0.0;
    step = Jg.transpose() * fg;
    if (p_.use_magnetometer && usable(mag)) {
      const Vec3 m = mag->normalized();
      // h = q ⊗ m ⊗ q*, b = (|h_xy|, 0, h_z) (eq. 45, 46); f_b, J_b (eq. 29, 30) with b itself.
      const Mat3 R = to_quat(q_).toRotationMatrix();
      const Vec3 h = R * m;
      const double bx = std::hypot(h.x(), h.y()), bz = h.z();
      const Vec3 fb(2.0 * bx * (0.5 - q2 * q2 - q3 * q3) + 2.0 * bz * (q1 * q3 - q0 * q2) - m.x(),
                    2.0 * bx * (q1 * q2 - q0 * q3) + 2.0 * bz * (q0 * q1 + q2 * q3) - m.y(),
                    2.0 * bx * (q0 * q2 + q1 * q3) + 2.0 * bz * (0.5 - q1 * q1 - q2 * q2) - m.z());
      Eigen::Matrix<double, 3, 4> Jb;
      Jb << -2.0 * bz * q2, 2.0 * bz * q3, -4.0 * bx * q2 - 2.0 * bz * q0, -4.0 * bx * q3 + 2.0 * bz * q1,  //
          -2.0 * bx * q3 + 2.0 * bz * q1, 2.0 * bx * q2 + 2.0 * bz * q0, 2.0 * bx * q1 + 2.0 * bz * q3,
          -2.0 * bx * q0 + 2.0 * bz * q2,  //
          2.0 * bx * q2, 2.0 * bx * q3 - 4.0 * bz * q1, 2.0 * bx * q0 - 4.0 * bz * q2, 2.0 * bx * q1;
      step += Jb.transpose() * fb;
    }
    const double n = step.norm();
    if (n > 1e-12 && std::isfinite(n)) {
      step /= n;
      corrected = true;
    } else {
      step.setZero();
    }
  }
  if (corrected && p_.zeta > 0.0) {
    const Vec4 conj(q0, -q1, -q2, -q3);
    const Vec3 w_err = 2.0 * qmul(conj, step).tail<3>();  // eq. 47
    bias_ += p_.zeta * w_err * dt;                          // eq. 48
  }
  const Vec3 w = gyro - bias_;  // eq. 49
  const Vec4 q_dot = 0.5 * qmul(q_, Vec4(0.0, w.x(), w.y(), w.z())) - p_.beta * step;
  Vec4 q = q_ + q_dot * dt;
  const double qn = q.norm();
  if (qn > 0.0 && std::isfinite(qn)) q_ = q / qn;  // else keep the last estimate
}

// ---- Madgwick, BROAD's copy of the reference C code --------------------------------------

MadgwickBroadFilter::MadgwickBroadFilter(float beta, float sample_freq_hz) : beta_(beta), sample_freq_(sample_freq_hz) {
  if (!(sample_freq_hz > 0.0f)) throw std::invalid_argument("madgwick-broad: the sample frequency must be positive");
}

void MadgwickBroadFilter::set_state_nwu(const Quat& q) {
  q0_ = static_cast<float>(q.w());
  q1_ = static_cast<float>(q.x());
  q2_ = static_cast<float>(q.y());
  q3_ = static_cast<float>(q.z());
}

void MadgwickBroadFilter::reset(const Quat& q_world_device) { set_state_nwu(q_enu_nwu().conjugate() * q_world_device); }

Quat MadgwickBroadFilter::q_world_device() const {
  return q_enu_nwu() * Quat(static_cast<double>(q0_), static_cast<double>(q1_), static_cast<double>(q2_),
                            static_cast<double>(q3_));
}

namespace {

// The steps both reference updates share, in MadgwickAHRS.cpp's float operation order so that
// the benchmark numbers are reproduced to the last digit.

// q̇ = ½ q ⊗ (0, ω)
void rate_of_change(float q0, float q1, float q2, float q3, float gx, float gy, float gz, float& d1, float& d2,
                    float& d3, float& d4) {
  d1 = 0.5f * (-q1 * gx - q2 * gy - q3 * gz);
  d2 = 0.5f * (q0 * gx + q2 * gz - q3 * gy);
  d3 = 0.5f * (q0 * gy - q1 * gz + q3 * gx);
  d4 = 0.5f * (q0 * gz + q1 * gy - q2 * gx);
}

// q̇ −= β s/|s| (the normalised gradient step)
void descend(float beta, float s0, float s1, float s2, float s3, float& d1, float& d2, float& d3, float& d4) {
  const float recipNorm = 1.0f / std::sqrt(s0 * s0 + s1 * s1 + s2 * s2 + s3 * s3);
  d1 -= beta * (s0 * recipNorm);
  d2 -= beta * (s1 * recipNorm);
  d3 -= beta * (s2 * recipNorm);
  d4 -= beta * (s3 * recipNorm);
}

// q ← normalise(q + q̇ / f)
void integrate(float sample_freq, float q0, float q1, float q2, float q3, float d1, float d2, float d3, float d4,
               float& o0, float& o1, float& o2, float& o3) {
  q0 += d1 * (1.0f / sample_freq);
  q1 += d2 * (1.0f / sample_freq);
  q2 += d3 * (1.0f / sample_freq);
  q3 += d4 * (1.0f / sample_freq);
  const float recipNorm = 1.0f / std::sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
  o0 = q0 * recipNorm;
  o1 = q1 * recipNorm;
  o2 = q2 * recipNorm;
  o3 = q3 * recipNorm;
}

}  // namespace

// The statement order and the float arithmetic follow MadgwickAHRS.cpp (BROAD example_code),
// including the variables _2bx, _2bz that hold bx, bz (the defect the benchmark reproduces).
void MadgwickBroadFilter::update(double /*dt*/, const Vec3& gyro, const Vec3* acc, const Vec3* mag) {
  const float gx = static_cast<float>(gyro.x()), gy = static_cast<float>(gyro.y()), gz = static_cast<float>(gyro.z());
  float ax = 0.0f, ay = 0.0f, az = 0.0f;
  if (acc) ax = static_cast<float>(acc->x()), ay = static_cast<float>(acc->y()), az = static_cast<float>(acc->z());
  float mx = 0.0f, my = 0.0f, mz = 0.0f;
  if (mag) mx = static_cast<float>(mag->x()), my = static_cast<float>(mag->y()), mz = static_cast<float>(mag->z());
  if (mx == 0.0f && my == 0.0f && mz == 0.0f) {
    update_imu(gx, gy, gz, ax, ay, az);
    return;
  }
  float q0 = q0_, q1 = q1_, q2 = q2_, q3 = q3_;
  float qDot1, qDot2, qDot3, qDot4;
  rate_of_change(q0, q1, q2, q3, gx, gy, gz, qDot1, qDot2, qDot3, qDot4);
  if (!(ax == 0.0f && ay == 0.0f && az == 0.0f)) {
    float recipNorm = 1.0f / std::sqrt(ax * ax + ay * ay + az * az);
    ax *= recipNorm;
    ay *= recipNorm;
    az *= recipNorm;
    recipNorm = 1.0f / std::sqrt(mx * mx + my * my + mz * mz);
    mx *= recipNorm;
    my *= recipNorm;
    mz *= recipNorm;
    const float _2q0mx = 2.0f * q0 * mx, _2q0my = 2.0f * q0 * my, _2q0mz = 2.0f * q0 * mz, _2q1mx = 2.0f * q1 * mx;
    const float _2q0 = 2.0f * q0, _2q1 = 2.0f * q1, _2q2 = 2.0f * q2, _2q3 = 2.0f * q3;
    const float _2q0q2 = 2.0f * q0 * q2, _2q2q3 = 2.0f * q2 * q3;
    const float q0q0 = q0 * q0, q0q1 = q0 * q1, q0q2 = q0 * q2, q0q3 = q0 * q3, q1q1 = q1 * q1, q1q2 = q1 * q2,
                q1q3 = q1 * q3, q2q2 = q2 * q2, q2q3 = q2 * q3, q3q3 = q3 * q3;
    const float hx = mx * q0q0 - _2q0my * q3 + _2q0mz * q2 + mx * q1q1 + _2q1 * my * q2 + _2q1 * mz * q3 - mx * q2q2 -
                     mx * q3q3;
    const float hy = _2q0mx * q3 + my * q0q0 - _2q0mz * q1 + _2q1mx * q2 - my * q1q1 + my * q2q2 + _2q2 * mz * q3 -
                     my * q3q3;
    const float _2bx = std::sqrt(hx * hx + hy * hy);
    const float _2bz = -_2q0mx * q2 + _2q0my * q1 + mz * q0q0 + _2q1mx * q3 - mz * q1q1 + _2q2 * my * q3 - mz * q2q2 +
                       mz * q3q3;
    const float _4bx = 2.0f * _2bx, _4bz = 2.0f * _2bz;
    const float ex = 2.0f * q1q3 - _2q0q2 - ax, ey = 2.0f * q0q1 + _2q2q3 - ay;
    const float mfx = _2bx * (0.5f - q2q2 - q3q3) + _2bz * (q1q3 - q0q2) - mx;
    const float mfy = _2bx * (q1q2 - q0q3) + _2bz * (q0q1 + q2q3) - my;
    const float mfz = _2bx * (q0q2 + q1q3) + _2bz * (0.5f - q1q1 - q2q2) - mz;
    const float ez = 1 - 2.0f * q1q1 - 2.0f * q2q2 - az;
    float s0 = -_2q2 * ex + _2q1 * ey - _2bz * q2 * mfx + (-_2bx * q3 + _2bz * q1) * mfy + _2bx * q2 * mfz;
    float s1 = _2q3 * ex + _2q0 * ey - 4.0f * q1 * ez + _2bz * q3 * mfx + (_2bx * q2 + _2bz * q0) * mfy +
               (_2bx * q3 - _4bz * q1) * mfz;
    float s2 = -_2q0 * ex + _2q3 * ey - 4.0f * q2 * ez + (-_4bx * q2 - _2bz * q0) * mfx + (_2bx * q1 + _2bz * q3) * mfy +
               (_2bx * q0 - _4bz * q2) * mfz;
    float s3 = _2q1 * ex + _2q2 * ey + (-_4bx * q3 + _2bz * q1) * mfx + (-_2bx * q0 + _2bz * q2) * mfy + _2bx * q1 * mfz;
    descend(beta_, s0, s1, s2, s3, qDot1, qDot2, qDot3, qDot4);
  }
  integrate(sample_freq_, q0, q1, q2, q3, qDot1, qDot2, qDot3, qDot4, q0_, q1_, q2_, q3_);
}

void MadgwickBroadFilter::update_imu(float gx, float gy, float gz, float ax, float ay, float az) {
  float q0 = q0_, q1 = q1_, q2 = q2_, q3 = q3_;
  float qDot1, qDot2, qDot3, qDot4;
  rate_of_change(q0, q1, q2, q3, gx, gy, gz, qDot1, qDot2, qDot3, qDot4);
  if (!(ax == 0.0f && ay == 0.0f && az == 0.0f)) {
    float recipNorm = 1.0f / std::sqrt(ax * ax + ay * ay + az * az);
    ax *= recipNorm;
    ay *= recipNorm;
    az *= recipNorm;
    const float _2q0 = 2.0f * q0, _2q1 = 2.0f * q1, _2q2 = 2.0f * q2, _2q3 = 2.0f * q3;
    const float _4q0 = 4.0f * q0, _4q1 = 4.0f * q1, _4q2 = 4.0f * q2, _8q1 = 8.0f * q1, _8q2 = 8.0f * q2;
    const float q0q0 = q0 * q0, q1q1 = q1 * q1, q2q2 = q2 * q2, q3q3 = q3 * q3;
    float s0 = _4q0 * q2q2 + _2q2 * ax + _4q0 * q1q1 - _2q1 * ay;
    float s1 = _4q1 * q3q3 - _2q3 * ax + 4.0f * q0q0 * q1 - _2q0 * ay - _4q1 + _8q1 * q1q1 + _8q1 * q2q2 + _4q1 * az;
    float s2 = 4.0f * q0q0 * q2 + _2q0 * ax + _4q2 * q3q3 - _2q3 * ay - _4q2 + _8q2 * q1q1 + _8q2 * q2q2 + _4q2 * az;
    float s3 = 4.0f * q1q1 * q3 - _2q1 * ax + 4.0f * q2q2 * q3 - _2q2 * ay;
    descend(beta_, s0, s1, s2, s3, qDot1, qDot2, qDot3, qDot4);
  }
  integrate(sample_freq_, q0, q1, q2, q3, qDot1, qDot2, qDot3, qDot4, q0_, q1_, q2_, q3_);
}

Quat broad_initial_state(const Vec3& acc, const Vec3& mag) {
  const Vec3 z = acc;
  const Vec3 x = z.cross(-mag).cross(z);
  const Vec3 y = z.cross(x);
  Mat3 R;
  R.col(0) = x / x.norm();
  R.col(1) = y / y.norm();
  R.col(2) = z / z.norm();
  const double w_sq = (1 + R(0, 0) + R(1, 1) + R(2, 2)) / 4, x_sq = (1 + R(0, 0) - R(1, 1) - R(2, 2)) / 4,
               y_sq = (1 - R(0, 0) + R(1, 1) - R(2, 2)) / 4, z_sq = (1 - R(0, 0) - R(1, 1) + R(2, 2)) / 4;
  // numpy.sqrt of a slightly negative rounding result is NaN; clamp as the limit intends.
  return Quat(std::sqrt(std::max(0.0, w_sq)), std::copysign(std::sqrt(std::max(0.0, x_sq)), R(2, 1) - R(1, 2)),
              std::copysign(std::sqrt(std::max(0.0, y_sq)), R(0, 2) - R(2, 0)),
              std::copysign(std::sqrt(std::max(0.0, z_sq)), R(1, 0) - R(0, 1)));
}

// ---- Mahony -----------------------------------------------------------------------------

MahonyFilter::MahonyFilter(const MahonyParams& params) : p_(params) {
  if (!(p_.kp >= 0.0) || !(p_.ki >= 0.0))
    throw std::invalid_argument(fmt::format("mahony: kp ({}) and ki ({}) must be >= 0", p_.kp, p_.ki));
}

void MahonyFilter::reset(const Quat& q_world_device) {
  q_nwu_device_ = (q_enu_nwu().conjugate() * q_world_device).normalized();
  bias_.setZero();
}

Quat MahonyFilter::q_world_device() const { return (q_enu_nwu() * q_nwu_device_).normalized(); }

void MahonyFilter::update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) {
  Vec3 w = gyro - bias_;
  if (usable(acc)) {
    const Mat3 R = q_nwu_device_.toRotationMatrix();  // R_nwu_device
    const Vec3 a = acc->normalized();
    Vec3 e = a.cross(R.row(2).transpose());  // v̂ = Rᵀ e_z
    if (p_.use_magnetometer && usable(mag)) {
      const Vec3 m = mag->normalized();
      const Vec3 h = R * m;
      const Vec3 b(std::hypot(h.x(), h.y()), 0.0, h.z());
      e += m.cross(R.transpose() * b);
    }
    bias_ -= p_.ki * e * dt;
    w = gyro - bias_ + p_.kp * e;
  }
  const Vec3 phi = w * dt;
  const double angle = phi.norm();
  const Quat dq = angle > 1e-12 ? Quat(Eigen::AngleAxisd(angle, phi / angle)) : Quat(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
  const Quat q = (q_nwu_device_ * dq).normalized();
  if (q.coeffs().allFinite()) q_nwu_device_ = q;
}

// ---- eCompass ---------------------------------------------------------------------------

OrientationTrack ecompass_track(const ImuData& data, const EcompassParams& p) {
  if (!data.has_magnetometer())
    throw MeasurementError("ecompass: the capture has no magnetometer stream; heading cannot be estimated");
  if (!(p.window_s >= 0.0)) throw std::invalid_argument("ecompass: window must be >= 0");
  // Prefix sums, offset by the first sample for accuracy.
  struct Prefix {
    const SensorSeries* s;
    Vec3 off;
    std::vector<Vec3> sum;
    std::vector<double> sq;
    explicit Prefix(const SensorSeries& x) : s(&x), off(x.v[0]), sum(x.size() + 1, Vec3::Zero()), sq(x.size() + 1, 0.0) {
      for (std::size_t i = 0; i < x.size(); ++i) {
        const Vec3 d = x.v[i] - off;
        sum[i + 1] = sum[i] + d;
        sq[i + 1] = sq[i] + d.squaredNorm();
      }
    }
    // Mean and RMS scatter over [t0, t1]; false when empty.
    bool stats(double t0, double t1, Vec3& mean, double& scatter) const {
      const auto b = static_cast<std::size_t>(std::lower_bound(s->t.begin(), s->t.end(), t0) - s->t.begin());
      const auto e = static_cast<std::size_t>(std::upper_bound(s->t.begin(), s->t.end(), t1) - s->t.begin());
      if (e <= b) return false;
      const double n = static_cast<double>(e - b);
      const Vec3 md = (sum[e] - sum[b]) / n;
      scatter = std::sqrt(std::max(0.0, (sq[e] - sq[b]) / n - md.squaredNorm()));
      mean = md + off;
      return true;
    }
  };
  const Prefix acc(data.accelerometer), mag(data.magnetometer);
  std::vector<double> norms(data.accelerometer.size());
  for (std::size_t i = 0; i < norms.size(); ++i) norms[i] = data.accelerometer.v[i].norm();
  const double g0 = median(std::move(norms));

  OrientationTrack track;
  track.method = "ecompass";
  const double half = 0.5 * p.window_s;
  const double mag_half = std::max(half, 0.5 * data.magnetometer.median_interval());
  for (std::size_t i = 0; i < data.accelerometer.size(); ++i) {
    const double t = data.accelerometer.t[i];
    Vec3 f, m;
    double fs = 0.0, ms = 0.0;
    if (!acc.stats(t - half, t + half, f, fs) || !mag.stats(t - mag_half, t + mag_half, m, ms)) continue;
    const double fn = f.norm();
    if (!(fn > 0.0)) continue;
    const Vec3 up = f / fn;
    const double H = m.cross(up).norm();
    if (!(H > 1e-6 * m.norm())) continue;
    const Mat3 R = triad_world_device(f, m);
    const double tilt = (fs + p.acc_bias_floor_mps2 + std::abs(fn - g0)) / g0;
    const double dip = std::atan2(-m.dot(up), H);
    const double head_mag = (ms + p.mag_residual_uT / std::sqrt(3.0)) / H;
    const double head = std::hypot(head_mag, tilt * std::tan(std::abs(dip)));
    track.push_back(t, Quat(R), Vec3(tilt * tilt, tilt * tilt, head * head).asDiagonal().toDenseMatrix());
  }
  if (track.empty())
    throw MeasurementError("ecompass: no accelerometer sample has a magnetometer sample within its window");
  return track;
}

}  // namespace antpose::orientation
