// Procedural noise for the simulated scenes' surfaces (radome dirt, facades, tree crowns, clouds):
// value noise on an integer lattice whose corner values are hashed from the lattice point and a
// seed, so it needs no tables, is deterministic for a seed and is safe to call from the
// renderer's threads.
#pragma once

#include <cstdint>

#include "antpose/geometry/rotation.hpp"

namespace antpose::sim {

/// The splitmix64 finaliser (Steele, Lea & Flood, "Fast splittable pseudorandom number
/// generators", OOPSLA 2014): a bijective 64-bit mix whose every input bit affects every output bit.
std::uint64_t mix_bits(std::uint64_t x);

/// A value in [−1, 1) hashed from the lattice point (i, j, k) and the seed.
double lattice_value(std::int64_t i, std::int64_t j, std::int64_t k, std::uint64_t seed);

/// Smooth value noise in [−1, 1] with unit lattice spacing: the lattice values interpolated with
/// the smoothstep weights t²(3 − 2t), so the noise is C¹.
double value_noise(const Vec3& p, std::uint64_t seed);

}  // namespace antpose::sim
