// UninitVector<T>: large per-point host arrays (the CPU backend's, the
// out-of-core chunks' best pairs). A std::vector
// whose resize(n) leaves new elements default-initialised (for the
// arithmetic types stored here: not written at all), so an array that is
// filled by parallel workers is first touched by those workers instead of
// being zeroed by one thread first; resize(n, value) still writes `value`.
// On Linux, blocks of at least kMappedBlock bytes are mapped on their own,
// those of kLargeBlock and more marked for transparent huge pages (one page
// fault per 2 MiB instead of per 4 KiB: at 5M points the faults of fresh
// arrays cost more than the sort). Freed ones are kept for the next block of
// the same mapped size, at most kCachedBlocks / kCachedBytes of them
// process-wide: a call's arrays are the next call's. Without it, glibc's
// malloc returned such blocks to the system after each call (its mmap and
// trim thresholds) and the next call faulted them in again: ~4,000 page
// faults and 60 % of a Dragon-vs-res2 call on the CPU backend.
// kLargeBlock is 1 MiB (was 4 MiB): a one-shot call's mid-size arrays (a
// 52,000-triangle BVH's 3.7 MB of corners and 1.5 MB of nodes) were most
// of its build in 4 KiB faults on a VM; huge pages took the CLI's
// armadillo-dec>armadillo from 27.3 to 18.1 ms and Dragon vs res2 from
// 73-75 to 49-67 ms on 2 cores (docs/bench/surfaces, session 9), at the
// cost of up to 1 MiB of rounding per block of 1-4 MiB.
//
// Contract: only for trivially copyable element types whose every element is
// written before it is read. Not under AddressSanitizer: there every block
// comes from operator new so that overflows stay detected.
// Threading: as std::vector; the kept blocks are shared by every thread
// behind a lock that is tried, never waited for.
// Memory: up to kCachedBytes (256 MiB) of freed blocks stay mapped for reuse
// after the arrays that held them are gone.
#pragma once

#include <atomic>
#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/sanitizers.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rthdist::core {

namespace detail {

#if defined(RTHDIST_ASAN)
inline constexpr bool kMapLargeBlocks = false;
#else
inline constexpr bool kMapLargeBlocks = true;
#endif

inline constexpr size_t kMappedBlock = size_t(64) << 10;  // bytes; smaller blocks from operator new
inline constexpr size_t kLargeBlock = size_t(1) << 20;    // and larger: huge pages, whole 2 MiB
inline constexpr size_t kCachedBytes = size_t(256) << 20;
inline constexpr size_t kCachedBlocks = 128;

// The mapped size of a block: whole 64 KiB, or whole 2 MiB for a large one.
[[nodiscard]] inline size_t mappedBytes(size_t bytes) {
    const size_t unit = bytes >= kLargeBlock ? size_t(2) << 20 : kMappedBlock;
    return (bytes + unit - 1) / unit * unit;
}

// The freed mapped blocks kept for reuse. A lock that is busy is never
// waited for (the block is then mapped or unmapped directly): no thread, nor
// a fork() child whose parent held it, can block on it.
class BlockCache {
public:
    // A kept block of exactly `bytes` (a mappedBytes size), or nullptr.
    [[nodiscard]] void* take(size_t bytes) noexcept {
        if (m_busy.exchange(true, std::memory_order_acquire)) return nullptr;
        void* found = nullptr;
        for (size_t i = 0; i < m_count; ++i) {
            if (m_sizes[i] != bytes) continue;
            found = m_blocks[i];
            m_total -= bytes;
            --m_count;
            m_blocks[i] = m_blocks[m_count];
            m_sizes[i] = m_sizes[m_count];
            break;
        }
        m_busy.store(false, std::memory_order_release);
        return found;
    }
    // Keeps the block; false (the caller unmaps it) when full or busy.
    [[nodiscard]] bool keep(void* p, size_t bytes) noexcept {
        if (m_busy.exchange(true, std::memory_order_acquire)) return false;
        const bool room = m_count < kCachedBlocks && m_total + bytes <= kCachedBytes;
        if (room) {
            m_blocks[m_count] = p;
            m_sizes[m_count] = bytes;
            ++m_count;
            m_total += bytes;
        }
        m_busy.store(false, std::memory_order_release);
        return room;
    }

private:
    std::atomic<bool> m_busy{false};
    void* m_blocks[kCachedBlocks] = {};
    size_t m_sizes[kCachedBlocks] = {};
    size_t m_count = 0, m_total = 0;
};

inline BlockCache& blockCache() {
    static BlockCache* const cache = new BlockCache;  // never destroyed: arrays freed at exit still find it
    return *cache;
}

[[nodiscard]] inline void* allocateBlock(size_t bytes) {
#if defined(__linux__)
    if (kMapLargeBlocks && bytes >= kMappedBlock) {
        const size_t mapped = mappedBytes(bytes);
        if (void* kept = blockCache().take(mapped)) return kept;
        void* p = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED) throw std::bad_alloc();
        if (bytes >= kLargeBlock) madvise(p, mapped, MADV_HUGEPAGE);  // a hint: failure only costs speed
        return p;
    }
#endif
    return ::operator new(bytes);
}

inline void freeBlock(void* p, size_t bytes) noexcept {
#if defined(__linux__)
    if (kMapLargeBlocks && bytes >= kMappedBlock) {
        const size_t mapped = mappedBytes(bytes);
        if (!blockCache().keep(p, mapped)) munmap(p, mapped);
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
