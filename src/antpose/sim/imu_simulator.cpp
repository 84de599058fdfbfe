#include "antpose/sim/imu_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/yaml_util.hpp"
#include "antpose/sim/random.hpp"
#include "antpose/geomag/earth_model.hpp"

namespace antpose::sim {

namespace {

constexpr double kStandardGravity = 9.80665;
constexpr double kMicroG = 1e-6 * kStandardGravity;  // m/s^2

void check_duration(double duration_s, const char* what) {
  if (!std::isfinite(duration_s) || duration_s <= 0.0)
    throw std::invalid_argument(fmt::format("{}: duration {} s must be positive", what, duration_s));
}

// Minimum-jerk profile s(τ) and its first two derivatives with respect to τ.
struct Profile {
  double s, ds, dds;
};
Profile min_jerk(double tau) {
  tau = std::clamp(tau, 0.0, 1.0);
  const double t2 = tau * tau, t3 = t2 * tau;
  return {t3 * (10.0 - 15.0 * tau + 6.0 * t2), 30.0 * t2 * (1.0 - 2.0 * tau + t2),
          60.0 * tau - 180.0 * t2 + 120.0 * t3};
}

// Right Jacobian of SO(3): exp(θ)^T d/dt exp(θ) = [J_r(θ) θ̇]× (Barfoot, State Estimation for
// Robotics, eq. 7.77b).
Mat3 right_jacobian(const Vec3& theta) {
  const double phi = theta.norm();
  const Mat3 K = skew(theta);
  double a, b;  // (1 − cos φ)/φ², (φ − sin φ)/φ³
  if (phi < 1e-4) {
    const double p2 = phi * phi;
    a = 0.5 - p2 / 24.0;
    b = 1.0 / 6.0 - p2 / 120.0;
  } else {
    a = (1.0 - std::cos(phi)) / (phi * phi);
    b = (phi - std::sin(phi)) / (phi * phi * phi);
  }
  return Mat3::Identity() - a * K + b * K * K;
}

constexpr std::uint32_t kImuStreams = 0x5eedu;  // make_rng's salt

Vec3 normal3(std::mt19937_64& rng, double sigma = 1.0) {
  std::normal_distribution<double> n(0.0, sigma);
  const double x = n(rng), y = n(rng), z = n(rng);
  return {x, y, z};
}

// Uniform random rotation (Shoemake, "Uniform random rotations", Graphics Gems III, 1992).
Mat3 uniform_rotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double two_pi = 2.0 * std::numbers::pi;
  const Quat q(b * std::cos(two_pi * u3), a * std::sin(two_pi * u2), a * std::cos(two_pi * u2),
               b * std::sin(two_pi * u3));
  return q.normalized().toRotationMatrix();
}

Mat3 small_offdiagonal(std::mt19937_64& rng, double sigma) {
  Mat3 M = Mat3::Identity();
  std::normal_distribution<double> n(0.0, sigma);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) M(i, j) = n(rng);
  return M;
}

// Sample times k/rate + phase + jitter_k, jitter normal truncated at ±0.45/rate so that the
// times strictly increase.
std::vector<double> sample_times(double rate_hz, double jitter_s, double duration, std::mt19937_64& rng) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0)
    throw std::invalid_argument(fmt::format("sample rate {} Hz must be positive", rate_hz));
  if (!std::isfinite(jitter_s) || jitter_s < 0.0)
    throw std::invalid_argument(fmt::format("rate jitter {} s must be >= 0", jitter_s));
  const double period = 1.0 / rate_hz;
  std::uniform_real_distribution<double> phase_dist(0.0, period);
  std::normal_distribution<double> jitter(0.0, jitter_s);
  const double phase = phase_dist(rng);
  const double limit = 0.45 * period;
  std::vector<double> t;
  t.reserve(static_cast<std::size_t>(duration * rate_hz) + 2);
  for (std::size_t k = 0;; ++k) {
    const double nominal = phase + static_cast<double>(k) * period;
    if (nominal > duration) break;
    const double j = jitter_s > 0.0 ? std::clamp(jitter(rng), -limit, limit) : 0.0;
    t.push_back(std::clamp(nominal + j, 0.0, duration));
  }
  // Clamping to [0, duration] could tie the first or last two samples; drop such ties.
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

