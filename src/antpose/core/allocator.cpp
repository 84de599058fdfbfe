#include "antpose/core/allocator.hpp"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace antpose {

bool tune_allocator(const AllocatorSettings& settings) {
#if defined(__GLIBC__)
  const auto set = [](int parameter, std::size_t value) {
    return value <= INT_MAX && mallopt(parameter, static_cast<int>(value)) == 1;  // mallopt: 1 on success
  };
  // Setting a threshold also stops glibc's own adjustment of both.
  const bool mmap_set = set(M_MMAP_THRESHOLD, settings.mmap_threshold_bytes);
  const bool trim_set = set(M_TRIM_THRESHOLD, settings.trim_threshold_bytes);
  const bool pad_set = set(M_TOP_PAD, settings.top_pad_bytes);
  return mmap_set && trim_set && pad_set;
#else
  (void)settings;
  return false;
#endif
}

}  // namespace antpose
