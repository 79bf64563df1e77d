// Session 19, call 7: what the out-of-core partition's two passes cost on a
// host when they do nothing but move memory. A stand-alone probe (not part of
// the library; built ad hoc: g++ -O2 -march=x86-64-v3 -pthread), run on the
// device host with the partition's sizes: 700M points of 12 bytes (the torus
// quarter's both sets), all threads, each on its own contiguous range.
//   read:      every word read (the keys pass's traffic, no cells)
//   cells:     each point's cell on a 32^3 grid, counted per thread (the keys pass)
//   copy-nt:   each point and its index to fresh arrays in input order, whole
//              cache lines with streaming stores (the scatter's traffic, no
//              randomness); once into fresh memory, once again into the same
//   (argument 3: 0 streaming stores of 16 bytes, 1 of 32, 2 ordinary stores)
//   scatter-B/G: each point and its index into B buckets (positions from the
//              counts), each bucket's next G buffered and written as whole
//              lines with streaming stores (the library's scheme: G = 16;
//              larger G: longer runs of lines to each place; B x G at most
//              2^18, the buffers 4 MiB a thread)
// Prints ms per pass.
#include <immintrin.h>
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

namespace {

struct P {
    float x, y, z;
};

double msSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

template <class Fn>
double onThreads(int threads, size_t n, Fn&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] { fn(t, n * size_t(t) / size_t(threads), n * size_t(t + 1) / size_t(threads)); });
    for (std::thread& th : pool) th.join();
    return msSince(t0);
}

__attribute__((always_inline)) inline uint32_t cellOf(const P& p) {
    const auto axis = [](float v) {
        float c = (v + 1.0f) * 16.0f;
        c = c > 0.0f ? c : 0.0f;
        c = c < 31.0f ? c : 31.0f;
        return uint32_t(c);
    };
    return axis(p.x) | axis(p.y) << 5 | axis(p.z) << 10;
}

// How a whole group goes out: 16-byte streaming stores (the library's),
// 32-byte ones (AVX2), or ordinary stores (the line read first).
int g_store = 0;
void stream(void* to, const void* from, size_t bytes) {
    const auto* s = static_cast<const char*>(from);
    if (g_store == 1) {
        auto* d = static_cast<__m256i*>(to);
        for (size_t k = 0; k < bytes / 32; ++k)
            _mm256_stream_si256(d + k, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s + 32 * k)));
        return;
    }
    if (g_store == 3) return;  // nothing written: the loop alone
    if (g_store == 2) {
        std::memcpy(to, from, bytes);
        return;
    }
    auto* d = static_cast<__m128i*>(to);
    for (size_t k = 0; k < bytes / 16; ++k)
        _mm_stream_si128(d + k, _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + 16 * k)));
}

// Huge pages where the kernel gives them on request, as the library's arrays.
void* fresh(size_t bytes) {
    const size_t size = (bytes + (2 << 20) - 1) / (2 << 20) * (2 << 20);
    void* p = std::aligned_alloc(2 << 20, size);
    madvise(p, size, MADV_HUGEPAGE);
    return p;
}

}  // namespace

