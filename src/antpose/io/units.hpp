// Detection of streams recorded in the wrong unit, from their typical magnitude.
//
// A phone at rest measures |specific force| = g ≈ 9.81 m/s^2 and an Earth field of 20–70 µT.
// An accelerometer whose median magnitude is near 1 is in g; a magnetometer near 0.2–0.7 is in
// gauss and one near 20 000–70 000 is in nT. Those are converted (with a warning) when repair
// is allowed, and are errors otherwise. Implausible magnitudes that fit no unit are errors.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "antpose/core/error.hpp"

namespace antpose {
struct Capture;
struct Stream;
}  // namespace antpose

namespace antpose::io {

struct UnitGuess {
  std::string unit;     // name of the unit the data appears to be in, e.g. "g", "gauss", "nT"
  double to_si = 1.0;   // factor to the capture unit (m/s^2 or µT)
};

/// Median of |(x, y, z)| over a stream (requires x, y, z columns).
double median_norm(const Stream& stream);

/// Unit of an accelerometer stream from its median magnitude; empty when already m/s^2.
/// Throws InputError (naming `file`) when the magnitude fits no known unit.
std::optional<UnitGuess> guess_accelerometer_unit(double median_norm, const std::filesystem::path& file);
/// Same for a magnetometer (µT expected; gauss and nT recognised).
std::optional<UnitGuess> guess_magnetometer_unit(double median_norm, const std::filesystem::path& file);

/// Applies both checks to the capture's accelerometer and magnetometer streams.
void check_units(Capture& capture, const std::filesystem::path& folder, Diagnostics& diagnostics, bool repair);

}  // namespace antpose::io
