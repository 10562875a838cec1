#pragma once

// Function multi-versioning for hot loops: LIDARLOOP_VECTOR_CLONES before a function adds an AVX2
// copy (twice SSE2's lanes), picked at load time on CPUs that have it; the build itself targets
// plain x86-64. AVX2 does not include FMA, so both copies round identically: results do not
// depend on the CPU. Off under AddressSanitizer and on other compilers and architectures.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
#define LIDARLOOP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LIDARLOOP_VECTOR_CLONES
#endif

// For the kernels such a function calls: inlined into each copy, so they are compiled for its
// target too (a kernel left out of line would run SSE2 code in the AVX2 copy).
#if defined(__GNUC__)
#define LIDARLOOP_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define LIDARLOOP_ALWAYS_INLINE inline
#endif
