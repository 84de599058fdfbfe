// The non-contact measurement timed and scored on captures with truth (a simulated site's
// truth/scene.yaml): the wall time of each stage, the process's peak memory, and each antenna's
// errors against the truth beside its σ and verdict. What `antpose bench measure` prints
// (docs/benchmarks.md); speed targets are measured here and never asserted by tests.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/core/error.hpp"
#include "antpose/io/capture.hpp"
#include "antpose/measure/non_contact.hpp"

namespace antpose::measure {

/// One antenna of a site's truth: the rectangle the simulator drew around it, its model's name
/// and its attitude (rad, azimuth from magnetic north).
struct TruthAntenna {
  AntennaRoi roi;
  std::string model;
  double azimuth_magnetic = 0.0, downtilt = 0.0, roll = 0.0;
};

/// The antennas of CAPTURE/truth/scene.yaml, in order. InputError naming the file, the line and
/// the key of a missing or bad value.
std::vector<TruthAntenna> read_truth_antennas(const std::filesystem::path& capture);

/// Wall time per stage from the measurement's progress reports (NonContactOptions::progress): the
/// time since the previous report goes to the stage now reported. An antenna's prefix
/// ("antenna N (photo): ", "antenna N: ") is dropped, so a stage sums over the antennas.
class StageClock {
 public:
  StageClock();
  void operator()(const std::string& stage, int done, int total);
  /// (stage, seconds) in the order first reported.
  const std::vector<std::pair<std::string, double>>& seconds() const { return seconds_; }

 private:
  double last_ = 0.0;
  std::vector<std::pair<std::string, double>> seconds_;
};

/// One antenna's answer against its truth: errors measured − truth (rad; azimuth wrapped to ±π)
/// and σ, or why it was refused.
struct AntennaScore {
  std::optional<std::string> refused;
  std::string verdict;
  std::optional<double> azimuth_error, azimuth_sigma;
  double downtilt_error = 0.0, downtilt_sigma = 0.0;
  std::optional<double> roll_error, roll_sigma;
  std::size_t warnings = 0;
};

struct SiteBenchmark {
  std::string name;  // the capture folder's name
  std::size_t photos = 0;
  int width_px = 0, height_px = 0;
  double seconds = 0.0;  // the whole measurement (reading the capture excluded)
  std::vector<std::pair<std::string, double>> stage_seconds;
  double peak_rss_mib = 0.0;  // the process's peak so far (getrusage), not this site's alone
  std::vector<AntennaScore> antennas;
};

/// Measures `capture` (read from `folder`, with the device's IMU calibration applied) with
/// `setup`'s phone and the board of folder/board.yaml, every antenna of its `truth`
/// (read_truth_antennas) at once with its rectangle and model, and scores the answers.
/// InputError for a model that is not a built-in panel; MeasurementError as measure_non_contact.
SiteBenchmark benchmark_site(const std::filesystem::path& folder, const Capture& capture,
                             const std::vector<TruthAntenna>& truth, NonContactSetup setup,
                             const NonContactOptions& options, Diagnostics& diagnostics);

nlohmann::json to_json(const SiteBenchmark& site);

}  // namespace antpose::measure
