// The process's allocator set up for image-sized buffers that come and go.
//
// The pipeline allocates and frees buffers of megabytes thousands of times per site: SIFT's
// scale space for every region crop, the crops and gradient pyramids of every outline
// refinement. glibc serves blocks above its mmap threshold straight from the kernel and gives
// them back on free, so every new one is faulted in again page by page: on a 12 MP site that
// was a sixth of the CPU time. Served from the heap, kept there after free and grown in large
// steps, they are reused instead. The process's peak memory stays what the work needs: what is
// kept was in use a moment before.
#pragma once

#include <cstddef>

namespace antpose {

struct AllocatorSettings {
  /// Blocks up to this size come from the heap and are reused after free (glibc's own
  /// adjustment reaches 32 MiB on 64-bit systems, at most; a worker thread's heap holds blocks
  /// under 64 MiB whatever the setting).
  std::size_t mmap_threshold_bytes = std::size_t{32} << 20;
  /// Freed memory at the heap's top kept for reuse up to this size, not returned to the kernel
  /// (SIFT's first octave on an enlarged 1600 px crop alone takes about 300 MiB).
  std::size_t trim_threshold_bytes = std::size_t{1} << 30;
  /// The heap grows by this much beyond each request, so that a run of large blocks does not
  /// grow it (and fault it in) once per block.
  std::size_t top_pad_bytes = std::size_t{64} << 20;
};

/// Applies the settings to the process's allocator; call it once, before the work starts (a
/// program's main). Returns false where the C library offers no such control (not glibc), or
/// refuses a value; the program then runs with its allocator's defaults.
bool tune_allocator(const AllocatorSettings& settings = {});

}  // namespace antpose
