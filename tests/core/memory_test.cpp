// Tests of core/memory.h: the free heap is measured and handed back only above the size asked to be kept.
#include "core/memory.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

namespace hsr {
namespace {

#if defined(__GLIBC__)
// DECISIONS #200: 64 MB freed in 64 KB blocks between blocks still held (so glibc cannot give them back by
// shrinking the heap's top) stay in the heap: release_free_memory_above keeps them under a larger size and hands
// them back under a smaller one.
TEST(Memory, TheFreeHeapGoesBackOnlyAboveTheSizeKept) {
  constexpr std::size_t kBlock = std::size_t{64} << 10, kBlocks = 2048;
  std::vector<void*> blocks(kBlocks);
  for (void*& b : blocks) {
    b = std::malloc(kBlock);
    ASSERT_NE(b, nullptr);
    static_cast<volatile char*>(b)[0] = 1;
  }
  for (std::size_t i = 0; i < kBlocks; i += 2) {
    std::free(blocks[i]);
    blocks[i] = nullptr;
  }
  const std::size_t freed = free_heap_bytes();
  EXPECT_GE(freed, kBlocks / 2 * kBlock);
  EXPECT_FALSE(release_free_memory_above(freed + (std::size_t{1} << 30)));
  EXPECT_GE(free_heap_bytes(), kBlocks / 2 * kBlock);  // kept
  EXPECT_TRUE(release_free_memory_above(std::size_t{1} << 20));
  for (void* b : blocks) std::free(b);
}
#endif

}  // namespace
}  // namespace hsr
