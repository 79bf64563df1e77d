// PointAllocator's memory (rthdist/io.hpp): the loaders' own copy of the idea
// in src/core/uninit_vector.hpp (src/io includes no other folder), without
// its cache of freed blocks: a loaded cloud is freed once, when its caller
// is done with it. Large arrays are mapped on their own so that the threads
// that convert a file's chunks fault in their own pages (2 MiB at a time
// where transparent huge pages are allowed), instead of one thread touching
// the whole array first.
#include <cstdint>
#include <new>

#include "rthdist/io.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rthdist::io::detail {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kMapLargeArrays = false;  // operator new keeps overflows detected
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kMapLargeArrays = false;
#else
constexpr bool kMapLargeArrays = true;
#endif
#else
constexpr bool kMapLargeArrays = true;
#endif

constexpr size_t kLargeArray = size_t(4) << 20;
constexpr size_t kHugePage = size_t(2) << 20;

[[nodiscard]] size_t mappedBytes(size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

[[nodiscard]] bool mapped(size_t bytes) {
#if defined(__linux__)
    return kMapLargeArrays && bytes >= kLargeArray;
#else
    (void)bytes;
    return false;
#endif
}

}  // namespace

void* allocatePointBytes(size_t bytes) {
#if defined(__linux__)
    if (mapped(bytes)) {
        if (bytes > SIZE_MAX - kHugePage) throw std::bad_alloc();
        void* p =
            ::mmap(nullptr, mappedBytes(bytes), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        (void)::madvise(p, mappedBytes(bytes), MADV_HUGEPAGE);  // a hint: refused, it costs only speed
        return p;
    }
#endif
    return ::operator new(bytes);
}

void freePointBytes(void* p, size_t bytes) noexcept {
#if defined(__linux__)
    if (mapped(bytes)) {
        ::munmap(p, mappedBytes(bytes));
        return;
    }
#endif
    ::operator delete(p);
}

}  // namespace rthdist::io::detail
