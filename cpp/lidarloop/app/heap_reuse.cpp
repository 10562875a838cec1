#include "lidarloop/app/heap_reuse.hpp"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace lidarloop::app {
namespace {

// Blocks from this size on are mapped by themselves (and unmapped when freed): above any scan or
// submap (600k points, 7 MB), under glibc's maximum of 32 MiB.
constexpr int kMapAtLeastBytes = 16 << 20;
// The free top of a heap is given back to the kernel only beyond this.
constexpr int kTrimBeyondBytes = 64 << 20;

}  // namespace

bool KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
    // Setting either threshold also stops glibc from adjusting both as it goes.
    return mallopt(M_MMAP_THRESHOLD, kMapAtLeastBytes) == 1 &&
           mallopt(M_TRIM_THRESHOLD, kTrimBeyondBytes) == 1;
#else
    return false;
#endif
}

}  // namespace lidarloop::app