// Inertial sensor stream: y = T K x + b + b_w + n, with the bias walk and noise discretised
// per IEEE Std 952 (see the header).
template <typename TrueValue>
Stream inertial_stream(std::string name, const InertialSensorErrors& e, double duration, std::mt19937_64& rng,
                       TrueValue&& truth) {
  const auto t = sample_times(e.rate_hz, e.rate_jitter_s, duration, rng);
  const double white_std = e.noise_density * std::sqrt(e.rate_hz);
  std::vector<Vec3> y(t.size());
  Vec3 walk = Vec3::Zero();
  double prev = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (e.bias_random_walk > 0.0) walk += normal3(rng, e.bias_random_walk * std::sqrt(t[k] - prev));
    prev = t[k];
    y[k] = e.apply(truth(t[k]), walk);
    if (white_std > 0.0) y[k] += normal3(rng, white_std);
  }
  return Stream::vector3(std::move(name), t, y);
}

using io::yaml_flow_matrix;
using io::yaml_flow_vector;
using io::yaml_scalar;

YAML::Node inertial_yaml(const InertialSensorErrors& e, const char* unit) {
  YAML::Node n;
  n["unit"] = unit;
  n["misalignment"] = yaml_flow_matrix(e.misalignment);
  n["scale"] = yaml_flow_vector(e.scale);
  n["bias"] = yaml_flow_vector(e.bias);
  n["noise_density"] = yaml_scalar(e.noise_density);
  n["bias_random_walk"] = yaml_scalar(e.bias_random_walk);
  n["rate_hz"] = yaml_scalar(e.rate_hz);
  n["rate_jitter_s"] = yaml_scalar(e.rate_jitter_s);
  return n;
}

}  // namespace

// --- sensor models ------------------------------------------------------------------------

Vec3 InertialSensorErrors::apply(const Vec3& x, const Vec3& bias_walk) const {
  return misalignment * scale.cwiseProduct(x) + bias + bias_walk;
}

PhoneModel PhoneModel::ideal() {
  PhoneModel p;
  p.name = "ideal";
  p.accelerometer.rate_hz = 100;
  p.gyroscope.rate_hz = 100;
  p.magnetometer.rate_hz = 50;
  return p;
}

PhoneModel PhoneModel::typical() {
  PhoneModel p;
  p.name = "typical";
  auto& a = p.accelerometer;
  a.noise_density = 180.0 * kMicroG;    // BMI160: 180 µg/√Hz
  a.bias_random_walk = 4e-4;            // m/s^3/√Hz, consumer MEMS (bias instability ≈ 0.05 mg)
  a.bias = Vec3(0.06, -0.09, 0.12);     // ≈ 6–12 mg residual after factory calibration
  a.scale = Vec3(1.004, 0.997, 1.002);  // sensitivity tolerance ≈ ±0.5 % after trim
  a.misalignment = Mat3::Identity();
  a.misalignment(0, 1) = 0.003;
  a.misalignment(0, 2) = -0.002;  // cross-axis ≈ 0.3 %
  a.misalignment(1, 0) = -0.001;
  a.misalignment(1, 2) = 0.002;
  a.misalignment(2, 0) = 0.002;
  a.misalignment(2, 1) = -0.003;
  a.rate_hz = 100;
  a.rate_jitter_s = 5e-4;
  auto& g = p.gyroscope;
  g.noise_density = deg2rad(0.007);                             // BMI160: 0.007 °/s/√Hz
  g.bias_random_walk = 3e-5;                                    // rad/s^2/√Hz
  g.bias = Vec3(deg2rad(0.15), deg2rad(-0.10), deg2rad(0.20));  // residual zero-rate offset
  g.scale = Vec3(0.996, 1.003, 1.005);                          // ±1 % sensitivity tolerance, partly trimmed
  g.misalignment = Mat3::Identity();
  g.misalignment(0, 1) = -0.004;
  g.misalignment(0, 2) = 0.002;
  g.misalignment(1, 0) = 0.003;
  g.misalignment(1, 2) = -0.002;
  g.misalignment(2, 0) = -0.001;
  g.misalignment(2, 1) = 0.003;
  g.rate_hz = 100;
  g.rate_jitter_s = 5e-4;
  auto& m = p.magnetometer;
  m.hard_iron_uT = Vec3(1.5, -2.0, 2.5);  // residual after the OS's hard-iron calibration
  m.soft_iron << 1.01, 0.01, -0.005,      // ≈ 1 % soft iron from the phone's parts
      0.01, 0.99, 0.008, -0.005, 0.008, 1.02;
  m.noise_uT = 0.4;  // AK09918: ≈ 0.3–0.6 µT rms
  m.rate_hz = 50;
  m.rate_jitter_s = 1e-3;
  return p;
}

