#include "skinmesh/core/allocator.hpp"

#include <cstdlib>  // defines __GLIBC__ where it applies

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace skinmesh {

void return_large_blocks_to_system() {
#if defined(__GLIBC__)
  // Setting the threshold also turns off glibc's dynamic adjustment of it.
  mallopt(M_MMAP_THRESHOLD, 64 * 1024);
#endif
}

}  // namespace skinmesh
