// Simulated phone captures: a device trajectory, an inertial/magnetic sensor error model, and
// asynchronous sensor streams with the truth that scores every estimate.
//
// Sensor model (the course's IMU error model, "seed 001"; Titterton & Weston, Strapdown
// Inertial Navigation Technology, 2nd ed., §8.2 and §4.3):
//   accelerometer / gyroscope:  y = T K x + b + b_w(t) + n
//     T  misalignment (unit diagonal, small off-diagonal: axis non-orthogonality / cross-axis),
//     K  diagonal scale factors, b constant (residual) bias,
//     b_w bias random walk (rate random walk), n white noise (angle/velocity random walk).
//   magnetometer:  m = S (R_world_device^T (B_world + d(t))) + h + n
//     S soft iron, h hard iron (µT), d(t) local disturbances (time windows, plus the field of
//     magnetic dipoles evaluated at the device's position), n white noise (µT rms per sample).
// Noise densities follow IEEE Std 952-1997 (Allan-variance coefficients N and K): sampled at
// rate f (Nyquist bandwidth f/2), white noise has std = N·sqrt(f); the bias random walk
// advances by K·sqrt(Δt)·N(0,1) per sample.
//
// Kinematics (frames per docs/conventions.md: world ENU, device = Android):
//   specific force   f_device = R_world_device^T (a_world − g_world),  g_world = (0, 0, −g),
//                    so a phone at rest measures f = R^T (0, 0, +g);
//   angular velocity ω_device from R_world_device^T dR_world_device/dt = [ω_device]×
//                    (analytic; plus R^T ω_earth when `earth_rotation` is set).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "antpose/geometry/attitude.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::sim {

/// Error model of one inertial sensor (accelerometer m/s^2 or gyroscope rad/s):
/// y = T K x + b + b_w(t) + n (see the file comment).
struct InertialSensorErrors {
  Mat3 misalignment = Mat3::Identity();  // T: unit diagonal, small off-diagonal
  Vec3 scale = Vec3::Ones();             // diagonal of K
  Vec3 bias = Vec3::Zero();              // b, unit of the sensor
  double noise_density = 0;              // N: unit/sqrt(Hz) (m/s^2/√Hz or rad/s/√Hz)
  double bias_random_walk = 0;           // K: unit/s/sqrt(Hz)
  double rate_hz = 100;                  // nominal sample rate
  double rate_jitter_s = 0;              // std of the sample-time jitter, s

  /// Applies T K x + b + bias_walk (no noise): the deterministic part of the model.
  Vec3 apply(const Vec3& x, const Vec3& bias_walk = Vec3::Zero()) const;
};

/// Magnetometer error model: m = S B_device + h + n.
struct MagnetometerErrors {
  Vec3 hard_iron_uT = Vec3::Zero();   // h
  Mat3 soft_iron = Mat3::Identity();  // S
  double noise_uT = 0;                // std per axis per sample, µT
  double rate_hz = 50;
  double rate_jitter_s = 0;

  Vec3 apply(const Vec3& B_device_uT) const { return soft_iron * B_device_uT + hard_iron_uT; }
};

struct PhoneModel {
  std::string name = "ideal";  // written as device.model ("simulated <name>")
  InertialSensorErrors accelerometer;
  InertialSensorErrors gyroscope;
  MagnetometerErrors magnetometer;

  /// No errors, no jitter; accelerometer and gyroscope 100 Hz, magnetometer 50 Hz.
  static PhoneModel ideal();
  /// A mid-range phone after factory calibration. Figures from datasheets: Bosch BMI160
  /// (acc noise 180 µg/√Hz, gyro 0.007 °/s/√Hz), ST LSM6DS3 (cross-axis ≈ 1 %, sensitivity
  /// tolerance ≈ 1 %), AKM AK09918 (0.15 µT/LSB, noise ≈ 0.4 µT rms); residual biases after
  /// calibration of ≈ 10 mg and ≈ 0.2 °/s, residual hard iron of a few µT.
  static PhoneModel typical();
  /// One unit drawn within the tolerances of typical(): biases, scales, misalignment, hard and
  /// soft iron are random; noise densities vary by ±30 %.
  static PhoneModel random(std::mt19937_64& rng);
};

/// A local magnetic disturbance: an extra field (world frame, µT) present for t0 <= t < t1.
struct MagneticDisturbance {
  double t0 = 0;
  double t1 = 0;
  Vec3 extra_world_uT = Vec3::Zero();
};

/// A point magnetic dipole (a magnetised steel part: a mast is a line of them), world frame.
struct MagneticDipole {
  Vec3 p_world = Vec3::Zero();     // m
  Vec3 moment_Am2 = Vec3::Zero();  // A·m²
};

