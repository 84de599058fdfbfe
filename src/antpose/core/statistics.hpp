// Order statistics shared across antpose: the sampling interval of a stream, a robust scale
// (σ ≈ 1.4826 · median |r| for Gaussian residuals), the median of a set of estimates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace antpose {

/// The element of rank ⌊q (n − 1)⌋ (0-based) of the sorted values, q clamped to [0, 1]; 0 when
/// there are none. Takes a copy: std::nth_element reorders it (O(n), no full sort).
template <typename T>
double quantile(std::vector<T> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return static_cast<double>(v[k]);
}

/// The upper median: the element of rank ⌊n / 2⌋ (0-based) of the sorted values, the middle one
/// for odd n; 0 when there are none. For an even n it is one of the two middle values, not their
/// mean: the robust uses here (thresholds, scales over hundreds of samples) need a value that
/// occurs.
template <typename T>
double median(std::vector<T> v) {
  if (v.empty()) return 0.0;
  const std::size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return static_cast<double>(v[k]);
}

/// The robust scale of residuals about their centre, 1.4826 · median |r|: σ for Gaussian residuals,
/// unmoved by a few outsized ones. 0 when there are none.
template <typename T>
double robust_sigma(std::vector<T> residuals) {
  for (T& r : residuals) r = std::abs(r);
  return 1.4826 * median(std::move(residuals));
}

}  // namespace antpose