int main(int argc, char** argv) {
    const size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 700000000;
    const int threads = argc > 2 ? std::atoi(argv[2]) : int(std::thread::hardware_concurrency());
    g_store = argc > 3 ? std::atoi(argv[3]) : 0;
    auto* pts = static_cast<P*>(fresh(n * sizeof(P)));
    onThreads(threads, n, [&](int t, size_t b, size_t e) {
        std::mt19937 rng(uint32_t(t) * 7919u + 1u);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        for (size_t i = b; i < e; ++i) pts[i] = {u(rng), u(rng), u(rng)};
    });
    std::printf("points %zu threads %d stores %s\n", n, threads, g_store == 3 ? "none" :
                g_store == 1 ? "streaming 32 B" : g_store == 2 ? "ordinary" : "streaming 16 B");

    const int rounds = argc > 4 ? std::atoi(argv[4]) : 2;
    for (int round = 0; round < rounds; ++round) {
        std::vector<uint32_t> sums(size_t(threads), 0);
        const auto* words = reinterpret_cast<const uint32_t*>(pts);
        const double read = onThreads(threads, n * 3, [&](int t, size_t b, size_t e) {
            uint32_t s = 0;
            for (size_t i = b; i < e; ++i) s ^= words[i];
            sums[size_t(t)] = s;
        });
        std::vector<std::vector<uint32_t>> counts(size_t(threads), std::vector<uint32_t>(32768, 0));
        const double cells = onThreads(threads, n, [&](int t, size_t b, size_t e) {
            std::vector<uint32_t>& c = counts[size_t(t)];
            for (size_t i = b; i < e; ++i) ++c[cellOf(pts[i])];
        });
        auto* outP = static_cast<P*>(fresh(n * sizeof(P)));
        auto* outI = static_cast<uint32_t*>(fresh(n * sizeof(uint32_t)));
        double copies[2];
        for (double& copy : copies)
            copy = onThreads(threads, n, [&](int, size_t b, size_t e) {
                alignas(64) P bufP[16];
                alignas(64) uint32_t bufI[16];
                size_t i = b;
                for (; i < e && i % 16 != 0; ++i) outP[i] = pts[i], outI[i] = uint32_t(i);
                for (; i + 16 <= e; i += 16) {
                    for (int k = 0; k < 16; ++k) bufP[k] = pts[i + size_t(k)], bufI[k] = uint32_t(i) + uint32_t(k);
                    stream(outP + i, bufP, sizeof(bufP));
                    stream(outI + i, bufI, sizeof(bufI));
                }
                for (; i < e; ++i) outP[i] = pts[i], outI[i] = uint32_t(i);
                _mm_sfence();
            });
        std::printf("round %d: read %.0f ms, cells %.0f ms, copy-nt %.0f ms fresh / %.0f ms again", round, read,
                    cells, copies[0], copies[1]);
        for (const uint32_t buckets : {64u, 256u, 1024u, 4096u})
            for (const uint64_t group : {uint64_t(16), uint64_t(32), uint64_t(64), uint64_t(256)}) {
                if (buckets * group > 262144) continue;  // the buffers past 4 MiB a thread
                // Each thread's first position in each bucket, from per-thread
                // counts of the bucket (bucket = cell & (buckets - 1); buckets are powers of two).
                std::vector<std::vector<uint64_t>> next(size_t(threads), std::vector<uint64_t>(buckets, 0));
                onThreads(threads, n, [&](int t, size_t b, size_t e) {
                    for (size_t i = b; i < e; ++i) ++next[size_t(t)][cellOf(pts[i]) & (buckets - 1)];
                });
                uint64_t at = 0;
                for (uint32_t k = 0; k < buckets; ++k)
                    for (int t = 0; t < threads; ++t) {
                        const uint64_t c = next[size_t(t)][k];
                        next[size_t(t)][k] = at;
                        at += c;
                    }
                const double scatter = onThreads(threads, n, [&](int t, size_t b, size_t e) {
                    std::vector<uint64_t>& pos = next[size_t(t)];
                    const std::vector<uint64_t> first = pos;
                    std::vector<P> bufP(size_t(buckets) * group);
                    std::vector<uint32_t> bufI(size_t(buckets) * group);
                    for (size_t i = b; i < e; ++i) {
                        const uint32_t k = cellOf(pts[i]) & (buckets - 1);
                        const uint64_t to = pos[k]++;
                        bufP[size_t(k) * group + (to & (group - 1))] = pts[i];
                        bufI[size_t(k) * group + (to & (group - 1))] = uint32_t(i);
                        if ((to & (group - 1)) != group - 1) continue;
                        const uint64_t from = std::max(to + 1 - group, first[k]);
                        if (to + 1 - from == group) {
                            stream(outP + from, &bufP[size_t(k) * group], group * sizeof(P));
                            stream(outI + from, &bufI[size_t(k) * group], group * sizeof(uint32_t));
                        } else {
                            for (uint64_t j = from; j <= to; ++j)
                                outP[j] = bufP[size_t(k) * group + (j & (group - 1))],
                                outI[j] = bufI[size_t(k) * group + (j & (group - 1))];
                        }
                    }
                    for (uint32_t k = 0; k < buckets; ++k) {
                        const uint64_t end = pos[k];
                        if ((end & (group - 1)) == 0) continue;
                        for (uint64_t j = std::max((end - 1) / group * group, first[k]); j < end; ++j)
                            outP[j] = bufP[size_t(k) * group + (j & (group - 1))],
                            outI[j] = bufI[size_t(k) * group + (j & (group - 1))];
                    }
                    _mm_sfence();
                });
                std::printf(", scatter-%u/%llu %.0f ms", buckets, (unsigned long long)group, scatter);
            }
        std::printf("\n");
        std::free(outP);
        std::free(outI);
    }
    return 0;
}