/// Field of a dipole at p_world, µT: μ0/(4π) (3 r̂ (r̂·m) − m) / |r|³ with r = p_world − p_dipole
/// (μ0/(4π) = 1e-7 T·m/A); |r| is floored at 5 cm (the field inside steel is not a dipole's).
Vec3 dipole_field_uT(const MagneticDipole& dipole, const Vec3& p_world);

/// The vertical bob of a walker's hand: each step lifts and lowers the body (Zijlstra & Hof,
/// "Displacement of the pelvis during human walking", Gait & Posture 1997: 2–5 cm at the pelvis,
/// about two steps per second).
struct GaitBob {
  double amplitude_m = 0.0;    // 0: none
  double frequency_hz = 2.0;   // steps per second
};

/// A trajectory of the device: R_world_device(t) and position p_world(t), built from segments
/// (holds and smooth minimum-jerk moves) with an optional hand tremor on top. Time runs from 0
/// to duration(); queries outside are clamped. The start pose is identity at the origin unless
/// the first segment is a hold (which then sets it) or the constructor sets it.
class Trajectory {
 public:
  Trajectory() = default;
  explicit Trajectory(const Mat3& R_world_device_start, const Vec3& p_world_start = Vec3::Zero());

  /// Appends a still pose held for `duration_s`. On a non-empty trajectory the pose must equal
  /// the current end pose (std::invalid_argument otherwise; use rotate_to to get there).
  Trajectory& hold(const Mat3& R_world_device, double duration_s);
  /// Holds the current end pose.
  Trajectory& hold(double duration_s);
  /// Appends a rotation to `R_world_device` over `duration_s` along the geodesic
  /// R0 exp(s(τ) log(R0^T R1)) with the minimum-jerk profile s(τ) = 10τ³ − 15τ⁴ + 6τ⁵
  /// (Flash & Hogan 1985), so angular velocity and acceleration start and end at zero.
  Trajectory& rotate_to(const Mat3& R_world_device, double duration_s);
  /// Same with a simultaneous minimum-jerk translation to `p_world` (m).
  Trajectory& move_to(const Mat3& R_world_device, const Vec3& p_world, double duration_s);
  /// move_to walked: plus the vertical bob A w(τ) sin(2π f (t − t0)), faded in and out by
  /// w(τ) = 64 τ³ (1 − τ)³ (which starts and ends with zero position, velocity and acceleration,
  /// so the holds around the walk stay still). Orientation and rate as move_to.
  Trajectory& walk_to(const Mat3& R_world_device, const Vec3& p_world, double duration_s, const GaitBob& bob);
  /// Hand tremor over the whole trajectory: R = R_nominal exp(θ(t)), p = p_nominal + δ(t), with
  /// θ and δ sums of sinusoids — 30 % of the variance in the physiological 8–12 Hz band, 70 %
  /// in a slow drift (0.05–0.5 Hz). `rotation_rms_rad` is the RMS of |θ|, `translation_rms_m`
  /// that of |δ|. Replaces an earlier tremor.
  Trajectory& with_tremor(double rotation_rms_rad, double translation_rms_m, std::uint64_t seed);

  double duration() const;
  bool empty() const { return segments_.empty(); }
  Mat3 R_world_device(double t) const;
  Vec3 position_world(double t) const;
  /// Body angular velocity ω_device (rad/s): R^T Ṙ = [ω]×, analytic.
  Vec3 angular_velocity_device(double t) const;
  /// d²p_world/dt², m/s^2, analytic.
  Vec3 acceleration_world(double t) const;
  /// True inside a move segment (rotate_to/move_to), false inside a hold (tremor ignored).
  bool moving(double t) const;
  /// Start and end times of the hold segments, in order.
  std::vector<std::pair<double, double>> holds() const;
  Mat3 end_R_world_device() const;
  Vec3 end_position_world() const;

 private:
  struct Segment {
    double t0 = 0, duration = 0;
    Mat3 R0 = Mat3::Identity();
    Vec3 rotvec = Vec3::Zero();  // log(R0^T R1), body frame
    Vec3 p0 = Vec3::Zero(), dp = Vec3::Zero();
    bool moving = false;
    GaitBob bob;  // walked moves only
  };
  struct Sinusoid {
    Vec3 amplitude;  // per axis
    double omega;    // rad/s
    Vec3 phase;
  };
  const Segment& segment_at(double t) const;
  void append(Segment s);

