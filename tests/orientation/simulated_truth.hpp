// Shared by the orientation tests: a simulated capture with its truth, and the angle between
// an estimated track and that truth.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "antpose/orientation/estimator.hpp"
#include "antpose/sim/imu_simulator.hpp"

namespace antpose::test {

struct Sim {
  sim::ImuSimulation sim;
  Capture capture;
};

inline Sim simulate(sim::Trajectory trajectory, sim::PhoneModel phone = sim::PhoneModel::ideal(),
                    std::vector<sim::MagneticDisturbance> disturbances = {}, std::uint64_t seed = 11) {
  Sim s;
  s.sim.trajectory = std::move(trajectory);
  s.sim.phone = std::move(phone);
  s.sim.disturbances = std::move(disturbances);
  s.sim.seed = seed;
  s.capture = sim::simulate_imu(s.sim);
  return s;
}

struct ErrorStats {
  double rms_deg = 0.0, max_deg = 0.0;
  bool finite = true;  // every quaternion (and tilt variance, when present) is finite
};

/// Angle between track and simulated truth over the track samples in [t0, t1].
inline ErrorStats errors(const orientation::OrientationTrack& track, const sim::Trajectory& truth, double t0,
                         double t1) {
  ErrorStats e;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < track.size(); ++i) {
    if (!track.q_world_device[i].coeffs().allFinite()) e.finite = false;
    if (track.has_uncertainty() && !track.covariance[i].diagonal().head<2>().allFinite()) e.finite = false;
    if (track.t[i] < t0 || track.t[i] > t1) continue;
    const double a =
        rad2deg(rotation_distance(track.q_world_device[i].toRotationMatrix(), truth.R_world_device(track.t[i])));
    sum += a * a, e.max_deg = std::max(e.max_deg, a), ++n;
  }
  e.rms_deg = n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  return e;
}

/// Removes the samples with t in [t0, t1) from a stream (a gap).
inline void cut_stream(Capture& capture, const std::string& name, double t0, double t1) {
  Stream& stream = capture.streams.at(name);
  std::vector<double> t;
  std::vector<Eigen::Index> keep;
  for (std::size_t i = 0; i < stream.size(); ++i)
    if (stream.t[i] < t0 || stream.t[i] >= t1) keep.push_back(static_cast<Eigen::Index>(i)), t.push_back(stream.t[i]);
  stream.values = Stream::Values(stream.values(keep, Eigen::all));
  stream.t = std::move(t);
}

}  // namespace antpose::test
