#pragma once
// Giving freed heap memory back to the operating system.

namespace robin {

/// Returns the pages of freed heap memory to the system (glibc's malloc_trim; glibc keeps them
/// otherwise, in the middle of its arenas), so that they do not count again in the resident
/// size beside what is allocated next (a factor, a body's fields). Does nothing on other C
/// libraries.
void release_free_heap_memory();

}  // namespace robin
