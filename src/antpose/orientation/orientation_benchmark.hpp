// Orientation estimators scored against optical truth (`antpose bench orientation` and
// `orientation-grid`; data and protocols in ../shared/data/orientation/README.md).
//
// Which truth samples are scored:
//  - truth with a `moving` column (BROAD): the samples with moving = 1 and valid truth; the
//    estimate must be enu-magnetic like the truth, no alignment (BROAD's protocol);
//  - truth without `moving` (Tyrex): every valid truth sample from `skip_s` (5 s) after the first
//    truth sample on (the Tyrex benchmark scores optical time [5, 120] s, its whole truth);
//    enu-true truth needs the capture's site: the estimate is turned to true north with the WMM
//    declination, q_true = Rz(−D) ⊗ q_magnetic (estimator.hpp), no other alignment.
// The estimate is sampled at the truth instants with OrientationTrack::at (slerp; at BROAD's
// common sample instants it is the filter output itself); truth instants outside the track are
// left out and counted.
//
// Errors per sample: broad_errors (rest_benchmark.hpp): total, heading, inclination; the trial
// score is their RMSE over the scored samples (BROAD) plus the mean total angle (Tyrex's printed
// score). For the thesis's protocol (§4.6) also the mean absolute differences of Android's
// azimuth, pitch and roll (android_orientation of estimate and truth; azimuth and roll
// differences wrapped to (−π, π]).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "antpose/geomag/wmm.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/orientation/estimator.hpp"
#include "antpose/orientation/rest_benchmark.hpp"

namespace antpose::orientation {

struct ScoringOptions {
  double skip_s = 5.0;  // truth without `moving`: seconds left out after its first sample
};

/// The truth samples to score, already in the frame the estimate is compared in.
struct ScoredTruth {
  std::string protocol;            // "moving" (BROAD) or "after-skip" (Tyrex)
  std::string world;               // enu-magnetic | enu-true
  double declination = 0.0;        // rad, applied to estimates (enu-true truth)
  std::string declination_model;   // e.g. "WMM-2020"
  std::vector<double> t;
  std::vector<Quat> q_world_device;
};

/// Selects and reads the scored truth samples of a capture. `models`: magnetic models to choose
/// from for enu-true truth (the first one valid for the site's date, else the one with the
/// nearest epoch, with the model's validity warning). InputError naming capture.yaml when there is no truth, a quaternion column is
/// missing, the world is unaligned or unknown, or enu-true truth has no site; MeasurementError
/// when no sample is left to score.
ScoredTruth scored_truth(const Capture& capture, const std::vector<geomag::MagneticModel>& models,
                         Diagnostics& diagnostics, const ScoringOptions& options = {});

struct TrackScore {
  std::size_t samples = 0;       // scored
  std::size_t outside = 0;       // truth instants outside the track (left out)
  BroadErrors rmse;              // rad
  double mean_total = 0.0;       // rad
  double yaw_mae = 0.0, pitch_mae = 0.0, roll_mae = 0.0;  // rad, Android angles
};

/// Scores an enu-magnetic track against the truth (applying the truth's declination).
/// MeasurementError when no truth instant lies inside the track.
TrackScore score_track(const OrientationTrack& track, const ScoredTruth& truth);

/// One capture ready for benchmarking.
struct BenchmarkTrial {
  std::string name;     // folder name
  std::string dataset;  // parent folder name (e.g. "broad", "tyrex")
  ImuData data;
  ScoredTruth truth;
};

/// Reads a capture folder into a BenchmarkTrial (read_capture, imu_data_from_capture,
/// scored_truth); warnings go to `diagnostics`.
BenchmarkTrial load_benchmark_trial(const std::filesystem::path& folder,
                                    const std::vector<geomag::MagneticModel>& models, Diagnostics& diagnostics,
                                    const ScoringOptions& options = {});

struct MethodScore {
  std::string trial, dataset, method;
  TrackScore score;
  std::size_t track_samples = 0;
  double seconds = 0.0;        // wall time of estimate()
  double ns_per_sample = 0.0;  // seconds / track_samples
};

/// Runs `estimator` on the trial (timed) and scores it.
MethodScore run_method(const BenchmarkTrial& trial, const OrientationEstimator& estimator, Diagnostics& diagnostics);

/// Unweighted means over trials of the RMSEs (and the other figures), as BROAD averages.
TrackScore mean_score(const std::vector<MethodScore>& scores);

// ---- the thesis's grid (§4.6) ------------------------------------------------------------

struct GridResult {
  std::vector<double> beta, zeta;    // rows, columns
  std::size_t trials = 0;
  // Mean over trials of each trial's mean absolute error (rad); rows = beta, cols = zeta.
  Eigen::MatrixXd yaw_mae, pitch_mae, roll_mae, pitch_roll_mae;  // pitch_roll = pitch + roll
  Eigen::MatrixXd total_rmse;                                    // BROAD total RMSE, for reference
};

/// Madgwick MARG (paper version) for every (beta, zeta) on every trial; `threads` ≥ 1 workers
/// (one grid cell at a time per worker).
GridResult madgwick_grid(const std::vector<BenchmarkTrial>& trials, const std::vector<double>& beta,
                         const std::vector<double>& zeta, unsigned threads = 1);

/// A heat map as SVG: `values` (rows × cols) drawn as cells coloured on a perceptual scale
/// (viridis anchors) between their min and max, each with its value printed; row labels on the
/// y axis (top row first), column labels on the x axis, a colour bar with min/max, a title.
struct Heatmap {
  std::string title, x_label, y_label, unit;
  std::vector<double> x_values, y_values;  // column / row labels
  Eigen::MatrixXd values;                  // rows = y, cols = x
  int value_decimals = 2;
};
std::string heatmap_svg(const Heatmap& map);

}  // namespace antpose::orientation