PhoneModel PhoneModel::random(std::mt19937_64& rng) {
  const PhoneModel t = typical();
  PhoneModel p = t;
  p.name = "random";
  std::uniform_real_distribution<double> factor(0.7, 1.3);
  auto& a = p.accelerometer;
  a.bias = normal3(rng, 0.1);  // ≈ 10 mg per axis
  a.scale = Vec3::Ones() + normal3(rng, 0.004);
  a.misalignment = small_offdiagonal(rng, 0.003);
  a.noise_density = t.accelerometer.noise_density * factor(rng);
  a.bias_random_walk = t.accelerometer.bias_random_walk * factor(rng);
  auto& g = p.gyroscope;
  g.bias = normal3(rng, deg2rad(0.2));
  g.scale = Vec3::Ones() + normal3(rng, 0.005);
  g.misalignment = small_offdiagonal(rng, 0.003);
  g.noise_density = t.gyroscope.noise_density * factor(rng);
  g.bias_random_walk = t.gyroscope.bias_random_walk * factor(rng);
  auto& m = p.magnetometer;
  m.hard_iron_uT = normal3(rng, 2.5);
  Mat3 E = small_offdiagonal(rng, 0.01) - Mat3::Identity();
  E.diagonal() = normal3(rng, 0.015);
  m.soft_iron = Mat3::Identity() + 0.5 * (E + E.transpose());  // symmetric, as physical soft iron is
  m.noise_uT = t.magnetometer.noise_uT * factor(rng);
  return p;
}

// --- trajectory ---------------------------------------------------------------------------

Trajectory::Trajectory(const Mat3& R_world_device_start, const Vec3& p_world_start)
    : R_start_(R_world_device_start), p_start_(p_world_start) {}

void Trajectory::append(Segment s) {
  s.t0 = duration();
  segments_.push_back(std::move(s));
}

Trajectory& Trajectory::hold(const Mat3& R_world_device, double duration_s) {
  check_duration(duration_s, "Trajectory::hold");
  if (segments_.empty()) {
    R_start_ = R_world_device;
  } else if (rotation_distance(R_world_device, end_R_world_device()) > 1e-9) {
    throw std::invalid_argument(
        fmt::format("Trajectory::hold: the pose differs by {:.6f}° from the end of the previous segment; use rotate_to",
                    rad2deg(rotation_distance(R_world_device, end_R_world_device()))));
  }
  return hold(duration_s);
}

Trajectory& Trajectory::hold(double duration_s) {
  check_duration(duration_s, "Trajectory::hold");
  Segment s;
  s.duration = duration_s;
  s.R0 = end_R_world_device();
  s.p0 = end_position_world();
  append(s);
  return *this;
}

Trajectory& Trajectory::rotate_to(const Mat3& R_world_device, double duration_s) {
  return move_to(R_world_device, end_position_world(), duration_s);
}

Trajectory& Trajectory::move_to(const Mat3& R_world_device, const Vec3& p_world, double duration_s) {
  check_duration(duration_s, "Trajectory::move_to");
  Segment s;
  s.duration = duration_s;
  s.R0 = end_R_world_device();
  s.rotvec = log_so3(s.R0.transpose() * R_world_device);
  s.p0 = end_position_world();
  s.dp = p_world - s.p0;
  s.moving = true;
  append(s);
  return *this;
}

