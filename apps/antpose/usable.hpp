// Whether a measured attitude is usable: the policy behind exit status 4 (commands.hpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace antpose::cli {

/// The default of --max-sigma-deg: a 1σ of 5° cannot tell an antenna inside a ±3° azimuth
/// tolerance (the common acceptance for panels) from one outside it.
inline constexpr double kDefaultMaxSigmaDeg = 5.0;

/// Adds --max-sigma-deg to `cmd`, checked to be positive and finite.
void add_max_sigma_option(CLI::App* cmd, double& max_sigma_deg);

/// One angle of a result: value and 1σ, rad; either may be missing.
struct AngleReading {
  std::string name;
  std::optional<double> value;
  std::optional<double> sigma;
};

/// Why the angles are not usable ("azimuth σ 8.1° over --max-sigma-deg 5", "roll undefined"),
/// joined by "; "; empty when every angle has a value and a σ within the limit.
std::string unusable_reason(const std::vector<AngleReading>& angles, double max_sigma_deg);

}  // namespace antpose::cli
