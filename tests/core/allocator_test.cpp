#include "antpose/core/allocator.hpp"

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace antpose {
namespace {

#if defined(__GLIBC__)
TEST(Allocator, ImageSizedBlocksComeFromTheReusedHeapOnceTuned) {
  ASSERT_TRUE(tune_allocator());
  // glibc's default serves a 16 MiB block by mmap (counted in hblkhd); tuned, the heap serves it.
  const auto mapped_before = mallinfo2().hblkhd;
  constexpr std::size_t kBlock = std::size_t{16} << 20;
  void* block = std::malloc(kBlock);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, kBlock);
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before);
  std::free(block);
}

TEST(Allocator, SaysWhenAValueCannotBeSet) {
  AllocatorSettings beyond_int;  // mallopt takes an int
  beyond_int.trim_threshold_bytes = std::size_t{1} << 40;
  EXPECT_FALSE(tune_allocator(beyond_int));
}
#else
TEST(Allocator, HasNoControlWithoutGlibc) { EXPECT_FALSE(tune_allocator()); }
#endif

}  // namespace
}  // namespace antpose
