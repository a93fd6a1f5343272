#pragma once
// Giving freed heap memory back to the operating system.

#include <cstddef>

namespace robin {

/// Returns the pages of freed heap memory to the system (glibc's malloc_trim; glibc keeps them
/// otherwise, in the middle of its arenas), so that they do not count again in the resident
/// size beside what is allocated next (a factor, a body's fields). Does nothing on other C
/// libraries, and under AddressSanitizer, whose allocator is not glibc's: glibc's trim of its
/// never-used arenas, first called from two setup threads at once, read a null arena pointer.
void release_free_heap_memory();

/// Whether release_free_heap_memory gives memory back in this build (glibc's allocator in use).
bool releases_free_heap_memory();

/// Makes every later allocation of at least `threshold_bytes` a mapping of its own, returned to
/// the system as soon as it is freed (glibc's M_MMAP_THRESHOLD, fixed). By default glibc raises
/// its threshold to the size of each mapped block freed (up to 32 MiB), so that after a large
/// temporary is freed the next blocks of up to that size come from the heap, where they stay
/// resident once freed, beside the factor allocated next. Does nothing where
/// releases_free_heap_memory() is false.
void map_large_blocks_separately(std::size_t threshold_bytes);

}  // namespace robin
