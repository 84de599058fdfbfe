// Static orientation scored against optical truth on the rest phases of benchmark captures
// (BROAD, ../shared/data/orientation/README.md).
//
// Error metric (BROAD, Laidig et al., Data 6(7):72, 2021; broad_utils.py): with the estimate
// q_est and the truth q_ref (both q_world_body), q_e = q_est ⊗ conj(q_ref) = (w, x, y, z):
//   total       = 2 acos(min(1, |w|)),
//   heading     = 2 atan(|z / w|)                      (twist about the world vertical),
//   inclination = 2 acos(min(1, sqrt(w² + z²)))         (the remaining swing).
// RMSE over the scored samples whose truth is valid.
//
// Rest-phase protocol (our reading; BROAD scores the movement phases, its README names no
// "first 20 s of rest"): the rest phases are the runs of truth samples with moving = 0. We
// score the first `rest_s` seconds of rest, starting at the first rest sample with valid
// truth and continuing into later rest phases if the first one is shorter. Every scored
// sample k gets its own static orientation (orientation/static_orientation's TRIAD) from the
// accelerometer and magnetometer averaged over [t_k − w/2, t_k + w/2] clipped to its rest
// phase (w = window_s). The estimate's world is ENU with y along the horizontal measured
// field, the truth's must be `enu-magnetic` (compared directly, no alignment).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "antpose/io/capture.hpp"

namespace antpose::orientation {

struct BroadErrors {
  double total = 0.0;        // rad
  double heading = 0.0;      // rad
  double inclination = 0.0;  // rad
};

/// BROAD's error angles between an estimate and the truth (both q_world_body).
BroadErrors broad_errors(const Quat& q_est, const Quat& q_ref);

struct RestBenchmarkOptions {
  double rest_s = 20.0;   // seconds of rest scored per trial
  double window_s = 1.0;  // averaging window per scored sample
};

struct RestBenchmarkTrial {
  std::string name;
  std::size_t samples = 0;       // scored samples (valid truth)
  double rest_s = 0.0;           // rest time covered
  std::size_t rest_phases = 0;   // rest phases the scored samples came from
  BroadErrors rmse;              // rad
};

/// Scores one capture. InputError (naming the capture folder) when the truth, its
/// `moving`/`valid` columns or the accelerometer/magnetometer streams are missing, or when
/// the truth world is not enu-magnetic; MeasurementError when no rest sample has valid truth.
RestBenchmarkTrial evaluate_rest_orientation(const Capture& capture, const std::string& name,
                                             const RestBenchmarkOptions& options = {});

/// Unweighted mean of the per-trial RMSEs (BROAD's convention for several trials).
BroadErrors mean_rmse(const std::vector<RestBenchmarkTrial>& trials);

}  // namespace antpose::orientation
