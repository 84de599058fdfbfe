// antpose bench: benchmarks against captures with truth.
//   antpose bench static-orientation DIR...   static eCompass on the rest phases (BROAD metric)
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "antpose/orientation/rest_benchmark.hpp"
#include "commands.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct StaticBenchArgs {
  std::vector<std::string> dirs;
  double rest_s = 20.0;
  double window_s = 1.0;
};

// A capture folder, or a folder of capture folders (sorted by name).
std::vector<fs::path> capture_folders(const std::vector<std::string>& dirs) {
  std::vector<fs::path> out;
  for (const auto& d : dirs) {
    const fs::path dir(d);
    if (!fs::is_directory(dir)) throw InputError(dir, "no such folder (expected a capture or a folder of captures)");
    if (fs::exists(dir / "capture.yaml")) {
      out.push_back(dir);
      continue;
    }
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_directory() && fs::exists(entry.path() / "capture.yaml")) found.push_back(entry.path());
    if (found.empty()) throw InputError(dir, "holds no capture.yaml and no capture folders");
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

void run_static_bench(const StaticBenchArgs& args) {
  orientation::RestBenchmarkOptions options;
  options.rest_s = args.rest_s;
  options.window_s = args.window_s;
  std::vector<orientation::RestBenchmarkTrial> trials;
  Diagnostics diagnostics;
  fmt::print("static orientation (TRIAD eCompass, {:.1f} s windows) on the first {:.0f} s of rest; BROAD error "
             "metric, RMSE in degrees\n",
             options.window_s, options.rest_s);
  fmt::print("{:<45} {:>8} {:>7} {:>9} {:>9} {:>12}\n", "trial", "samples", "rest_s", "total", "heading",
             "inclination");
  for (const auto& folder : capture_folders(args.dirs)) {
    const Capture capture = read_capture(folder, diagnostics);
    const auto t = orientation::evaluate_rest_orientation(capture, folder.filename().string(), options);
    fmt::print("{:<45} {:>8} {:>7.1f} {:>9.3f} {:>9.3f} {:>12.3f}\n", t.name, t.samples, t.rest_s,
               rad2deg(t.rmse.total), rad2deg(t.rmse.heading), rad2deg(t.rmse.inclination));
    trials.push_back(t);
  }
  const auto m = orientation::mean_rmse(trials);
  fmt::print("{:<45} {:>8} {:>7} {:>9.3f} {:>9.3f} {:>12.3f}\n", fmt::format("mean of {} trials", trials.size()), "",
             "", rad2deg(m.total), rad2deg(m.heading), rad2deg(m.inclination));
  print_warnings(diagnostics);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "benchmarks against captures with truth");
  bench->require_subcommand(1);
  auto args = std::make_shared<StaticBenchArgs>();
  auto* st = bench->add_subcommand("static-orientation",
                                   "score the static eCompass on the rest phases of captures with enu-magnetic truth");
  st->add_option("dirs", args->dirs, "capture folders, or folders of capture folders")->required();
  st->add_option("--rest-s", args->rest_s, "seconds of rest scored per trial")->capture_default_str();
  st->add_option("--window-s", args->window_s, "averaging window per scored sample, s")->capture_default_str();
  st->callback([args] { run_static_bench(*args); });
}

}  // namespace antpose::cli
