#include "usable.hpp"

#include <cmath>

#include <fmt/format.h>

#include "antpose/geometry/rotation.hpp"

namespace antpose::cli {

void add_max_sigma_option(CLI::App* cmd, double& max_sigma_deg) {
  cmd->add_option("--max-sigma-deg", max_sigma_deg,
                  "an angle whose 1-sigma exceeds this is reported but not usable (exit status 4)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
}

std::string unusable_reason(const std::vector<AngleReading>& angles, double max_sigma_deg) {
  std::string why;
  const auto add = [&](const std::string& item) { why += (why.empty() ? "" : "; ") + item; };
  for (const auto& a : angles) {
    if (!a.value)
      add(a.name + " undefined");
    else if (!a.sigma || !std::isfinite(*a.sigma))
      add(a.name + " without a sigma");
    else if (rad2deg(*a.sigma) > max_sigma_deg)
      add(fmt::format("{} sigma {:.2f}° over --max-sigma-deg {:g}", a.name, rad2deg(*a.sigma), max_sigma_deg));
  }
  return why;
}

}  // namespace antpose::cli
