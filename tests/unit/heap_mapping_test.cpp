// map_large_blocks_separately against the process's resident size (VmRSS of
// /proc/self/status): once the mapping threshold is fixed, large blocks leave the resident set
// when freed, even after a larger temporary would have raised glibc's dynamic threshold. In an
// executable of its own: blocks served from free heap space that another test left would not
// be mappings.

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "../resident_set.hpp"
#include "numerics/heap_memory.hpp"

namespace robin {
namespace {

TEST(HeapMemory, LargeBlocksLeaveTheResidentSetWhenFreedOnceMappedSeparately) {
  if (!releases_free_heap_memory()) {
    GTEST_SKIP() << "not glibc's allocator: map_large_blocks_separately does nothing here";
  }
  map_large_blocks_separately(std::size_t{1} << 20);
  constexpr std::size_t mebibyte = 1024 * 1024;
  // A large temporary freed: by default glibc would now serve blocks of up to its size from
  // the heap (its dynamic threshold), where freed blocks below a live one stay resident.
  char* temporary = static_cast<char*>(std::malloc(24 * mebibyte));
  ASSERT_NE(temporary, nullptr);
  std::memset(temporary, 1, 24 * mebibyte);
  std::free(temporary);
  constexpr std::size_t block_count = 6;
  std::vector<char*> blocks;
  for (std::size_t k = 0; k < block_count; ++k) {
    blocks.push_back(static_cast<char*>(std::malloc(8 * mebibyte)));
    ASSERT_NE(blocks.back(), nullptr);
    std::memset(blocks.back(), 1, 8 * mebibyte);
  }
  char* live = static_cast<char*>(std::malloc(4000));  // above the blocks, were they in the heap
  ASSERT_NE(live, nullptr);
  std::memset(live, 2, 4000);
  const double allocated = resident_mib();
  for (char* block : blocks) std::free(block);
  const double freed = resident_mib();
  EXPECT_LT(freed, allocated - 0.75 * 8.0 * block_count)
      << "resident " << allocated << " MiB allocated, " << freed << " MiB freed";
  EXPECT_EQ(live[3999], 2);
  std::free(live);
}

}  // namespace
}  // namespace robin