Trajectory& Trajectory::walk_to(const Mat3& R_world_device, const Vec3& p_world, double duration_s,
                                const GaitBob& bob) {
  if (!(bob.amplitude_m >= 0.0) || !(bob.frequency_hz > 0.0))
    throw std::invalid_argument("Trajectory::walk_to: the bob's amplitude must be >= 0 and its frequency > 0");
  move_to(R_world_device, p_world, duration_s);
  segments_.back().bob = bob;
  return *this;
}

Trajectory& Trajectory::with_tremor(double rotation_rms_rad, double translation_rms_m, std::uint64_t seed) {
  if (!(rotation_rms_rad >= 0.0) || !(translation_rms_m >= 0.0))
    throw std::invalid_argument("Trajectory::with_tremor: amplitudes must be >= 0");
  auto rng = make_rng(seed, 0x7e, kImuStreams);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  // Per band: (variance fraction, lowest and highest frequency in Hz, number of sinusoids).
  struct Band {
    double fraction, f_lo, f_hi;
    int count;
  };
  constexpr Band kBands[] = {{0.3, 8.0, 12.0, 4}, {0.7, 0.05, 0.5, 3}};
  auto make = [&](double rms) {
    std::vector<Sinusoid> out;
    if (rms == 0.0) return out;
    for (const auto& band : kBands) {
      std::uniform_real_distribution<double> f(band.f_lo, band.f_hi);
      // Each axis sinusoid of amplitude a adds a²/2 to E|θ|²; 3·count of them share the band.
      const double a = std::sqrt(2.0 * band.fraction * rms * rms / (3.0 * band.count));
      for (int i = 0; i < band.count; ++i) {
        const double omega = 2.0 * std::numbers::pi * f(rng);
        const Vec3 ph(phase(rng), phase(rng), phase(rng));
        out.push_back({Vec3::Constant(a), omega, ph});
      }
    }
    return out;
  };
  tremor_rotation_ = make(rotation_rms_rad);
  tremor_translation_ = make(translation_rms_m);
  return *this;
}

double Trajectory::duration() const {
  return segments_.empty() ? 0.0 : segments_.back().t0 + segments_.back().duration;
}

Mat3 Trajectory::end_R_world_device() const {
  if (segments_.empty()) return R_start_;
  const auto& s = segments_.back();
  return s.R0 * exp_so3(s.rotvec);
}

Vec3 Trajectory::end_position_world() const {
  if (segments_.empty()) return p_start_;
  const auto& s = segments_.back();
  return s.p0 + s.dp;
}

const Trajectory::Segment& Trajectory::segment_at(double t) const {
  if (segments_.empty()) throw std::invalid_argument("Trajectory: no segments (add hold/rotate_to first)");
  auto it =
      std::upper_bound(segments_.begin(), segments_.end(), t, [](double v, const Segment& s) { return v < s.t0; });
  return it == segments_.begin() ? segments_.front() : *std::prev(it);
}

namespace {

// The gait bob's height and its second time derivative at t inside a segment (GaitBob).
std::pair<double, double> bob_height(const GaitBob& bob, double t_in, double duration) {
  if (bob.amplitude_m == 0.0) return {0.0, 0.0};
  const double tau = std::clamp(t_in / duration, 0.0, 1.0), u = tau * (1.0 - tau);
  const double w = 64.0 * u * u * u;
  const double dw = 192.0 * u * u * (1.0 - 2.0 * tau) / duration;
  const double ddw = 384.0 * u * ((1.0 - 2.0 * tau) * (1.0 - 2.0 * tau) - u) / (duration * duration);
  const double omega = 2.0 * std::numbers::pi * bob.frequency_hz;
  const double sn = std::sin(omega * t_in), cs = std::cos(omega * t_in);
  return {bob.amplitude_m * w * sn, bob.amplitude_m * (ddw * sn + 2.0 * dw * omega * cs - w * omega * omega * sn)};
}

template <typename Sinusoids>
Vec3 sum_sin(const Sinusoids& list, double t, int derivative) {
  Vec3 out = Vec3::Zero();
  for (const auto& s : list)
    for (int i = 0; i < 3; ++i) {
      const double arg = s.omega * t + s.phase[i];
      switch (derivative) {
        case 0:
          out[i] += s.amplitude[i] * std::sin(arg);
          break;
        case 1:
          out[i] += s.amplitude[i] * s.omega * std::cos(arg);
          break;
        default:
          out[i] -= s.amplitude[i] * s.omega * s.omega * std::sin(arg);
          break;
      }
    }
  return out;
}
}  // namespace

