#include "antpose/measure/site_benchmark.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <regex>

#include "antpose/camera/board.hpp"
#include "antpose/io/text_file.hpp"
#include "antpose/io/yaml_util.hpp"
#include "antpose/model/antenna_model.hpp"

namespace antpose::measure {
namespace {

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// "antenna 2 (images/img_0004.jpg): dense stereo" → "dense stereo"; "antenna 2: with its
// neighbours known" → "with its neighbours known".
std::string stage_name(const std::string& stage) {
  static const std::regex antenna(R"(^antenna \d+( \([^)]*\))?: )");
  std::smatch m;
  return std::regex_search(stage, m, antenna) ? m.suffix().str() : stage;
}

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: KiB
}

AntennaScore score(const AntennaMeasurement& m, const TruthAntenna& truth) {
  AntennaScore s;
  s.warnings = m.warnings.size() + m.attitude.warnings.size();
  if (m.error) {
    s.refused = *m.error;
    return s;
  }
  s.verdict = registration::to_string(m.verdict);
  const auto& a = m.attitude;
  if (a.magnetic.azimuth) s.azimuth_error = wrap_pi(*a.magnetic.azimuth - truth.azimuth_magnetic);
  s.azimuth_sigma = a.sigma.azimuth;
  s.downtilt_error = a.magnetic.downtilt - truth.downtilt;
  s.downtilt_sigma = a.sigma.downtilt;
  if (a.magnetic.roll) s.roll_error = wrap_pi(*a.magnetic.roll - truth.roll);
  s.roll_sigma = a.sigma.roll;
  return s;
}

nlohmann::json degrees(const std::optional<double>& rad) {
  return rad ? nlohmann::json(rad2deg(*rad)) : nlohmann::json(nullptr);
}

}  // namespace

std::vector<TruthAntenna> read_truth_antennas(const std::filesystem::path& capture) {
  const auto file = capture / "truth" / "scene.yaml";
  if (!std::filesystem::exists(file))
    throw InputError(file, "not found: a benchmark needs the truth of a simulated capture (antpose simulate capture)");
  const YAML::Node root = io::load_yaml(io::read_text(file), file);
  const YAML::Node antennas = io::yaml_required(root, "antennas", file, "antennas");
  if (!antennas.IsSequence() || antennas.size() == 0)
    throw InputError(file, io::line_of(antennas), "antennas: " + io::show(antennas) + ", expected a list of antennas");
  std::vector<TruthAntenna> out;
  for (std::size_t i = 0; i < antennas.size(); ++i) {
    const YAML::Node a = antennas[i];
    const auto at = "antennas[" + std::to_string(i) + "]";
    const YAML::Node roi = io::yaml_required(a, "roi", file, at + ".roi");
    TruthAntenna t;
    t.roi.image = io::yaml_string(roi["image"], file, at + ".roi.image");
    t.roi.roi = {static_cast<int>(io::yaml_integer(roi["x"], file, at + ".roi.x")),
                 static_cast<int>(io::yaml_integer(roi["y"], file, at + ".roi.y")),
                 static_cast<int>(io::yaml_integer(roi["width"], file, at + ".roi.width")),
                 static_cast<int>(io::yaml_integer(roi["height"], file, at + ".roi.height"))};
    t.roi.drawn = t.roi.roi;  // the truth's rectangle is on the photo as shown
    t.model = io::yaml_string(a["model"], file, at + ".model");
    t.azimuth_magnetic = deg2rad(io::yaml_number(a["azimuth_magnetic_deg"], file, at + ".azimuth_magnetic_deg"));
    t.downtilt = deg2rad(io::yaml_number(a["downtilt_deg"], file, at + ".downtilt_deg"));
    t.roll = deg2rad(io::yaml_number(a["roll_deg"], file, at + ".roll_deg"));
    out.push_back(std::move(t));
  }
  return out;
}

StageClock::StageClock() : last_(now_s()) {}

void StageClock::operator()(const std::string& stage, int, int) {
  const double t = now_s();
  const auto name = stage_name(stage);
  auto it = std::find_if(seconds_.begin(), seconds_.end(), [&](const auto& s) { return s.first == name; });
  if (it == seconds_.end()) it = seconds_.insert(seconds_.end(), {name, 0.0});
  it->second += t - last_;
  last_ = t;
}

SiteBenchmark benchmark_site(const std::filesystem::path& folder, const Capture& capture,
                             const std::vector<TruthAntenna>& truth, NonContactSetup setup,
                             const NonContactOptions& options, Diagnostics& diagnostics) {
  setup.board = camera::read_board(capture_file(folder, "board.yaml"));
  setup.models.clear();
  setup.rois.clear();
  for (const auto& t : truth) {
    if (!model::is_builtin_panel(t.model))
      throw InputError(folder / "truth" / "scene.yaml", "model '" + t.model + "' is not a built-in panel");
    setup.models.push_back(model::builtin_panel(t.model));
    setup.rois.push_back(t.roi);
  }
  SiteBenchmark out;
  out.name = folder.filename().string();
  auto clock = std::make_shared<StageClock>();
  NonContactOptions timed = options;
  timed.progress = [clock, user = options.progress](const std::string& stage, int done, int total) {
    (*clock)(stage, done, total);
    if (user) user(stage, done, total);
  };
  const double start = now_s();
  const auto result = measure_non_contact(capture, setup, timed, diagnostics);
  out.seconds = now_s() - start;
  out.stage_seconds = clock->seconds();
  out.peak_rss_mib = peak_rss_mib();
  out.photos = result.photos.size();
  out.width_px = result.intrinsics.width;
  out.height_px = result.intrinsics.height;
  for (std::size_t k = 0; k < truth.size() && k < result.antennas.size(); ++k)
    out.antennas.push_back(score(result.antennas[k], truth[k]));
  return out;
}

nlohmann::json to_json(const SiteBenchmark& site) {
  nlohmann::json j;
  j["site"] = site.name;
  j["photos"] = site.photos;
  j["width_px"] = site.width_px;
  j["height_px"] = site.height_px;
  j["seconds"] = site.seconds;
  j["peak_rss_mib"] = site.peak_rss_mib;
  j["stage_seconds"] = nlohmann::json::object();
  for (const auto& [stage, s] : site.stage_seconds) j["stage_seconds"][stage] = s;
  j["antennas"] = nlohmann::json::array();
  for (const auto& a : site.antennas) {
    nlohmann::json r;
    r["refused"] = a.refused ? nlohmann::json(*a.refused) : nlohmann::json(nullptr);
    r["verdict"] = a.verdict;
    r["warnings"] = a.warnings;
    r["azimuth_error_deg"] = degrees(a.azimuth_error);
    r["azimuth_sigma_deg"] = degrees(a.azimuth_sigma);
    r["downtilt_error_deg"] = rad2deg(a.downtilt_error);
    r["downtilt_sigma_deg"] = rad2deg(a.downtilt_sigma);
    r["roll_error_deg"] = degrees(a.roll_error);
    r["roll_sigma_deg"] = degrees(a.roll_sigma);
    j["antennas"].push_back(std::move(r));
  }
  return j;
}

}  // namespace antpose::measure