  Mat3 R_start_ = Mat3::Identity();
  Vec3 p_start_ = Vec3::Zero();
  std::vector<Segment> segments_;
  std::vector<Sinusoid> tremor_rotation_, tremor_translation_;
};

/// A trajectory through `R_world_device` poses: hold the first for `hold_s`, then for each
/// next pose rotate_to it over `move_s` and hold it for `hold_s`.
Trajectory static_poses(const std::vector<Mat3>& R_world_device, double hold_s, double move_s);
/// The multi-position calibration set: each of the six device axes up, then the twelve
/// edge-up poses in between (18 poses in all), as rotations R_world_device.
std::vector<Mat3> calibration_poses();
/// `count` orientations drawn uniformly on SO(3) (Shoemake 1992), held and joined as in
/// static_poses.
Trajectory random_rotations(std::size_t count, double hold_s, double move_s, std::uint64_t seed);
/// Continuous tumbling: back-to-back moves of `move_s` to random orientations, no holds
/// (except 1 s still at both ends), for about `duration_s`.
Trajectory tumble(double duration_s, double move_s, std::uint64_t seed);

/// Motion of the contact measurement: the phone is brought from the hand onto the antenna's
/// back plate, held there, then taken away.
struct ContactMotion {
  double before_s = 1.0;    // still in the hand before the approach
  double approach_s = 2.5;  // hand → plate
  double hold_s = 8.0;      // lying on the plate
  double removal_s = 2.0;   // plate → hand
  double after_s = 1.0;     // still in the hand at the end
  double tremor_rotation_rms_rad = 0.001;
  double tremor_translation_rms_m = 1e-5;
};

/// R_world_device of a phone lying on the plate: R_world_antenna · R_device_antenna^T.
Mat3 contact_device_rotation(const Mat3& R_world_antenna, ContactPlacement placement);
/// The contact trajectory; the plate hold is holds()[1].
Trajectory contact_trajectory(const Mat3& R_world_antenna, ContactPlacement placement, const ContactMotion& motion,
                              std::uint64_t seed);

struct ImuSimulation {
  Trajectory trajectory;
  PhoneModel phone = PhoneModel::ideal();
  Vec3 field_world_uT = Vec3(0.0, 24.0, -41.569219381653056);  // ENU, µT (48 µT, dip 60°, no declination)
  std::vector<MagneticDisturbance> disturbances;
  std::vector<MagneticDipole> dipoles;  // position-dependent disturbance at the device's position
  double gravity = 9.80665;             // m/s^2 (see geomag::normal_gravity for a site)
  bool earth_rotation = false;          // add Earth's rate (needs `site` for the latitude)
  std::optional<Site> site;
  std::optional<std::string> time_origin;  // ISO-8601 UTC of t = 0
  std::string kind = "imu-log";
  std::string truth_world = "enu-true";
  double truth_rate_hz = 200;
  std::uint64_t seed = 1;
};

/// Runs the simulation. The capture has
///  - streams accelerometer, gyroscope, magnetometer at their own rates, each with a random
///    phase in [0, 1/rate) and jitter (normal, truncated at ±0.45/rate so times increase);
///  - truth_orientation t,qw,qx,qy,qz,valid,moving (q_world_device) at truth_rate_hz;
///  - generated_files["truth/device.yaml"]: the simulated errors (device_yaml) and
///    metadata truth.device naming it.
/// Deterministic for a given seed (independent generators per stream).
/// Throws std::invalid_argument on an empty trajectory or non-positive rates.
Capture simulate_imu(const ImuSimulation& sim);

/// truth/device.yaml text: the phone model, field, gravity, disturbances and seed.
std::string device_yaml(const ImuSimulation& sim);

/// The truth of a contact scene.
struct ContactTruth {
  Mat3 R_world_antenna = Mat3::Identity();
  ContactPlacement placement = ContactPlacement::kTopUp;
  double declination = 0;                // rad, east positive, from the simulated field
  std::pair<double, double> hold{0, 0};  // when the phone lies on the plate, s
};
/// truth/scene.yaml text: antennas[0] with R_world_antenna, azimuth_deg (true),
/// magnetic_azimuth_deg, downtilt_deg, roll_deg, declination_deg, and contact: placement, hold.
std::string contact_scene_yaml(const ContactTruth& truth);

/// A contact capture: `sim` with its trajectory replaced by contact_trajectory(...), kind
/// "contact", and generated_files["truth/scene.yaml"] (metadata truth.scene names it).
Capture simulate_contact(ImuSimulation sim, const Mat3& R_world_antenna,
                         ContactPlacement placement = ContactPlacement::kTopUp, const ContactMotion& motion = {});

}  // namespace antpose::sim