Mat3 Trajectory::R_world_device(double t) const {
  const Segment& s = segment_at(t);
  t = std::clamp(t, 0.0, duration());
  const Profile p = min_jerk((t - s.t0) / s.duration);
  Mat3 R = s.moving ? Mat3(s.R0 * exp_so3(p.s * s.rotvec)) : s.R0;
  if (!tremor_rotation_.empty()) R = R * exp_so3(sum_sin(tremor_rotation_, t, 0));
  return R;
}

Vec3 Trajectory::position_world(double t) const {
  const Segment& s = segment_at(t);
  t = std::clamp(t, 0.0, duration());
  const Profile p = min_jerk((t - s.t0) / s.duration);
  Vec3 x = s.p0 + p.s * s.dp;
  if (s.bob.amplitude_m > 0.0) x.z() += bob_height(s.bob, t - s.t0, s.duration).first;
  if (!tremor_translation_.empty()) x += sum_sin(tremor_translation_, t, 0);
  return x;
}

Vec3 Trajectory::angular_velocity_device(double t) const {
  const Segment& s = segment_at(t);
  if (t < 0.0 || t > duration()) return Vec3::Zero();
  const Profile p = min_jerk((t - s.t0) / s.duration);
  // Nominal R_n = R0 exp(s w): body rate ṡ w, constant axis.
  Vec3 omega = s.moving ? Vec3(p.ds / s.duration * s.rotvec) : Vec3::Zero();
  if (!tremor_rotation_.empty()) {
    // R = R_n exp(θ): ω = exp(θ)^T ω_n + J_r(θ) θ̇.
    const Vec3 theta = sum_sin(tremor_rotation_, t, 0);
    omega = exp_so3(theta).transpose() * omega + right_jacobian(theta) * sum_sin(tremor_rotation_, t, 1);
  }
  return omega;
}

Vec3 Trajectory::acceleration_world(double t) const {
  const Segment& s = segment_at(t);
  if (t < 0.0 || t > duration()) return Vec3::Zero();
  const Profile p = min_jerk((t - s.t0) / s.duration);
  Vec3 a = s.moving ? Vec3(p.dds / (s.duration * s.duration) * s.dp) : Vec3::Zero();
  if (s.bob.amplitude_m > 0.0) a.z() += bob_height(s.bob, t - s.t0, s.duration).second;
  if (!tremor_translation_.empty()) a += sum_sin(tremor_translation_, t, 2);
  return a;
}

bool Trajectory::moving(double t) const { return segment_at(t).moving; }

std::vector<std::pair<double, double>> Trajectory::holds() const {
  std::vector<std::pair<double, double>> out;
  for (const auto& s : segments_)
    if (!s.moving) {
      if (!out.empty() && out.back().second == s.t0)
        out.back().second = s.t0 + s.duration;  // consecutive holds are one
      else
        out.emplace_back(s.t0, s.t0 + s.duration);
    }
  return out;
}

// --- presets ------------------------------------------------------------------------------

Trajectory static_poses(const std::vector<Mat3>& R_world_device, double hold_s, double move_s) {
  if (R_world_device.empty()) throw std::invalid_argument("static_poses: no poses");
  Trajectory tr;
  tr.hold(R_world_device.front(), hold_s);
  for (std::size_t i = 1; i < R_world_device.size(); ++i) tr.rotate_to(R_world_device[i], move_s).hold(hold_s);
  return tr;
}

