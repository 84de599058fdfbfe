// Orientation estimators behind one interface: the phone's attitude q_world_device over a whole
// native capture, from asynchronous accelerometer / gyroscope / (optional) magnetometer streams.
//
// Data flow. `ImuData` holds the three streams (device frame, SI units, capture clock) and checks
// them once (gaps, gyroscope saturation, gyroscope bias at rest, magnetic disturbance → warnings).
// `merge_events` interleaves the streams into one time-ordered event list; at equal times the
// order is accelerometer, magnetometer, gyroscope, so a gyroscope sample "sees" the corrections
// taken at its own instant (this makes synchronous data, e.g. BROAD, behave as one 9-D sample).
//
// Gyro-driven filters (Madgwick, Mahony, ...) implement `GyroDrivenFilter` and are run by
// `run_gyro_driven`: each gyroscope sample k is one prediction over dt_k = t_k − t_{k−1} (from the
// time stamps: no equal-rate assumption) followed by a correction with the LATEST accelerometer
// and magnetometer samples ("sample and hold"), passed only while they are fresh (age ≤
// max_hold_s); a stale sensor is passed as nullptr. A gyroscope gap (dt > gap threshold) is not
// integrated: the filter is updated with its nominal dt and its corrections re-converge. One
// output sample per gyroscope sample.
//
// Estimators that need the whole log (smoothers) or their own event handling implement
// `OrientationEstimator::estimate` directly (use merge_events); they return the same
// `OrientationTrack`.
//
// World frame of every estimate: ENU with y along MAGNETIC north ("enu-magnetic"), the local
// horizontal field defining north. `apply_declination` turns a track into "enu-true":
// a vector in ENU-magnetic coordinates is rotated about the vertical by −D (D = declination,
// east positive), R_true_magnetic = Rz(−D), so that a heading h_mag becomes h_mag + D (see
// docs/conventions.md: true azimuth = magnetic azimuth + declination).
//
// Uncertainty (optional, per sample): covariance (rad², world frame) of the error rotation
// vector δ with q_true = exp(δ) ⊗ q_est; δ_z is the heading error, δ_x, δ_y the tilt errors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "antpose/core/error.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::orientation {

/// One sensor's samples: times (s, strictly increasing) and values (device frame).
struct SensorSeries {
  std::vector<double> t;
  std::vector<Vec3> v;
  std::size_t size() const { return t.size(); }
  bool empty() const { return t.empty(); }
  /// Median sample interval (s); 0 for fewer than 2 samples.
  double median_interval() const;
};

/// What the estimators consume: gyroscope (rad/s), accelerometer (specific force, m/s²) and an
/// optional magnetometer (µT), all in the device frame on the capture clock.
struct ImuData {
  SensorSeries gyroscope;
  SensorSeries accelerometer;
  SensorSeries magnetometer;  // empty: 6-D estimation only
  std::filesystem::path source;  // capture folder, for messages
  bool has_magnetometer() const { return !magnetometer.empty(); }
};

struct ImuCheckOptions {
  double gap_factor = 10.0;             // gap: interval > gap_factor × median interval
  double saturation_min_rad_s = 2.0;    // plateaus below this rate are not taken for clipping
  std::size_t saturation_run = 3;       // consecutive equal samples at the stream's extreme
  double rest_window_s = 1.0;           // windows for the bias-at-rest check
  double rest_acc_std_mps2 = 0.05;      // per-axis accelerometer std below which a window is still
  double bias_warning_rad_s = deg2rad(1.0);  // |mean gyro| in a still window above this → warning
  double field_deviation = 0.15;        // | |m| − median |m| | / median above this → disturbed
  double field_min_run_s = 0.25;        // report disturbed runs at least this long
};

/// Copies the capture's gyroscope, accelerometer and (when present) magnetometer streams and runs
/// check_imu_data. InputError naming capture.yaml when the gyroscope or accelerometer is missing
/// or has fewer than 2 samples, or a stream has no x, y, z columns.
ImuData imu_data_from_capture(const Capture& capture, Diagnostics& diagnostics, const ImuCheckOptions& options = {});

/// Warnings for what degrades every estimator: gaps in a stream, gyroscope saturation plateaus,
/// a gyroscope that reads a large rate while the accelerometer is still (bias), and runs where
/// the field norm departs from its median (magnetic disturbance). Non-finite values are an
/// InputError naming the stream.
void check_imu_data(const ImuData& data, Diagnostics& diagnostics, const ImuCheckOptions& options = {});

/// A gyroscope axis that sits at its extreme value for runs of ≥ saturation_run samples.
struct GyroSaturation {
  int axis = 0;
  double level = 0.0;       // rad/s, |value| at which the axis clips
  std::size_t samples = 0;  // samples in such runs
  double first_t = 0.0;     // s, start of the first run
};
/// The clipped axes of a gyroscope stream (the check behind check_imu_data's warning).
std::vector<GyroSaturation> gyro_saturation(const SensorSeries& gyroscope, const ImuCheckOptions& options = {});

enum class Sensor : std::uint8_t { kAccelerometer = 0, kMagnetometer = 1, kGyroscope = 2 };

/// One sample of one stream in the merged, time-ordered sequence.
struct SensorEvent {
  double t = 0.0;
  Sensor sensor = Sensor::kGyroscope;
  std::uint32_t index = 0;  // row in that sensor's series
};

/// All samples of `data` sorted by time; ties ordered accelerometer, magnetometer, gyroscope.
std::vector<SensorEvent> merge_events(const ImuData& data);

