#pragma once

namespace lidarloop::app {

/// Lets the C library's allocator keep freed memory for the next scan instead of returning it to
/// the kernel: every scan allocates and frees a few megabytes (its points, their voxels), and by
/// default glibc unmaps such blocks or trims them off the heap, so the next scan takes a page
/// fault for every page it touches again (most of reading a dense scan, a tenth of preparing
/// it; docs/BENCHMARK.md, "Freed memory kept for the next scan"). Holds on to at most 64 MiB free
/// per allocator arena. For a whole process (the command-line tool calls it first); returns whether
/// the allocator took the settings (false where it is not glibc's).
bool KeepFreedMemoryForReuse();

}  // namespace lidarloop::app