std::vector<Mat3> calibration_poses() {
  // R_world_device such that the device axis `up` points up (world z): rows chosen as
  // R^T e_z = up. Built from a device-frame "up" and a device-frame "north".
  auto pose = [](const Vec3& up_device, const Vec3& north_device) {
    Mat3 R_device_world;
    R_device_world.col(2) = up_device.normalized();
    R_device_world.col(1) =
        (north_device - north_device.dot(R_device_world.col(2)) * R_device_world.col(2)).normalized();
    R_device_world.col(0) = R_device_world.col(1).cross(R_device_world.col(2));
    return Mat3(R_device_world.transpose());
  };
  const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
  std::vector<Mat3> poses = {pose(ez, ey), pose(-ez, ey), pose(ex, ey), pose(-ex, ey), pose(ey, ez), pose(-ey, ez)};
  const Vec3 axes[3] = {ex, ey, ez};
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      for (int si : {1, -1})
        for (int sj : {1, -1}) {
          const Vec3 up = si * axes[i] + sj * axes[j];
          const Vec3 north = axes[3 - i - j];
          poses.push_back(pose(up, north));
        }
  return poses;
}

Trajectory random_rotations(std::size_t count, double hold_s, double move_s, std::uint64_t seed) {
  if (count == 0) throw std::invalid_argument("random_rotations: count must be positive");
  auto rng = make_rng(seed, 0x40, kImuStreams);
  std::vector<Mat3> poses(count);
  for (auto& R : poses) R = uniform_rotation(rng);
  return static_poses(poses, hold_s, move_s);
}

Trajectory tumble(double duration_s, double move_s, std::uint64_t seed) {
  check_duration(duration_s, "tumble");
  check_duration(move_s, "tumble");
  auto rng = make_rng(seed, 0x70, kImuStreams);
  Trajectory tr;
  tr.hold(uniform_rotation(rng), 1.0);
  while (tr.duration() + move_s + 1.0 <= duration_s || tr.duration() <= 1.0)
    tr.rotate_to(uniform_rotation(rng), move_s);
  tr.hold(1.0);
  return tr;
}

Mat3 contact_device_rotation(const Mat3& R_world_antenna, ContactPlacement placement) {
  return R_world_antenna * contact_rotation(placement).transpose();
}

Trajectory contact_trajectory(const Mat3& R_world_antenna, ContactPlacement placement, const ContactMotion& motion,
                              std::uint64_t seed) {
  const Mat3 R_plate = contact_device_rotation(R_world_antenna, placement);
  // In the hand: 0.3 m towards the person (along the screen normal) and tilted 60° screen-up
  // about the device x axis, turned 15° about its z axis; different on the way out.
  const Vec3 towards_person = R_plate * Vec3::UnitZ();
  const Mat3 R_hand_in = R_plate * rot_x(deg2rad(-60.0)) * rot_z(deg2rad(15.0));
  const Mat3 R_hand_out = R_plate * rot_x(deg2rad(-50.0)) * rot_z(deg2rad(-20.0));
  const Vec3 p_plate = Vec3::Zero();
  Trajectory tr(R_hand_in, p_plate + 0.30 * towards_person);
  tr.hold(motion.before_s)
      .move_to(R_plate, p_plate, motion.approach_s)
      .hold(motion.hold_s)
      .move_to(R_hand_out, p_plate + 0.25 * towards_person, motion.removal_s)
      .hold(motion.after_s);
  if (motion.tremor_rotation_rms_rad > 0.0 || motion.tremor_translation_rms_m > 0.0)
    tr.with_tremor(motion.tremor_rotation_rms_rad, motion.tremor_translation_rms_m, seed);
  return tr;
}

// --- simulation ---------------------------------------------------------------------------

