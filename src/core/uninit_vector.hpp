// UninitVector<T>: large per-point host arrays (the CPU backend's, the
// out-of-core chunks' best pairs). A std::vector
// whose resize(n) leaves new elements default-initialised (for the
// arithmetic types stored here: not written at all), so an array that is
// filled by parallel workers is first touched by those workers instead of
// being zeroed by one thread first; resize(n, value) still writes `value`.
// Blocks of at least kLargeBlock bytes are mapped on their own and, on Linux,
// marked for transparent huge pages (one page fault per 2 MiB instead of per
// 4 KiB: at 5M points the faults of fresh arrays cost more than the sort).
//
// Contract: only for trivially copyable element types whose every element is
// written before it is read. Not under AddressSanitizer: there every block
// comes from operator new so that overflows stay detected.
// Threading: as std::vector (the allocator itself is stateless).
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rthdist::core {

namespace detail {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kMapLargeBlocks = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kMapLargeBlocks = false;
#else
inline constexpr bool kMapLargeBlocks = true;
#endif
#else
inline constexpr bool kMapLargeBlocks = true;
#endif

inline constexpr size_t kLargeBlock = size_t(4) << 20;  // bytes; smaller blocks from operator new

[[nodiscard]] inline void* allocateBlock(size_t bytes) {
#if defined(__linux__)
    if (kMapLargeBlocks && bytes >= kLargeBlock) {
        void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        madvise(p, bytes, MADV_HUGEPAGE);  // a hint: failure only costs speed
        return p;
    }
#endif
    return ::operator new(bytes);
}

inline void freeBlock(void* p, size_t bytes) noexcept {
#if defined(__linux__)
    if (kMapLargeBlocks && bytes >= kLargeBlock) {
        munmap(p, bytes);
        return;
    }
#endif
    ::operator delete(p);
}

}  // namespace detail

template <class T>
struct UninitAllocator {
    static_assert(std::is_trivially_copyable_v<T>);
    using value_type = T;

    UninitAllocator() = default;
    template <class U>
    UninitAllocator(const UninitAllocator<U>&) noexcept {}

    [[nodiscard]] T* allocate(size_t n) { return static_cast<T*>(detail::allocateBlock(n * sizeof(T))); }
    void deallocate(T* p, size_t n) noexcept { detail::freeBlock(p, n * sizeof(T)); }

    // Value-less construction default-initialises (no write); with a value, copies it.
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        if constexpr (sizeof...(Args) == 0) {
            ::new (static_cast<void*>(p)) U;
        } else {
            ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
        }
    }

    friend bool operator==(const UninitAllocator&, const UninitAllocator&) noexcept { return true; }
};

template <class T>
using UninitVector = std::vector<T, UninitAllocator<T>>;

}  // namespace rthdist::core
