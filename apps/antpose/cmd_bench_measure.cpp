// antpose bench measure: the non-contact measurement timed and scored on simulated sites.
//   antpose bench measure DIR... --device ID|FILE [--db DB] [--json OUT]
// Each capture is measured with every antenna of its truth/scene.yaml (rectangle and built-in
// model) at once, as `antpose measure` would; the speed target is per site (docs/benchmarks.md).

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/imu/imu_calibration.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/measure/device_setup.hpp"
#include "antpose/measure/site_benchmark.hpp"
#include "antpose/store/device_ref.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"
#include "progress.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct MeasureBenchArgs {
  std::vector<std::string> dirs;
  std::string device, json;
  std::optional<std::string> db;
};

std::string angle(const std::optional<double>& error, const std::optional<double>& sigma) {
  if (!error) return "undefined";
  return fmt::format("{:+.2f} σ{:.2f}", rad2deg(*error), rad2deg(sigma.value_or(0.0)));
}

void print_site(const measure::SiteBenchmark& s) {
  fmt::print("{}: {} photos of {}×{} px, {:.1f} s, peak RSS {:.0f} MiB\n", s.name, s.photos, s.width_px, s.height_px,
             s.seconds, s.peak_rss_mib);
  for (const auto& [stage, seconds] : s.stage_seconds)
    if (seconds >= 0.05 * s.seconds) fmt::print("    {:<20} {:6.1f} s\n", stage, seconds);
  for (std::size_t k = 0; k < s.antennas.size(); ++k) {
    const auto& a = s.antennas[k];
    if (a.refused) {
      fmt::print("  antenna {}: refused: {}\n", k + 1, *a.refused);
      continue;
    }
    fmt::print("  antenna {}: azimuth {}  downtilt {}  roll {}  {} ({} warnings)\n", k + 1,
               angle(a.azimuth_error, a.azimuth_sigma), angle(a.downtilt_error, a.downtilt_sigma),
               angle(a.roll_error, a.roll_sigma), a.verdict, a.warnings);
  }
}

void run_measure_bench(const MeasureBenchArgs& args, const CLI::App& verb) {
  const auto ref = store::resolve_device_ref(args.device, args.db ? std::optional<fs::path>(*args.db) : std::nullopt);
  const fs::path where = ref.file ? *ref.file : fs::path("--device " + ref.profile.id);
  const auto setup = measure::device_setup(ref.profile, where);
  const auto folders = capture_folders(args.dirs);
  nlohmann::json sites = nlohmann::json::array();
  std::vector<double> seconds;
  for (const auto& folder : folders) {
    // The truth before the photos: a capture without it fails at once.
    const auto truth = measure::read_truth_antennas(folder);
    Diagnostics diagnostics;
    Capture capture = read_capture(folder, diagnostics);
    if (ref.profile.has_imu) imu::apply(ref.profile.imu, capture);
    measure::NonContactOptions options;
    ProgressLine progress(folder.filename().string());
    options.progress = progress.callback();
    const auto site = measure::benchmark_site(folder, capture, truth, setup, options, diagnostics);
    print_site(site);
    seconds.push_back(site.seconds);
    sites.push_back(measure::to_json(site));
  }
  std::sort(seconds.begin(), seconds.end());
  if (!seconds.empty())
    fmt::print("{} sites: median {:.1f} s, slowest {:.1f} s per site\n", seconds.size(), seconds[seconds.size() / 2],
               seconds.back());
  if (!args.json.empty()) {
    store::Provenance provenance = provenance_of(verb);
    add_device(provenance, ref);
    for (const auto& folder : folders) provenance.input("capture", folder);
    write_json(args.json, nlohmann::json{{"sites", sites}}, provenance);
  }
}

}  // namespace

void add_bench_measure_command(CLI::App& bench) {
  auto args = std::make_shared<MeasureBenchArgs>();
  auto* cmd = bench.add_subcommand(
      "measure", "the non-contact measurement on simulated sites (truth/scene.yaml): time per stage, memory, errors");
  cmd->add_option("dirs", args->dirs, "capture folders with truth, or folders of them")->required();
  cmd->add_option("--device", args->device, "the phone: a device id in the database or a profile YAML file")
      ->required();
  cmd->add_option("--db", args->db, "device database (default as 'antpose device')");
  add_json_option(cmd, args->json, "write the per-site results");
  cmd->callback([args, cmd] { run_measure_bench(*args, *cmd); });
}

}  // namespace antpose::cli