Capture simulate_imu(const ImuSimulation& sim) {
  const Trajectory& tr = sim.trajectory;
  if (tr.empty()) throw std::invalid_argument("simulate_imu: the trajectory is empty");
  if (!std::isfinite(sim.truth_rate_hz) || sim.truth_rate_hz <= 0.0)
    throw std::invalid_argument(fmt::format("simulate_imu: truth rate {} Hz must be positive", sim.truth_rate_hz));
  if (sim.earth_rotation && !sim.site)
    throw std::invalid_argument("simulate_imu: earth_rotation needs a site (latitude)");
  const double T = tr.duration();
  const Vec3 g_world(0.0, 0.0, -sim.gravity);
  const Vec3 earth_world = sim.earth_rotation ? geomag::earth_rate_enu(sim.site->lat_deg) : Vec3::Zero();

  Capture c;
  c.kind = sim.kind;
  c.time_origin = sim.time_origin;
  c.device_model = "simulated " + sim.phone.name;
  c.device_id = "sim-" + sim.phone.name;
  c.sensor_frame = "android";
  c.site = sim.site;
  c.truth_world = sim.truth_world;

  auto rng_acc = make_rng(sim.seed, 1, kImuStreams), rng_gyr = make_rng(sim.seed, 2, kImuStreams),
       rng_mag = make_rng(sim.seed, 3, kImuStreams);
  c.streams.emplace(
      std::string(streams::kAccelerometer),
      inertial_stream(std::string(streams::kAccelerometer), sim.phone.accelerometer, T, rng_acc, [&](double t) {
        return Vec3(tr.R_world_device(t).transpose() * (tr.acceleration_world(t) - g_world));
      }));
  c.streams.emplace(std::string(streams::kGyroscope),
                    inertial_stream(std::string(streams::kGyroscope), sim.phone.gyroscope, T, rng_gyr, [&](double t) {
                      Vec3 w = tr.angular_velocity_device(t);
                      if (sim.earth_rotation) w += tr.R_world_device(t).transpose() * earth_world;
                      return w;
                    }));
  {
    const auto& m = sim.phone.magnetometer;
    const auto t = sample_times(m.rate_hz, m.rate_jitter_s, T, rng_mag);
    std::vector<Vec3> y(t.size());
    for (std::size_t k = 0; k < t.size(); ++k) {
      Vec3 B = sim.field_world_uT;
      for (const auto& d : sim.disturbances)
        if (t[k] >= d.t0 && t[k] < d.t1) B += d.extra_world_uT;
      if (!sim.dipoles.empty()) {
        const Vec3 p = tr.position_world(t[k]);
        for (const auto& d : sim.dipoles) B += dipole_field_uT(d, p);
      }
      y[k] = m.apply(tr.R_world_device(t[k]).transpose() * B);
      if (m.noise_uT > 0.0) y[k] += normal3(rng_mag, m.noise_uT);
    }
    c.streams.emplace(std::string(streams::kMagnetometer), Stream::vector3(std::string(streams::kMagnetometer), t, y));
  }

  Stream truth;
  truth.name = "orientation";
  truth.columns = {"qw", "qx", "qy", "qz", "valid", "moving"};
  const auto n = static_cast<std::size_t>(std::floor(T * sim.truth_rate_hz + 1e-9)) + 1;
  truth.t.resize(n);
  truth.values.resize(static_cast<Eigen::Index>(n), 6);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = std::min(static_cast<double>(j) / sim.truth_rate_hz, T);
    Quat q(tr.R_world_device(t));
    q.normalize();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    truth.t[j] = t;
    truth.values.row(static_cast<Eigen::Index>(j)) << q.w(), q.x(), q.y(), q.z(), 1.0, tr.moving(t) ? 1.0 : 0.0;
  }
  c.truth_orientation = std::move(truth);

  c.generated_files["truth/device.yaml"] = device_yaml(sim);
  c.metadata["truth"]["device"] = "truth/device.yaml";
  c.metadata["source"]["name"] = "antpose simulate";
  c.metadata["source"]["seed"] = std::to_string(sim.seed);
  return c;
}

