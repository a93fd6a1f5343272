#include "numerics/heap_memory.hpp"

#include <cstdlib>  // defines __GLIBC__ (through <features.h>) with the GNU C library

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// AddressSanitizer replaces malloc: glibc's heap is then not the one in use (GCC defines
// __SANITIZE_ADDRESS__, Clang answers __has_feature)
#if defined(__SANITIZE_ADDRESS__)
#define ROBIN_SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ROBIN_SANITIZER_ALLOCATOR 1
#endif
#endif

namespace robin {

#if defined(__GLIBC__) && !defined(ROBIN_SANITIZER_ALLOCATOR)
void release_free_heap_memory() {
  malloc_trim(0);
}

bool releases_free_heap_memory() {
  return true;
}

void map_large_blocks_separately(std::size_t threshold_bytes) {
  mallopt(M_MMAP_THRESHOLD, static_cast<int>(threshold_bytes));
}
#else
void release_free_heap_memory() {}

bool releases_free_heap_memory() {
  return false;
}

void map_large_blocks_separately(std::size_t) {}
#endif

}  // namespace robin
