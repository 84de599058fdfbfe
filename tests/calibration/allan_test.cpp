// OADEV against Stable32 and NIST SP 1065 reference values (../shared/data/allan/README.md):
// the term count `#` exactly, σ within 1e-4 relative (Stable32, 5 digits) or 5e-7 (NIST, 7).
#include "antpose/calibration/allan.hpp"

#include <cmath>
#include <random>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::calibration {
namespace {

// Rows of a CSV with a header line, as numbers.
std::vector<std::vector<double>> read_csv(const std::string& relative) {
  std::stringstream in(io::read_text(test::shared_path(relative)));
  std::string line;
  std::getline(in, line);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

std::vector<double> column(const std::vector<std::vector<double>>& rows, std::size_t c) {
  std::vector<double> v;
  for (const auto& r : rows) v.push_back(r.at(c));
  return v;
}

// Compares a Stable32 table (af,tau_s,n,alpha,[min,]oadev[,max]) with our OADEV; returns the
// max relative error.
double compare_table(const std::vector<std::vector<double>>& table, std::size_t sigma_col,
                     const std::vector<AllanPoint>& ours, double tau0) {
  EXPECT_EQ(ours.size(), table.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(ours.size(), table.size()); ++i) {
    EXPECT_EQ(ours[i].m, static_cast<std::size_t>(table[i][0]));
    EXPECT_EQ(ours[i].n, static_cast<std::size_t>(table[i][2])) << "af " << table[i][0];
    EXPECT_DOUBLE_EQ(ours[i].tau, table[i][0] * tau0);
    const double rel = std::abs(ours[i].deviation / table[i][sigma_col] - 1.0);
    EXPECT_LT(rel, 1e-4) << "af " << table[i][0] << ": " << ours[i].deviation << " vs " << table[i][sigma_col];
    worst = std::max(worst, rel);
  }
  return worst;
}

std::vector<std::size_t> afs(const std::vector<std::vector<double>>& table) {
  std::vector<std::size_t> m;
  for (const auto& r : table) m.push_back(static_cast<std::size_t>(r[0]));
  return m;
}

TEST(Allan, PhaseDatMatchesStable32AllTauAndOctave) {
  const auto x = column(read_csv("data/allan/phase-dat/phase.csv"), 1);
  ASSERT_EQ(x.size(), 1001u);
  const auto all = read_csv("data/allan/phase-dat/oadev-alltau.csv");
  const double e1 = compare_table(all, 4, oadev_phase(x, 1.0, afs(all)), 1.0);
  const auto oct = read_csv("data/allan/phase-dat/oadev-octave.csv");
  EXPECT_EQ(octave_factors(x.size()).size(), 9u);  // 1 … 256 (Stable32 stops its octave run at 128)
  const double e2 = compare_table(oct, 5, oadev_phase(x, 1.0, afs(oct)), 1.0);
  std::printf("PHASE.DAT OADEV max relative error vs Stable32: all-tau %.2e, octave %.2e\n", e1, e2);
}

TEST(Allan, PinkFrequencyMatchesStable32) {
  const auto y = column(read_csv("data/allan/pink-frequency/frequency.csv"), 1);
  ASSERT_EQ(y.size(), 10000u);
  const auto all = read_csv("data/allan/pink-frequency/oadev-alltau-tau0-42s.csv");
  const double e1 = compare_table(all, 4, oadev_frequency(y, 42.0, afs(all)), 42.0);
  const auto oct = read_csv("data/allan/pink-frequency/oadev-octave.csv");
  const double e2 = compare_table(oct, 5, oadev_frequency(y, 1.0, afs(oct)), 1.0);
  std::printf("pink_frequency OADEV max relative error vs Stable32: all-tau %.2e, octave %.2e\n", e1, e2);
}

TEST(Allan, NbsSetsMatchNistSp1065) {
  const std::vector<double> nine = column(read_csv("data/allan/nbs14/nbs-9point-frequency.csv"), 1);
  const std::vector<double> thousand = column(read_csv("data/allan/nbs14/nbs14-1000point-frequency.csv"), 2);
  ASSERT_EQ(nine.size(), 9u);
  ASSERT_EQ(thousand.size(), 1000u);
  std::stringstream in(io::read_text(test::shared_path("data/allan/nbs14/reference.csv")));
  std::string line;
  std::getline(in, line);
  double worst = 0.0;
  int rows = 0;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string name, tau0, af, tau, adev, oadev;
    std::getline(ls, name, ',');
    std::getline(ls, tau0, ',');
    std::getline(ls, af, ',');
    std::getline(ls, tau, ',');
    std::getline(ls, adev, ',');
    std::getline(ls, oadev, ',');
    const auto& y = name == "nbs-9point" ? nine : thousand;
    const std::vector<std::size_t> m = {static_cast<std::size_t>(std::stoul(af))};
    const auto o = oadev_frequency(y, std::stod(tau0), m);
    const auto a = adev_frequency(y, std::stod(tau0), m);
    ASSERT_EQ(o.size(), 1u);
    ASSERT_EQ(a.size(), 1u);
    for (const auto& [ours, theirs] : {std::pair{o[0].deviation, std::stod(oadev)}, std::pair{a[0].deviation, std::stod(adev)}}) {
      const double rel = std::abs(ours / theirs - 1.0);
      EXPECT_LT(rel, 5e-7) << name << " af " << af << ": " << ours << " vs " << theirs;
      worst = std::max(worst, rel);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 5);
  std::printf("NBS 9-point / NBS14 1000-point ADEV+OADEV max relative error vs NIST SP 1065: %.2e\n", worst);
}

TEST(Allan, NoiseFitRecoversSimulatedWhiteNoiseAndRandomWalk) {
  // Rate samples at 100 Hz: white noise density N and a rate random walk K (IEEE 952 model).
  const double fs = 100.0, N = 2e-3, K = 2e-4;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  std::vector<double> y(400000);
  double walk = 0.0;
  for (auto& v : y) {
    walk += K * std::sqrt(1.0 / fs) * n01(rng);
    v = walk + N * std::sqrt(fs) * n01(rng);
  }
  const auto curve = oadev_frequency(y, 1.0 / fs, log_factors(y.size() + 1, 10));
  const NoiseFit fit = fit_noise(curve);
  ASSERT_TRUE(fit.white && fit.random_walk && fit.bias_instability);
  EXPECT_NEAR(*fit.white / N, 1.0, 0.05);
  EXPECT_NEAR(*fit.random_walk / K, 1.0, 0.35);  // few long-tau terms: ±30 % is the estimator's spread
  std::printf("simulated N %.3e (true %.3e), K %.3e (true %.3e), B %.3e at tau %.1f s\n", *fit.white, N, *fit.random_walk,
              K, *fit.bias_instability, *fit.bias_instability_tau);
  const std::string svg = allan_svg({{"x", curve, fit}}, "test", "rad/s");
  EXPECT_THAT(svg, ::testing::HasSubstr("<polyline"));
}

TEST(Allan, TooFewPointsIsAnError) {
  EXPECT_THROW(oadev_phase({1.0, 2.0}, 1.0, {1}), std::invalid_argument);
  EXPECT_THROW(oadev_phase({1.0, 2.0, 3.0}, 0.0, {1}), std::invalid_argument);
  Stream s = Stream::vector3("gyroscope", {0.0, 0.01}, {Vec3::Zero(), Vec3::Zero()});
  Diagnostics d;
  try {
    allan_of_stream(s, d, "cap");
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("has 2 samples, need at least 100"));
  }
}

}  // namespace
}  // namespace antpose::calibration
