// The non-contact measurement end to end through the command line, one test per simulated site,
// as a user runs it: `simulate capture` draws a site, `measure` reads every antenna's attitude
// with the rectangle the simulator suggests and the stored profile of phone 401 (12 MP, calibrated
// through the CLI by scripts/calibrate-simulated-phone.sh), and each antenna is checked against
// truth/scene.yaml.
//
// Every site must hold what a user relies on: no error beyond 4σ unless the answer says the angle
// is in doubt (an ambiguous registration; for the azimuth, a disturbed compass), hence no
// confident wrong answer (azimuth off by more than 3° or downtilt by more than 1°), and a refusal
// always says what to do. The accuracy targets are over a whole
// set (MeasureSiteSet below).
//
// Sites: the everyday list (CI) holds wide-distribution development sites, one of them a site that
// must be refused with a given reason, and regression sites of the classic distribution.
// ANTPOSE_MEASURE_SET=FIRST-LAST (e.g. 7101-7112) replaces it by a set of
// wide sites drawn alike (rooftop and ground alternating, 1–3 antennas, a magnetised mast at every
// third; 2 MP photos, plain radomes and side-by-side panels forced in turn), and
// ANTPOSE_MEASURE_RESULTS=DIR keeps each site's rows there for MeasureSiteSet. With
// ANTPOSE_MEASURE_DISTRIBUTION=classic the set is drawn from the classic distribution by the same
// rule, nothing forced (the regression sets); ANTPOSE_MEASURE_REGRESSION=all adds to the everyday
// list the classic regression sites whose fault a shorter test guards.
#include <cmath>
#include <algorithm>
#include <cstdlib>
#include <functional>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "acceptance_support.hpp"
#include "antpose/geometry/rotation.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;

struct Site {
  std::string name;
  int seed = 0;
  std::string distribution = "wide";
  bool ground = false, disturbance = false;
  int antennas = 1;
  std::string forced;       // further `simulate capture` flags
  bool regression = false;  // a classic site kept as a regression check
  int only = 0;             // the one antenna (1-based) measured, or 0 for all
  std::string warns;        // a warning the answer must give (part of its text)
  std::string refuses;      // a refusal the answer must give instead (part of its text)
};

void PrintTo(const Site& s, std::ostream* os) { *os << s.name; }

// The set's k-th site (the file comment): setting, compass and panels by k; a wide site also has
// 2 MP photos, a plain radome or side-by-side panels forced in turn.
Site set_site(int seed, int k, const std::string& distribution) {
  Site s;
  s.seed = seed;
  s.distribution = distribution;
  s.ground = k % 2 == 1;
  s.disturbance = k % 3 == 2;
  s.antennas = 1 + (k / 2) % 3;
  s.name = fmt::format("{}_{}", distribution, seed);
  if (distribution != "wide") return s;
  switch (k % 4) {
    case 0:
      s.forced = "--photo-scale 0.41";
      break;  // 1640 × 1230: 2 MP
    case 1:
      s.forced = "--radome plain";
      break;
    case 2:
      s.forced = s.antennas > 1 ? "--arrangement side-by-side" : "";
      break;
    default:
      break;
  }
  return s;
}

