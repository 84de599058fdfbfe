// The simulators' seeded random streams: a capture's seed gives every random choice its own
// stream, so that a change in one (another photo count, say) leaves the others' draws alone.
#pragma once

#include <cstdint>
#include <random>

namespace antpose::sim {

/// The generator of stream `stream` of `seed`. `salt` keeps two simulators' streams of the same
/// number apart (the capture simulator's and the IMU simulator's).
inline std::mt19937_64 make_rng(std::uint64_t seed, std::uint64_t stream, std::uint32_t salt) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream), salt};
  return std::mt19937_64(seq);
}

/// Uniform on [lo, hi).
inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// Uniform on the integers lo..hi (both included).
inline int uniform_int(std::mt19937_64& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }

}  // namespace antpose::sim
