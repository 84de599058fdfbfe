#include "antpose/sim/procedural_noise.hpp"

#include <cmath>

namespace antpose::sim {

std::uint64_t mix_bits(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double lattice_value(std::int64_t i, std::int64_t j, std::int64_t k, std::uint64_t seed) {
  const std::uint64_t h = mix_bits(seed ^ mix_bits(static_cast<std::uint64_t>(i) ^
                                                   mix_bits(static_cast<std::uint64_t>(j) ^
                                                            mix_bits(static_cast<std::uint64_t>(k)))));
  return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;  // [-1, 1)
}

double value_noise(const Vec3& p, std::uint64_t seed) {
  const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
  const auto i = static_cast<std::int64_t>(fx), j = static_cast<std::int64_t>(fy), k = static_cast<std::int64_t>(fz);
  auto smooth = [](double t) { return t * t * (3.0 - 2.0 * t); };
  const double ax = smooth(p.x() - fx), ay = smooth(p.y() - fy), az = smooth(p.z() - fz);
  double c[2][2][2];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int d = 0; d < 2; ++d) c[a][b][d] = lattice_value(i + a, j + b, k + d, seed);
  auto lerp = [](double u, double v, double t) { return u + t * (v - u); };
  const double x00 = lerp(c[0][0][0], c[1][0][0], ax), x10 = lerp(c[0][1][0], c[1][1][0], ax);
  const double x01 = lerp(c[0][0][1], c[1][0][1], ax), x11 = lerp(c[0][1][1], c[1][1][1], ax);
  return lerp(lerp(x00, x10, ay), lerp(x01, x11, ay), az);
}

}  // namespace antpose::sim
