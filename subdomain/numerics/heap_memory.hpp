#pragma once
// Giving freed heap memory back to the operating system.

namespace robin {

/// Returns the pages of freed heap memory to the system (glibc's malloc_trim; glibc keeps them
/// otherwise, in the middle of its arenas), so that they do not count again in the resident
/// size beside what is allocated next (a factor, a body's fields). Does nothing on other C
/// libraries, and under AddressSanitizer, whose allocator is not glibc's: glibc's trim of its
/// never-used arenas, first called from two setup threads at once, read a null arena pointer.
void release_free_heap_memory();

/// Whether release_free_heap_memory gives memory back in this build (glibc's allocator in use).
bool releases_free_heap_memory();

}  // namespace robin
