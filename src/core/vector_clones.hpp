// RTHDIST_VECTOR_CLONES: a function compiled three times, for the x86-64
// baseline the package targets (SSE2), for AVX2 and for AVX-512
// (x86-64-v4), the dynamic loader picking the one the CPU runs (GCC and
// Clang target_clones, an IFUNC). For the host's hot loops over every point
// that the compiler vectorizes: each point's cell in the out-of-core
// partition ran 3x faster with it on this machine's AVX-512 (22M points on 2
// cores, docs/bench/scale session 13).
//
// Exactness: the project compiles with -ffp-contract=off (CMakeLists.txt),
// so no clone fuses a product and a sum into an FMA: every clone rounds
// every operation as written, and computes the same bits as the baseline
// (IEEE arithmetic, vector or scalar).
//
// Elsewhere (not x86-64, not an ELF target, or under a sanitizer) the
// functions are compiled once, as written: a clone's resolver runs while
// the program is relocated, before a sanitizer's runtime is up, and
// ThreadSanitizer's instrumentation of it crashed the tests at start
// (rthdist_core_tests, GCC 12).
#pragma once

#include "core/sanitizers.hpp"

#if defined(__x86_64__) && defined(__ELF__) && !defined(RTHDIST_UNDER_SANITIZER)
#define RTHDIST_VECTOR_CLONES __attribute__((target_clones("default", "avx2", "arch=x86-64-v4")))
#else
#define RTHDIST_VECTOR_CLONES
#endif
