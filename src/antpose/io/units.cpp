#include "antpose/io/units.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "antpose/core/statistics.hpp"
#include "antpose/io/capture.hpp"

namespace antpose::io {

double median_norm(const Stream& s) {
  std::vector<double> n(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) n[i] = s.xyz(i).norm();
  return median(std::move(n));
}

std::optional<UnitGuess> guess_accelerometer_unit(double m, const std::filesystem::path& file) {
  // Wide bands: a moving phone's median stays near g, a badly scaled one within ±50%.
  if (m >= 5.0 && m <= 20.0) return std::nullopt;
  if (m >= 0.5 && m <= 2.0) return UnitGuess{"g", 9.80665};
  throw InputError(file, fmt::format("accelerometer median magnitude {:.4g} fits neither m/s^2 (about 9.81) nor g (about 1)", m));
}

std::optional<UnitGuess> guess_magnetometer_unit(double m, const std::filesystem::path& file) {
  // µT: Earth's field is 20–70 µT; phones with a hard iron read up to several hundred.
  if (m >= 5.0 && m <= 2000.0) return std::nullopt;
  if (m >= 0.1 && m < 5.0) return UnitGuess{"gauss", 100.0};
  if (m >= 5000.0 && m <= 2.0e6) return UnitGuess{"nT", 1e-3};
  throw InputError(file, fmt::format("magnetometer median magnitude {:.4g} fits neither µT (20–70), gauss (0.2–0.7) nor nT (20000–70000)", m));
}

void check_units(Capture& capture, const std::filesystem::path& folder, Diagnostics& diagnostics, bool repair) {
  struct Check {
    std::string_view stream;
    std::string_view expected;
    std::optional<UnitGuess> (*guess)(double, const std::filesystem::path&);
  };
  for (const Check& check : {Check{streams::kAccelerometer, "m/s^2", guess_accelerometer_unit},
                             Check{streams::kMagnetometer, "µT", guess_magnetometer_unit}}) {
    auto it = capture.streams.find(std::string(check.stream));
    if (it == capture.streams.end() || !it->second.has_xyz()) continue;
    Stream& s = it->second;
    const auto file = stream_source(folder, s);
    const double m = median_norm(s);
    const auto guess = check.guess(m, file);
    if (!guess) continue;
    if (!repair)
      throw InputError(file, fmt::format("median magnitude {:.4g} looks like {}, expected {}; unit repair is disabled "
                                         "(--no-unit-repair), so the stream is rejected",
                                         m, guess->unit, check.expected));
    s.values.leftCols(3) *= guess->to_si;
    diagnostics.warn(file, 0, fmt::format("median magnitude {:.4g} looks like {}: converted to {} (×{}); "
                                          "use --no-unit-repair to refuse instead",
                                          m, guess->unit, check.expected, guess->to_si));
  }
}

}  // namespace antpose::io
