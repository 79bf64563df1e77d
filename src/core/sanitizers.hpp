// Which sanitizer this translation unit is compiled under, for GCC
// (__SANITIZE_ADDRESS__, __SANITIZE_THREAD__) and Clang (__has_feature):
// RTHDIST_ASAN, RTHDIST_TSAN, and RTHDIST_UNDER_SANITIZER for any of them
// (MemorySanitizer included), each defined to 1 or left undefined. For code
// that must behave differently there: large blocks from operator new so that
// AddressSanitizer sees overflows (core/uninit_vector.hpp), functions
// compiled once (core/vector_clones.hpp), tests the runtime changes
// (tests/cpu/thread_pool_test.cpp). src/io, which depends on no other
// layer, and the CLI tests, which see no src/ header, test on their own.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define RTHDIST_ASAN 1
#endif
#if defined(__SANITIZE_THREAD__)
#define RTHDIST_TSAN 1
#endif
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RTHDIST_ASAN 1
#endif
#if __has_feature(thread_sanitizer)
#define RTHDIST_TSAN 1
#endif
#if __has_feature(memory_sanitizer)
#define RTHDIST_MSAN 1
#endif
#endif

#if defined(RTHDIST_ASAN) || defined(RTHDIST_TSAN) || defined(RTHDIST_MSAN)
#define RTHDIST_UNDER_SANITIZER 1
#endif