std::string device_yaml(const ImuSimulation& sim) {
  YAML::Node root;
  root["model"] = "y = T K x + b + b_w(t) + n (accelerometer m/s^2, gyroscope rad/s); m = S B_device + h + n (uT)";
  root["phone"] = sim.phone.name;
  root["seed"] = std::to_string(sim.seed);
  root["accelerometer"] = inertial_yaml(sim.phone.accelerometer, "m/s^2");
  root["gyroscope"] = inertial_yaml(sim.phone.gyroscope, "rad/s");
  YAML::Node mag;
  mag["unit"] = "uT";
  mag["hard_iron_uT"] = yaml_flow_vector(sim.phone.magnetometer.hard_iron_uT);
  mag["soft_iron"] = yaml_flow_matrix(sim.phone.magnetometer.soft_iron);
  mag["noise_uT"] = yaml_scalar(sim.phone.magnetometer.noise_uT);
  mag["rate_hz"] = yaml_scalar(sim.phone.magnetometer.rate_hz);
  mag["rate_jitter_s"] = yaml_scalar(sim.phone.magnetometer.rate_jitter_s);
  root["magnetometer"] = mag;
  root["field_world_uT"] = yaml_flow_vector(sim.field_world_uT);
  root["gravity"] = yaml_scalar(sim.gravity);
  root["earth_rotation"] = sim.earth_rotation;
  YAML::Node dist(YAML::NodeType::Sequence);
  for (const auto& d : sim.disturbances) {
    YAML::Node n;
    n["t0"] = yaml_scalar(d.t0);
    n["t1"] = yaml_scalar(d.t1);
    n["extra_world_uT"] = yaml_flow_vector(d.extra_world_uT);
    dist.push_back(n);
  }
  root["disturbances"] = dist;
  if (!sim.dipoles.empty()) {
    YAML::Node dip(YAML::NodeType::Sequence);
    for (const auto& d : sim.dipoles) {
      YAML::Node n;
      n["p_world_m"] = yaml_flow_vector(d.p_world);
      n["moment_Am2"] = yaml_flow_vector(d.moment_Am2);
      dip.push_back(n);
    }
    root["dipoles"] = dip;
    root["dipoles_model"] = "B += 1e-7 (3 r^ (r^.m) - m) / |r|^3 T at the device position, r = p_device - p_dipole";
  }
  return io::yaml_document(root);
}

std::string contact_scene_yaml(const ContactTruth& truth) {
  const AntennaAttitude att = attitude_from_rotation(truth.R_world_antenna);
  YAML::Node antenna;
  antenna["name"] = "antenna";
  antenna["R_world_antenna"] = yaml_flow_matrix(truth.R_world_antenna);
  if (att.azimuth) {
    antenna["azimuth_deg"] = yaml_scalar(rad2deg(*att.azimuth));
    antenna["magnetic_azimuth_deg"] = yaml_scalar(rad2deg(wrap_2pi(*att.azimuth - truth.declination)));
  }
  antenna["downtilt_deg"] = yaml_scalar(rad2deg(att.downtilt));
  if (att.roll) antenna["roll_deg"] = yaml_scalar(rad2deg(*att.roll));
  antenna["declination_deg"] = yaml_scalar(rad2deg(truth.declination));
  YAML::Node root;
  root["antennas"].push_back(antenna);
  root["contact"]["placement"] = std::string(to_string(truth.placement));
  YAML::Node hold;
  hold.push_back(io::format_number(truth.hold.first));
  hold.push_back(io::format_number(truth.hold.second));
  hold.SetStyle(YAML::EmitterStyle::Flow);
  root["contact"]["hold"] = hold;
  return io::yaml_document(root);
}

Capture simulate_contact(ImuSimulation sim, const Mat3& R_world_antenna, ContactPlacement placement,
                         const ContactMotion& motion) {
  sim.trajectory = contact_trajectory(R_world_antenna, placement, motion, sim.seed);
  sim.kind = "contact";
  ContactTruth truth;
  truth.R_world_antenna = R_world_antenna;
  truth.placement = placement;
  truth.declination = std::atan2(sim.field_world_uT.x(), sim.field_world_uT.y());
  truth.hold = sim.trajectory.holds().at(1);
  Capture c = simulate_imu(sim);
  c.generated_files["truth/scene.yaml"] = contact_scene_yaml(truth);
  c.metadata["truth"]["scene"] = "truth/scene.yaml";
  return c;
}

Vec3 dipole_field_uT(const MagneticDipole& dipole, const Vec3& p_world) {
  const Vec3 r = p_world - dipole.p_world;
  const double d = std::max(r.norm(), 0.05);
  const Vec3 u = r.norm() > 0.0 ? Vec3(r / r.norm()) : Vec3::UnitZ();
  // 1e-7 T·m/A = 0.1 µT·m/A.
  return 0.1 * (3.0 * u * u.dot(dipole.moment_Am2) - dipole.moment_Am2) / (d * d * d);
}

}  // namespace antpose::sim
