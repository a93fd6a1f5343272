// release_free_heap_memory against the process's resident size as the kernel counts it (VmRSS
// of /proc/self/status): small blocks freed in the middle of glibc's heap, below a block that
// stays allocated, stay resident (free can only shorten the heap at its top), and the trim gives
// their pages back.

#include "numerics/heap_memory.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "../resident_set.hpp"

namespace robin {
namespace {

TEST(HeapMemory, FreedBlocksBelowALiveOneLeaveTheResidentSetOnlyWhenReleased) {
  if (!releases_free_heap_memory()) {
    GTEST_SKIP() << "not glibc's allocator: release_free_heap_memory does nothing here";
  }
  constexpr std::size_t block_bytes = 4000;   // below glibc's mmap threshold: in the heap
  constexpr std::size_t block_count = 50000;  // 200 MB
  std::vector<char*> blocks;
  blocks.reserve(block_count);
  for (std::size_t k = 0; k < block_count; ++k) {
    char* block = static_cast<char*>(std::malloc(block_bytes));
    ASSERT_NE(block, nullptr);
    std::memset(block, 1, block_bytes);  // resident
    blocks.push_back(block);
  }
  char* live = static_cast<char*>(std::malloc(block_bytes));  // above the freed ones
  ASSERT_NE(live, nullptr);
  std::memset(live, 2, block_bytes);
  const double allocated = resident_mib();
  for (char* block : blocks) std::free(block);
  const double freed = resident_mib();
  release_free_heap_memory();
  const double released = resident_mib();
  const double megabytes = block_count * block_bytes / (1024.0 * 1024.0);
  EXPECT_GT(freed, allocated - 0.25 * megabytes) << "free alone gave most of the heap back";
  EXPECT_LT(released, freed - 0.75 * megabytes)
      << "resident " << allocated << " MiB allocated, " << freed << " MiB freed, " << released
      << " MiB released";
  EXPECT_EQ(live[block_bytes - 1], 2);
  std::free(live);
}

}  // namespace
}  // namespace robin