std::vector<Site> everyday_sites() {
  std::vector<Site> sites;
  // Wide development sites (seeds 7001–7099 are for development): 2 MP on a rooftop, a plain
  // radome from the ground, three panels on a rooftop, and one whose front and back no cue decides
  // (its refusal must say what to do).
  for (const int k : {0, 1, 4, 6, 7}) {
    sites.push_back(set_site(7001 + k, k, "wide"));
    if (k == 1) sites.back().warns = "the radome shows little texture, so the angles rest on its outline";
  }
  // A grey radome before a grey sky, its points all on the mount pipe and clamps: the poses that
  // fit an outline lie on the pipe and meet little of their own, and the answer must say so rather
  // than give the pipe's tilt.
  sites.push_back(set_site(18701, 0, "wide"));
  sites.back().refuses = "meets the photos' edges along little of its outline";
  // Classic regression sites, each measuring the antenna its fault was found on.
  const auto classic = [](int seed, bool ground, bool disturbance, int antennas, int only, std::string warns = {}) {
    Site s;
    s.name = fmt::format("classic_{}_{}", seed, only);
    s.seed = seed, s.distribution = "classic", s.ground = ground, s.disturbance = disturbance;
    s.antennas = antennas, s.only = only, s.regression = true, s.warns = std::move(warns);
    return s;
  };
  sites.push_back(classic(3406, true, true, 3, 3));
  sites.push_back(classic(3711, false, false, 3, 2));
  // Measured without its neighbours, with a nearer panel across its rectangle, its best pose meets
  // too little of its outline to be an answer: none, rather than the neighbour's edges taken for
  // its own.
  sites.push_back(classic(5111, false, false, 3, 3));
  sites.back().regression = false, sites.back().refuses = "meets the photos' edges along little of its outline";
  sites.push_back(classic(5810, true, false, 2, 1));
  // The rest of the regression sites, each also guarded by a shorter test or an everyday site that
  // takes the same path.
  if (const char* all = std::getenv("ANTPOSE_MEASURE_REGRESSION"); all && std::string(all) == "all") {
    sites.push_back(classic(3312, true, true, 3, 2));
    sites.push_back(classic(3208, true, false, 1, 0));
    sites.push_back(classic(3811, false, false, 3, 3));
    sites.push_back(classic(3802, true, false, 1, 0));
    sites.push_back(classic(6109, false, true, 2, 2));
  }
  return sites;
}

std::vector<Site> sites() {
  const char* set = std::getenv("ANTPOSE_MEASURE_SET");
  if (!set) return everyday_sites();
  int first = 0, last = 0;
  if (std::sscanf(set, "%d-%d", &first, &last) != 2 || last < first) return everyday_sites();
  const char* kind = std::getenv("ANTPOSE_MEASURE_DISTRIBUTION");
  const std::string distribution = kind && std::string(kind) == "classic" ? "classic" : "wide";
  std::vector<Site> out;
  for (int seed = first; seed <= last; ++seed) out.push_back(set_site(seed, seed - first, distribution));
  return out;
}

// One antenna's row: its errors against the truth, its σ and how it answered.
struct Row {
  int antenna = 0;
  bool refused = false, warned = false, magnetic = false;
  double az = 0, tilt = 0, roll = 0, s_az = 0, s_tilt = 0, s_roll = 0;
  std::string error, warnings, verdict;
};

Row row_of(int antenna, const nlohmann::json& m, const YAML::Node& truth) {
  Row r;
  r.antenna = antenna;
  if (!m["error"].is_null()) {
    r.refused = true, r.error = m["error"].get<std::string>();
    return r;
  }
  r.az =
      rad2deg(wrap_pi(deg2rad(m["azimuth_magnetic_deg"].get<double>() - truth["azimuth_magnetic_deg"].as<double>())));
  r.tilt = m["downtilt_deg"].get<double>() - truth["downtilt_deg"].as<double>();
  r.roll = m["roll_deg"].get<double>() - truth["roll_deg"].as<double>();
  const auto& s = m["sigma"];
  r.s_az = s["azimuth_magnetic_deg"].get<double>(), r.s_tilt = s["downtilt_deg"].get<double>(),
  r.s_roll = s["roll_deg"].get<double>();
  for (const auto& w : m["warnings"]) r.warnings += w.get<std::string>() + "; ";
  r.verdict = m["verdict"].get<std::string>();
  r.warned = !r.warnings.empty();
  r.magnetic =
      r.warnings.find("magnet") != std::string::npos || r.warnings.find("disagree on the heading") != std::string::npos;
  return r;
}

class MeasureSite : public ::testing::TestWithParam<Site> {};

