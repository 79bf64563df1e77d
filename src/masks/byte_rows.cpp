// Row packing of 8-bit labels (byte_rows.hpp).
#include "masks/byte_rows.hpp"

#include <algorithm>
#include <bit>

#if defined(__x86_64__)
#include <immintrin.h>
#define RTHDIST_BYTE_ROWS_AVX2 1
#endif

namespace rthdist::masks::detail {

uint64_t byteWord(const uint8_t* labels, int64_t n, ByteSelect s) {
#if defined(__SSE2__)
    if (n == 64) {
        const __m128i key = _mm_set1_epi8(static_cast<char>(s.key));
        uint64_t bits = 0;
        for (int k = 0; k < 4; ++k) {
            const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(labels + 16 * k));
            bits |= uint64_t(uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(v, key)))) << (16 * k);
        }
        return s.any ? ~bits : bits;
    }
#endif
    uint64_t bits = 0;
    for (int64_t i = 0; i < n; ++i) bits |= uint64_t(s.any ? labels[i] != 0 : labels[i] == s.key) << i;
    return bits;
}

namespace {

#if defined(RTHDIST_BYTE_ROWS_AVX2)
__attribute__((target("avx2,popcnt"))) uint64_t packAvx2(const uint8_t* labels, int64_t nx, ByteSelect s,
                                                         uint64_t* words) {
    const __m256i key = _mm256_set1_epi8(static_cast<char>(s.key));
    const uint64_t flip = s.any ? ~uint64_t(0) : 0;
    uint64_t count = 0;
    int64_t x = 0;
    for (; x + 64 <= nx; x += 64) {
        const __m256i lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(labels + x));
        const __m256i hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(labels + x + 32));
        const uint64_t w = (uint64_t(uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(lo, key)))) |
                            uint64_t(uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(hi, key)))) << 32) ^
                           flip;
        *words++ = w;
        count += uint64_t(_mm_popcnt_u64(w));
    }
    if (x < nx) {
        const uint64_t w = byteWord(labels + x, nx - x, s);
        *words = w;
        count += uint64_t(_mm_popcnt_u64(w));
    }
    return count;
}
#endif

bool detectAvx2() {
#if defined(RTHDIST_BYTE_ROWS_AVX2)
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
#else
    return false;
#endif
}

}  // namespace

uint64_t packByteRowPortable(const uint8_t* labels, int64_t nx, ByteSelect select, uint64_t* words) {
    uint64_t count = 0;
    for (int64_t x = 0; x < nx; x += 64) {
        const uint64_t w = byteWord(labels + x, std::min<int64_t>(64, nx - x), select);
        *words++ = w;
        // std::popcount is a library call on the baseline x86-64 target; most words are 0.
        if (w != 0) count += uint64_t(std::popcount(w));
    }
    return count;
}

bool packByteRowUsesAvx2() {
    static const bool avx2 = detectAvx2();
    return avx2;
}

uint64_t packByteRow(const uint8_t* labels, int64_t nx, ByteSelect select, uint64_t* words) {
#if defined(RTHDIST_BYTE_ROWS_AVX2)
    if (packByteRowUsesAvx2()) return packAvx2(labels, nx, select, words);
#endif
    return packByteRowPortable(labels, nx, select, words);
}

}  // namespace rthdist::masks::detail
