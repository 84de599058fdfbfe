// antpose bench: benchmarks against captures with truth.
//   antpose bench static-orientation DIR...   static eCompass on the rest phases (BROAD metric)
//   antpose bench orientation DIR...          every orientation estimator, BROAD metric, throughput
//   antpose bench orientation-grid DIR...     Madgwick beta × zeta sweep (thesis §4.6), SVG heat maps
//   antpose bench registration [SHARED]      antpose's ICP against PCL's and Open3D's (docs/benchmarks.md)
//   antpose bench measure DIR... --device D   the non-contact measurement on simulated sites (cmd_bench_measure.cpp)
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/io/text_file.hpp"
#include "antpose/orientation/orientation_benchmark.hpp"
#include "antpose/orientation/rest_benchmark.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "option_checks.hpp"
#include "json_output.hpp"

namespace antpose::cli {

namespace fs = std::filesystem;

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

namespace {

struct StaticBenchArgs {
  std::vector<std::string> dirs;
  double rest_s = 20.0;
  double window_s = 1.0;
};

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

struct OrientationBenchArgs {
  std::vector<std::string> dirs;
  std::string methods;
  std::string json;
  std::vector<std::string> wmm;
  double skip_s = 5.0;
  std::string output = "orientation-grid";
  unsigned threads = 0;
};

std::vector<geomag::MagneticModel> load_models(const std::vector<std::string>& files) {
  std::vector<geomag::MagneticModel> models;
  for (const auto& f : files) models.push_back(geomag::MagneticModel::from_file(f));
  models.push_back(geomag::MagneticModel::wmm2025());
  return models;
}

std::vector<orientation::BenchmarkTrial> load_trials(const OrientationBenchArgs& args, Diagnostics& diagnostics) {
  const auto models = load_models(args.wmm);
  orientation::ScoringOptions scoring;
  scoring.skip_s = args.skip_s;
  std::vector<orientation::BenchmarkTrial> trials;
  for (const auto& folder : capture_folders(args.dirs))
    trials.push_back(orientation::load_benchmark_trial(folder, models, diagnostics, scoring));
  return trials;
}

nlohmann::json score_json(const orientation::TrackScore& s) {
  return {{"samples", s.samples},
          {"outside_track", s.outside},
          {"total_rmse_deg", rad2deg(s.rmse.total)},
          {"heading_rmse_deg", rad2deg(s.rmse.heading)},
          {"inclination_rmse_deg", rad2deg(s.rmse.inclination)},
          {"mean_total_deg", rad2deg(s.mean_total)},
          {"yaw_mae_deg", rad2deg(s.yaw_mae)},
          {"pitch_mae_deg", rad2deg(s.pitch_mae)},
          {"roll_mae_deg", rad2deg(s.roll_mae)}};
}

void run_orientation_bench(const OrientationBenchArgs& args, const CLI::App& verb) {
  Diagnostics diagnostics;
  const std::vector<std::string> methods =
      args.methods.empty() ? orientation::estimator_names() : split_list(args.methods);
  std::vector<std::unique_ptr<orientation::OrientationEstimator>> estimators;
  for (const auto& m : methods) estimators.push_back(orientation::make_estimator(m));
  const auto trials = load_trials(args, diagnostics);

  // results[method][dataset] = per-trial scores, in trial order
  std::map<std::string, std::map<std::string, std::vector<orientation::MethodScore>>> results;
  nlohmann::json jt = nlohmann::json::array();
  for (const auto& e : estimators) {
    fmt::print("\n{} (default parameters for all trials); RMSE over the scored samples, degrees\n", e->name());
    fmt::print("{:<45} {:>7} {:>8} {:>8} {:>8} {:>8} {:>10}\n", "trial", "samples", "total", "heading", "incl",
               "mean_tot", "ns/sample");
    std::string last_dataset;
    for (const auto& trial : trials) {
      Diagnostics run_diag;  // per-run warnings would repeat the data checks; keep the first method's
      auto m = orientation::run_method(trial, *e, e == estimators.front() ? diagnostics : run_diag);
      const auto& s = m.score;
      fmt::print("{:<45} {:>7} {:>8.4f} {:>8.4f} {:>8.4f} {:>8.3f} {:>10.1f}\n", trial.dataset + "/" + trial.name,
                 s.samples, rad2deg(s.rmse.total), rad2deg(s.rmse.heading), rad2deg(s.rmse.inclination),
                 rad2deg(s.mean_total), m.ns_per_sample);
      nlohmann::json j = score_json(s);
      j["trial"] = m.trial;
      j["dataset"] = m.dataset;
      j["method"] = m.method;
      j["protocol"] = trial.truth.protocol;
      j["declination_deg"] = rad2deg(trial.truth.declination);
      j["declination_model"] = trial.truth.declination_model;
      j["track_samples"] = m.track_samples;
      j["ns_per_sample"] = m.ns_per_sample;
      jt.push_back(j);
      results[e->name()][trial.dataset].push_back(std::move(m));
    }
    for (const auto& [dataset, scores] : results[e->name()]) {
      const auto mean = orientation::mean_score(scores);
      double ns = 0.0;
      for (const auto& s : scores) ns += s.ns_per_sample;
      fmt::print("{:<45} {:>7} {:>8.4f} {:>8.4f} {:>8.4f} {:>8.3f} {:>10.1f}\n",
                 fmt::format("mean of {} {} trials", scores.size(), dataset), "", rad2deg(mean.rmse.total),
                 rad2deg(mean.rmse.heading), rad2deg(mean.rmse.inclination), rad2deg(mean.mean_total),
                 ns / static_cast<double>(scores.size()));
    }
  }
  if (!args.json.empty()) {
    nlohmann::json means = nlohmann::json::object();
    for (const auto& [method, by_dataset] : results)
      for (const auto& [dataset, scores] : by_dataset) {
        nlohmann::json j = score_json(orientation::mean_score(scores));
        double ns = 0.0;
        for (const auto& s : scores) ns += s.ns_per_sample;
        j["trials"] = scores.size();
        j["ns_per_sample"] = ns / static_cast<double>(scores.size());
        means[dataset][method] = j;
      }
    const nlohmann::json out = {{"metric", "BROAD (total/heading/inclination RMSE); Tyrex-style mean total"},
                                {"methods", methods},
                                {"trials", jt},
                                {"means", means}};
    store::Provenance provenance = provenance_of(verb);
    for (const auto& folder : capture_folders(args.dirs)) provenance.input("capture", folder);
    write_json(args.json, out, provenance);
    if (args.json != "-") fmt::print("\nJSON written to {}\n", args.json);
  }
  print_warnings(diagnostics);
}

void run_orientation_grid(const OrientationBenchArgs& args) {
  Diagnostics diagnostics;
  const auto trials = load_trials(args, diagnostics);
  std::vector<double> beta, zeta;
  for (int i = 0; i <= 10; ++i) beta.push_back(0.1 * i), zeta.push_back(0.01 * i);
  const unsigned threads = args.threads > 0 ? args.threads : std::max(1u, std::thread::hardware_concurrency());
  fmt::print("Madgwick MARG over beta 0..1 (step 0.1) × zeta 0..0.1 (step 0.01) on {} trials, {} threads\n",
             trials.size(), threads);
  const auto g = orientation::madgwick_grid(trials, beta, zeta, threads);
  const std::filesystem::path out(args.output);
  std::filesystem::create_directories(out);
  struct Item {
    const char* file;
    const char* title;
    const Eigen::MatrixXd* values;
  };
  const Item items[] = {{"yaw_mae.svg", "yaw (azimuth) mean absolute error", &g.yaw_mae},
                        {"pitch_mae.svg", "pitch mean absolute error", &g.pitch_mae},
                        {"roll_mae.svg", "roll mean absolute error", &g.roll_mae},
                        {"pitch_roll_mae.svg", "pitch + roll mean absolute error", &g.pitch_roll_mae}};
  nlohmann::json j = {{"beta", beta}, {"zeta", zeta}, {"trials", g.trials}};
  for (const auto& it : items) {
    orientation::Heatmap map;
    map.title = fmt::format("Madgwick MARG: {} (mean of {} trials)", it.title, g.trials);
    map.x_label = "zeta (rad/s²)";
    map.y_label = "beta (rad/s)";
    map.unit = "°";
    map.x_values = zeta;
    map.y_values = beta;
    map.values = it.values->unaryExpr([](double v) { return rad2deg(v); });
    io::write_text_atomic(out / it.file, orientation::heatmap_svg(map));
    Eigen::Index r = 0, c = 0;
    const double best = map.values.minCoeff(&r, &c);
    fmt::print("{:<36} best {:.3f}° at beta {:.1f}, zeta {:.2f}  -> {}\n", it.title, best, beta[r], zeta[c],
               (out / it.file).string());
    std::vector<std::vector<double>> rows;
    for (Eigen::Index i = 0; i < map.values.rows(); ++i) {
      std::vector<double> row;
      for (Eigen::Index k = 0; k < map.values.cols(); ++k) row.push_back(map.values(i, k));
      rows.push_back(row);
    }
    j[std::string(it.file).substr(0, std::string(it.file).size() - 4) + "_deg"] = rows;
  }
  io::write_text_atomic(out / "grid.json", j.dump(2) + "\n");
  print_warnings(diagnostics);
}

struct RegistrationBenchArgs {
  std::string shared;  // empty: the build's ANTPOSE_SHARED_DIR
  int repeats = 9;
  std::string json;
};

// The comparison links PCL and Open3D, which antpose itself never does (benchmark-only
// dependencies, not in CI), so it is a program of its own, built into the folder of the antpose
// executable where scripts/install-bench-deps.sh installed them; this verb runs it in this
// process' place. Found beside the running executable, never at a path fixed when building.
[[noreturn]] void run_registration_bench(const RegistrationBenchArgs& args) {
  if (!args.shared.empty() && !fs::exists(fs::path(args.shared) / "data/pointclouds/pcl/bun0.ply"))
    throw InputError(args.shared, "no data/pointclouds/pcl/bun0.ply (expected the shared data folder)");
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const std::string program = (self.parent_path() / "antpose_bench_registration").string();
  if (ec || !fs::is_regular_file(program))
    throw InputError(
        {}, fmt::format("no registration comparison beside this antpose ({}): it needs PCL and Open3D (benchmark-only "
                        "dependencies: scripts/install-bench-deps.sh), then cmake --build build --target "
                        "antpose_bench_registration",
                        program));
  std::vector<std::string> words{program, "--repeats", std::to_string(args.repeats)};
  if (!args.json.empty()) words.insert(words.end(), {"--json", args.json});
  if (!args.shared.empty()) words.push_back(args.shared);
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  execv(program.c_str(), argv.data());
  throw Error(fmt::format("{}: cannot run it: {}", program, std::strerror(errno)));
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

  auto oargs = std::make_shared<OrientationBenchArgs>();
  auto* ob = bench->add_subcommand("orientation", "score every orientation estimator against captures with truth");
  ob->add_option("dirs", oargs->dirs, "capture folders, or folders of capture folders")->required();
  add_orientation_method_option(*ob, oargs->methods, "estimators to score (default: all)",
                                {.several = true, .other_names = {}, .other_hint = {}});
  add_renamed_option(*ob, "--methods", "--method");
  add_json_option(ob, oargs->json, "write the per-trial and mean results");
  ob->add_option("--wmm", oargs->wmm, "extra WMM coefficient files for the declination (repeatable; with the built-in "
                                      "WMM2025, the model valid for the capture date is used, else the nearest epoch)");
  ob->add_option("--skip-s", oargs->skip_s, "truth without a moving column: seconds left out at its start")
      ->capture_default_str();
  ob->callback([oargs, ob] { run_orientation_bench(*oargs, *ob); });

  auto gargs = std::make_shared<OrientationBenchArgs>();
  auto* og = bench->add_subcommand("orientation-grid",
                                   "Madgwick beta × zeta sweep (thesis §4.6): yaw/pitch/roll MAE heat maps as SVG");
  og->add_option("dirs", gargs->dirs, "capture folders, or folders of capture folders")->required();
  og->add_option("-o,--output", gargs->output, "output folder for the SVG files and grid.json")->capture_default_str();
  og->add_option("--wmm", gargs->wmm, "extra WMM coefficient files for the declination (repeatable)");
  og->add_option("--skip-s", gargs->skip_s, "truth without a moving column: seconds left out at its start")
      ->capture_default_str();
  og->add_option("--threads", gargs->threads, "worker threads (0: all cores)")->capture_default_str();
  og->callback([gargs] { run_orientation_grid(*gargs); });

  auto rargs = std::make_shared<RegistrationBenchArgs>();
  auto* rb = bench->add_subcommand(
      "registration",
      "antpose's point-to-point, point-to-plane and generalized ICP against PCL's and Open3D's on the "
      "same clouds: time, error and time ratios (needs scripts/install-bench-deps.sh)");
  rb->add_option("shared", rargs->shared, "the shared data folder (default: the build's ANTPOSE_SHARED_DIR)");
  rb->add_option("--repeats", rargs->repeats, "runs per method; the median time is reported")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  rb->add_option("--json", rargs->json, "write the results as JSON");
  rb->callback([rargs] { run_registration_bench(*rargs); });

  add_bench_measure_command(*bench);
}

}  // namespace antpose::cli