TEST_P(MeasureSite, AnswersAreRightOrSayWhyNot) {
  const Site& site = GetParam();
  test::TempDir dir;
  const auto capture = dir / "site";
  test::run(
      fmt::format("simulate capture -o '{}' --scenario antenna --distribution {} --seed {} --device-seed 401 "
                  "--setting {} --antennas {}{} --width 4000 --height 3000 --supersampling 2 {}",
                  capture.string(), site.distribution, site.seed, site.ground ? "ground" : "rooftop", site.antennas,
                  site.disturbance ? " --disturbance" : "", site.forced));
  if (HasFatalFailure()) return;
  const YAML::Node truth = YAML::LoadFile((capture / "truth/scene.yaml").string());
  std::vector<std::pair<int, YAML::Node>> measured;
  std::string rois;
  for (std::size_t i = 0; i < truth["antennas"].size(); ++i) {
    if (site.only != 0 && site.only != static_cast<int>(i) + 1) continue;
    const auto a = truth["antennas"][i];
    const auto roi = a["roi"];
    rois +=
        fmt::format(" --roi '{}:{},{},{},{}' --model {}", roi["image"].as<std::string>(), roi["x"].as<int>(),
                    roi["y"].as<int>(), roi["width"].as<int>(), roi["height"].as<int>(), a["model"].as<std::string>());
    measured.emplace_back(static_cast<int>(i) + 1, a);
  }
  const auto json = dir / "result.json";
  const auto r =
      test::run_cli(fmt::format("measure '{}' --device '{}' {} --json '{}'", capture.string(),
                                test::source_path("tests/data/phone401.yaml").string(), rois, json.string()));
  // 3: no antenna measured; 4: one failed or carries a σ over --max-sigma-deg (ambiguous).
  ASSERT_TRUE(r.status == 0 || r.status == 3 || r.status == 4) << r.err << r.out;
  const auto j = nlohmann::json::parse(io::read_text(json));
  ASSERT_EQ(j["antennas"].size(), measured.size());
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t n = 0; n < measured.size(); ++n) {
    const Row row = row_of(measured[n].first, j["antennas"][n], measured[n].second);
    std::printf("%s ant %d: %s\n", site.name.c_str(), row.antenna,
                row.refused
                    ? ("REFUSED: " + row.error).c_str()
                    : fmt::format("az {:+.2f} (σ {:.2f})  tilt {:+.2f} (σ {:.2f})  roll {:+.2f} (σ {:.2f})  {}  {}",
                                  row.az, row.s_az, row.tilt, row.s_tilt, row.roll, row.s_roll, row.verdict,
                                  row.warnings.substr(0, 160))
                          .c_str());
    rows.push_back({{"site", site.name},
                    {"antenna", row.antenna},
                    {"refused", row.refused},
                    {"error", row.error},
                    {"az", row.az},
                    {"tilt", row.tilt},
                    {"roll", row.roll},
                    {"s_az", row.s_az},
                    {"s_tilt", row.s_tilt},
                    {"s_roll", row.s_roll},
                    {"warned", row.warned},
                    {"magnetic", row.magnetic},
                    {"disturbed", site.disturbance},
                    {"verdict", row.verdict},
                    {"truth_downtilt", measured[n].second["downtilt_deg"].as<double>()}});
    if (row.refused) {
      EXPECT_GT(row.error.size(), 40u) << "a refusal says why and what to do";
      EXPECT_FALSE(site.regression) << site.name << ": " << row.error;
      EXPECT_NE(row.error.find(site.refuses), std::string::npos) << row.error;
      continue;
    }
    EXPECT_TRUE(site.refuses.empty()) << site.name << " must be refused (" << site.refuses << ")";
    // An error may exceed 4σ only where the answer says the angle is in doubt: an ambiguous
    // registration, or for the azimuth a compass disturbed by the mast's steel. Beyond 3° in
    // azimuth or 1° in downtilt that is a confident wrong answer.
    const bool ambiguous = row.verdict != "unique";
    const bool az_doubted = ambiguous || (site.disturbance && row.magnetic);
    const auto where = fmt::format("{} antenna {}", site.name, row.antenna);
    EXPECT_TRUE(std::abs(row.az) <= 4 * row.s_az || az_doubted) << where << ": azimuth beyond 4σ, not in doubt";
    EXPECT_TRUE(std::abs(row.tilt) <= 4 * row.s_tilt || ambiguous) << where << ": downtilt beyond 4σ, not in doubt";
    EXPECT_TRUE(std::abs(row.roll) <= 4 * row.s_roll || ambiguous) << where << ": roll beyond 4σ, not in doubt";
    EXPECT_TRUE(std::abs(row.az) <= 3.0 || az_doubted || std::abs(row.az) <= 4 * row.s_az)
        << where << ": a confident wrong azimuth";
    EXPECT_TRUE(std::abs(row.tilt) <= 1.0 || ambiguous || std::abs(row.tilt) <= 4 * row.s_tilt)
        << where << ": a confident wrong downtilt";
    if (!site.warns.empty()) {
      EXPECT_NE(row.warnings.find(site.warns), std::string::npos) << row.warnings;
    }
  }
  if (const char* results = std::getenv("ANTPOSE_MEASURE_RESULTS")) {
    fs::create_directories(results);
    io::write_text_atomic(fs::path(results) / (site.name + ".json"), rows.dump() + "\n");
  }
}