/// An estimated attitude trajectory.
struct OrientationTrack {
  std::string method;
  std::string world = "enu-magnetic";  // or "enu-true" after apply_declination
  std::vector<double> t;               // s, increasing
  std::vector<Quat> q_world_device;    // unit quaternions, sign continuous
  std::vector<Mat3> covariance;        // empty, or one per sample (see file comment)

  struct Sample {
    double t = 0.0;
    Quat q_world_device = Quat::Identity();
    std::optional<Mat3> covariance;
    double tilt_sigma() const;     // rad, RMS of the two tilt axes (NaN without covariance)
    double heading_sigma() const;  // rad (NaN without covariance)
  };

  std::size_t size() const { return t.size(); }
  bool empty() const { return t.empty(); }
  bool has_uncertainty() const { return !covariance.empty(); }
  bool contains(double time) const { return !t.empty() && time >= t.front() && time <= t.back(); }
  /// Orientation at `time`: slerp between the neighbouring samples (an exact sample time returns
  /// that sample); covariance interpolated linearly. MeasurementError outside [t.front, t.back].
  Sample at(double time) const;
  /// Appends a sample, flipping q's sign to stay continuous with the previous one.
  void push_back(double time, const Quat& q, const std::optional<Mat3>& cov = std::nullopt);
};

/// R_true_magnetic = Rz(−declination) (declination rad, east positive).
Quat magnetic_to_true(double declination);
/// The track rotated from enu-magnetic to enu-true (covariances rotated too). std::invalid_argument
/// when the track is not enu-magnetic.
OrientationTrack apply_declination(const OrientationTrack& track, double declination);

/// An orientation estimator (causal filter or smoother) over a whole log.
class OrientationEstimator {
 public:
  virtual ~OrientationEstimator() = default;
  virtual std::string name() const = 0;
  /// True when the estimate at t uses only samples up to t.
  virtual bool causal() const = 0;
  /// Runs over the whole log; the track is enu-magnetic. MeasurementError when the data cannot
  /// support an estimate (e.g. a magnetometer-based method without magnetometer).
  virtual OrientationTrack estimate(const ImuData& data, Diagnostics& diagnostics) const = 0;
};

/// A filter advanced once per gyroscope sample (see file comment).
class GyroDrivenFilter {
 public:
  virtual ~GyroDrivenFilter() = default;
  virtual void reset(const Quat& q_world_device) = 0;
  /// Predict over dt (s) with the gyroscope rate (rad/s, device frame), then correct with the
  /// specific force (m/s²) and field (µT) when not null.
  virtual void update(double dt, const Vec3& gyro, const Vec3* acc, const Vec3* mag) = 0;
  /// The same, told how old (s) the held accelerometer and magnetometer samples are. Filters
  /// that use the age (e.g. to rotate a stale sample forward) override this; others ignore it.
  virtual void update_with_ages(double dt, const Vec3& gyro, const Vec3* acc, double acc_age, const Vec3* mag,
                                double mag_age) {
    (void)acc_age, (void)mag_age;
    update(dt, gyro, acc, mag);
  }
  virtual Quat q_world_device() const = 0;  // enu-magnetic
  /// Optional covariance of the current estimate (see file comment).
  virtual std::optional<Mat3> covariance() const { return std::nullopt; }
};

struct GyroDrivenOptions {
  double max_hold_s = 0.0;    // 0: 5 × the stream's median interval (at least 20 ms)
  double gap_factor = 10.0;   // gyroscope interval > gap_factor × median: not integrated
  bool gyro_trapezoid = false;  // samples are instantaneous rates: integrate the mean of two
                                // consecutive samples (false: each sample is the interval's mean rate)
};

/// Runs `filter` over `data` as the file comment says, starting from q0_world_device (applied with
/// reset before the first gyroscope sample).
OrientationTrack run_gyro_driven(GyroDrivenFilter& filter, const ImuData& data, const Quat& q0_world_device,
                                 const GyroDrivenOptions& options = {});

/// Initial attitude from the first accelerometer and magnetometer samples (TRIAD,
/// orientation::triad_world_device), or tilt only (heading 0) without magnetometer.
/// `average_s` > 0 averages each stream over its first average_s seconds.
Quat initial_attitude(const ImuData& data, double average_s = 0.0);

// ---- registry ----------------------------------------------------------------------------

/// Parameters by name (numbers only), e.g. from "--param beta=0.1".
using EstimatorParams = std::map<std::string, double>;

/// Parses "name=value" strings. InputError (file "--param") for a missing '=', an empty name,
/// a value that is not a finite number, or a name given twice.
EstimatorParams parse_params(const std::vector<std::string>& name_value);

struct ParamSpec {
  std::string name;
  double default_value = 0.0;
  std::string help;
};

struct EstimatorInfo {
  std::string name;
  std::string description;
  bool causal = true;
  std::vector<ParamSpec> params;
  /// Builds the estimator from a complete parameter set (defaults filled in).
  std::function<std::unique_ptr<OrientationEstimator>(const EstimatorParams&)> create;
};

/// The available estimators, in the order the benchmark lists them. New estimators add an
/// entry in estimator_registry.cpp.
std::vector<EstimatorInfo> estimator_registry();
std::vector<std::string> estimator_names();

/// Builds an estimator by name with `params` over its defaults. InputError (file "--method" /
/// "--param") for an unknown method or parameter, listing the accepted ones, or a parameter
/// outside its range (the estimator's constructor checks it).
std::unique_ptr<OrientationEstimator> make_estimator(std::string_view name, const EstimatorParams& params = {});

/// Writes t,qw,qx,qy,qz (+ tilt_sigma_deg, heading_sigma_deg when the track has covariances).
void write_track_csv(const OrientationTrack& track, const std::filesystem::path& file);

}  // namespace antpose::orientation
