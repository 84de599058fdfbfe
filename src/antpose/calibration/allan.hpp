// Overlapping Allan deviation and the IMU noise model read from it.
//
// OADEV (W. J. Riley, Handbook of Frequency Stability Analysis, NIST SP 1065, 2008, eq. 14
// for phase data x_i, spaced tau0):
//   σ²(τ) = Σ_{i=1}^{N−2m} (x_{i+2m} − 2x_{i+m} + x_i)² / (2 m² τ0² (N − 2m)),  τ = m τ0.
// A rate sensor's output (gyroscope rad/s, accelerometer m/s²) is frequency-type data y_i; its
// phase is the integral x_1 = 0, x_{k+1} = x_k + τ0 y_k (N = M + 1), and σ has the unit of
// the rate. The non-overlapping ADEV (SP 1065 eq. 10) uses every m-th phase point.
//
// Noise fit (IEEE Std 952-1997 Annex C; El-Sheimy, Hou, Niu, "Analysis and Modeling of
// Inertial Sensors Using Allan Variance", IEEE TIM 2008):
//   white noise (angle / velocity random walk) N: slope −1/2, N = σ(τ=1 s) on that line;
//   bias instability B: the flat minimum, B = σ_min / 0.664 (= σ_min / sqrt(2 ln 2 / π));
//   rate random walk K: slope +1/2, K = σ(τ=3 s) on that line.
// Each line is fitted (in log-log, with its slope fixed) to the points whose local slope is
// closest to the line's slope.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::calibration {

struct AllanPoint {
  std::size_t m = 0;  // averaging factor
  double tau = 0.0;   // m · tau0, s
  std::size_t n = 0;  // number of terms in the sum (Stable32's "#")
  double deviation = 0.0;
};

/// Averaging factors 1, 2, 4, ... up to the largest with at least one term.
std::vector<std::size_t> octave_factors(std::size_t phase_points);
/// Every averaging factor 1 … (N−1)/2.
std::vector<std::size_t> all_factors(std::size_t phase_points);
/// About `per_decade` log-spaced averaging factors per decade (distinct integers), for plots
/// and fits on long logs.
std::vector<std::size_t> log_factors(std::size_t phase_points, int per_decade = 10);

/// OADEV of phase data x (time units; tau0 s) at the averaging factors `m` (factors without a
/// term are skipped). Throws std::invalid_argument for fewer than 3 points or tau0 ≤ 0.
std::vector<AllanPoint> oadev_phase(const std::vector<double>& x, double tau0, const std::vector<std::size_t>& m);
/// OADEV of frequency (rate) data y, via its phase (see the file comment).
std::vector<AllanPoint> oadev_frequency(const std::vector<double>& y, double tau0, const std::vector<std::size_t>& m);
/// Non-overlapping ADEV of frequency data (SP 1065 eq. 10), for reference checks.
std::vector<AllanPoint> adev_frequency(const std::vector<double>& y, double tau0, const std::vector<std::size_t>& m);

struct NoiseFit {
  std::optional<double> white;               // N, unit/√Hz (= unit·s^½)
  std::optional<double> bias_instability;    // B, unit
  std::optional<double> bias_instability_tau;  // s, where σ is minimal
  std::optional<double> random_walk;         // K, unit·s^−½ (unit/s/√Hz)
};

/// Fits the three noise terms to a deviation curve (see the file comment). A term is empty when
/// the curve has no point with a local slope within 0.25 of that term's slope (e.g. no
/// +1/2 region in a short log); B is empty when the minimum is at the last tau.
NoiseFit fit_noise(const std::vector<AllanPoint>& curve);

/// Per-axis OADEV and noise fit of a rate stream (frequency-type data, tau0 = median sample
/// interval), at log_factors(…, per_decade). Warns in `diagnostics` when the sampling is
/// irregular (gaps), since OADEV assumes equal spacing. Throws MeasurementError naming
/// `source` for fewer than 100 samples.
struct StreamAllan {
  std::string stream;
  double tau0 = 0.0;
  std::vector<std::string> axes;
  std::vector<std::vector<AllanPoint>> curves;  // per axis
  std::vector<NoiseFit> fits;                   // per axis
};
StreamAllan allan_of_stream(const Stream& stream, Diagnostics& diagnostics, const std::filesystem::path& source = {},
                            int per_decade = 10);

/// A log-log SVG plot of one or more deviation curves with their fitted noise lines.
struct AllanSeries {
  std::string label;
  std::vector<AllanPoint> curve;
  NoiseFit fit;
};
std::string allan_svg(const std::vector<AllanSeries>& series, const std::string& title, const std::string& unit);

}  // namespace antpose::calibration
