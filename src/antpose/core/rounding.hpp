// Rounding to the nearest integer, half away from zero (std::lround's rule), inline: pixel
// look-ups in the outline searches run once per search step of every sample, where the libm call
// costs several per cent of a measurement.
#pragma once

namespace antpose {

inline int round_half_away(double v) { return static_cast<int>(v < 0.0 ? v - 0.5 : v + 0.5); }

}  // namespace antpose
