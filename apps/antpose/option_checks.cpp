#include "option_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/core.h>
#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/orientation/estimator.hpp"

namespace antpose::cli {

CLI::Validator finite_within(double lo, double hi, const std::string& unit) {
  return CLI::Validator(
      [lo, hi, unit](std::string& text) -> std::string {
        double v = 0.0;
        try {
          std::size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return fmt::format("'{}' is not a number", text);
        } catch (const std::exception&) {
          return fmt::format("'{}' is not a number", text);
        }
        if (!std::isfinite(v) || v < lo || v > hi)
          return fmt::format("{} must be within [{}, {}] {}", text, lo, hi, unit);
        return {};
      },
      fmt::format("NUMBER in [{}, {}] {}", lo, hi, unit));
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

void add_renamed_option(CLI::App& cmd, const std::string& old_name, const std::string& new_name) {
  // A hidden option has no name in CLI11's own messages, so the refusal is an InputError here.
  cmd.add_option(old_name)
      ->group("")  // hidden from --help
      ->each([old_name, new_name](const std::string& value) {
        throw InputError(old_name, fmt::format("this option is now called {} (given '{}')", new_name, value));
      });
}

CLI::Option* add_orientation_method_option(CLI::App& cmd, std::string& value, const std::string& help,
                                           const OrientationMethodSettings& settings) {
  const auto known = orientation::estimator_names();
  auto check = [known, settings](std::string& text) -> std::string {
    const auto items = split_list(text);
    if (items.empty()) return "no orientation method given";
    if (items.size() > 1 && !settings.several) return fmt::format("'{}': one orientation method only", text);
    for (const auto& item : items) {
      if (std::find(known.begin(), known.end(), item) != known.end()) continue;
      const auto& others = settings.other_names;
      if (std::find(others.begin(), others.end(), item) != others.end())
        return fmt::format("'{}' is not an orientation method: {}", item, settings.other_hint);
      return fmt::format("'{}' is not an orientation method, expected {}", item, fmt::join(known, ", "));
    }
    return {};
  };
  return cmd
      .add_option("--method", value,
                  fmt::format("{}: {}{}", help, fmt::join(known, ", "),
                              settings.several ? " (comma-separated, several allowed)" : ""))
      ->check(CLI::Validator(check, settings.several ? "METHOD[,METHOD...]" : "METHOD"));
}

}  // namespace antpose::cli
