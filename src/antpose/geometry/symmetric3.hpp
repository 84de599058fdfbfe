// The six independent entries of a symmetric 3×3 matrix, in the order its parameters are kept
// (the upper triangle row by row: xx, xy, xz, yy, yz, zz), as a soft-iron matrix is fitted and
// its σ reported.
#pragma once

#include <array>

namespace antpose {

struct SymmetricEntry {
  int row = 0, col = 0;
};

inline constexpr std::array<SymmetricEntry, 6> kSymmetricEntries{{{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}}};

}  // namespace antpose
