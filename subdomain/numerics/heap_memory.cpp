#include "numerics/heap_memory.hpp"

#include <cstdlib>  // defines __GLIBC__ (through <features.h>) with the GNU C library

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace robin {

void release_free_heap_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace robin
