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

void keep_large_blocks_for_reuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  // The heap's top is given back only past this much free memory (the
  // default, 128 KiB, gave back and faulted in again a frame's copies).
  mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024);
#endif
}

}  // namespace skinmesh