INSTANTIATE_TEST_SUITE_P(Sites, MeasureSite, ::testing::ValuesIn(sites()),
                         [](const ::testing::TestParamInfo<Site>& info) { return info.param.name; });

// RMS of x over the rows where `use` holds.
double rms(const std::vector<nlohmann::json>& rows, const char* key,
           const std::function<bool(const nlohmann::json&)>& use, const char* sigma = nullptr) {
  double sum = 0.0;
  int n = 0;
  for (const auto& r : rows)
    if (use(r)) {
      const double x = r[key].get<double>() / (sigma ? r[sigma].get<double>() : 1.0);
      sum += x * x, ++n;
    }
  return n ? std::sqrt(sum / n) : 0.0;
}

// The set's figures from the rows MeasureSite kept (ANTPOSE_MEASURE_RESULTS): RMS errors of the
// undisturbed unique answers, RMS(error/σ), refusals; the targets asserted with
// ANTPOSE_MEASURE_ACCEPTANCE=1. Run it after the sites. An ambiguous answer is not offered as a
// measurement (its σ spans its rivals), so the accuracy is that of the unique ones; the
// RMS(error/σ) holds every answer to its σ, ambiguous ones included, and the RMS over all
// undisturbed answers is printed beside it.
TEST(MeasureSiteSet, FiguresOfTheSet) {
  const char* results = std::getenv("ANTPOSE_MEASURE_RESULTS");
  if (!results) GTEST_SKIP() << "ANTPOSE_MEASURE_RESULTS names no folder of site results";
  std::vector<nlohmann::json> rows;
  for (const auto& f : fs::directory_iterator(results))
    if (f.path().extension() == ".json")
      for (const auto& r : nlohmann::json::parse(io::read_text(f.path()))) rows.push_back(r);
  const auto answered = [](const nlohmann::json& r) { return !r["refused"].get<bool>(); };
  const auto clean = [&](const nlohmann::json& r) { return answered(r) && !r["disturbed"].get<bool>(); };
  const auto unique = [&](const nlohmann::json& r) { return clean(r) && r["verdict"] == "unique"; };
  const auto refused = std::count_if(rows.begin(), rows.end(), [&](const auto& r) { return !answered(r); });
  const auto ambiguous = std::count_if(
      rows.begin(), rows.end(), [&](const nlohmann::json& r) { return answered(r) && r["verdict"] != "unique"; });
  const double az = rms(rows, "az", unique), tilt = rms(rows, "tilt", unique), roll = rms(rows, "roll", unique);
  const double z_az = rms(rows, "az", clean, "s_az"), z_tilt = rms(rows, "tilt", answered, "s_tilt");
  const double z_roll = rms(rows, "roll", answered, "s_roll");
  std::printf(
      "%zu antennas, %td refused, %td ambiguous; undisturbed unique RMS azimuth %.3f°, downtilt %.3f°, roll %.3f° "
      "(all undisturbed answers: %.3f°, %.3f°, %.3f°); RMS(error/σ) azimuth %.2f, downtilt %.2f, roll %.2f\n",
      rows.size(), refused, ambiguous, az, tilt, roll, rms(rows, "az", clean), rms(rows, "tilt", clean),
      rms(rows, "roll", clean), z_az, z_tilt, z_roll);
  if (!std::getenv("ANTPOSE_MEASURE_ACCEPTANCE")) return;
  EXPECT_LE(az, 1.0);
  EXPECT_LE(tilt, 0.3);
  EXPECT_LE(roll, 0.5);
  EXPECT_LE(static_cast<double>(refused), 0.05 * static_cast<double>(rows.size()));
  for (const double z : {z_az, z_tilt, z_roll}) {
    EXPECT_GE(z, 0.7);
    EXPECT_LE(z, 1.5);
  }
}

}  // namespace
}  // namespace antpose
