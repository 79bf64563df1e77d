#include "api/narrowed_targets.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

#include "api/route_planner.hpp"
#include "core/certificate.hpp"
#include "core/packed_float_scan.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"

namespace rthdist::api {
namespace {

// Points a task of the passes below: 2^14 keeps the 16 cores of a GPU
// host busy on a pair of 200k points (2^16 left 12 of them idle).
constexpr size_t kChunk = size_t(1) << 14;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Squared distance from p to the box (0 inside).
double boxDistance2(const glm::dvec3& p, const core::Bounds& box) {
    return core::boxDistance2(p, box.lo, box.hi);
}

// Point i of a view of scalar S (float or double), in double.
template <class S>
glm::dvec3 pointAt(const unsigned char* base, size_t stride, size_t i) {
    S c[3];
    std::memcpy(c, base + i * stride, sizeof(c));
    return {double(c[0]), double(c[1]), double(c[2])};
}

// fn.template operator()<S>() for v's scalar type: the passes below read
// the points in their own type, the branch taken once per pass.
template <class Fn>
void withScalar(const PointView& v, Fn&& fn) {
    if (v.scalar == Scalar::kFloat64)
        fn.template operator()<double>();
    else
        fn.template operator()<float>();
}

bool isFloat(const glm::dvec3& p) { return glm::dvec3(glm::vec3(p)) == p; }

core::Bounds emptyBox() { return core::Bounds{glm::dvec3(kInf), glm::dvec3(-kInf)}; }

// The points of `v` at `indices` (ascending), packed in v's scalar type.
PointSubset listedSubset(const PointView& v, std::vector<uint64_t> indices, int workers) {
    PointSubset out;
    out.listed = std::move(indices);
    const size_t pointBytes = 3 * scalarBytes(v.scalar);
    out.bytes.resize(out.listed.size() * pointBytes);
    core::parallelChunks(out.listed.size(), kChunk, workers, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k)
            std::memcpy(out.bytes.data() + k * pointBytes,
                        static_cast<const unsigned char*>(v.data) + out.listed[k] * v.strideBytes,
                        pointBytes);
    });
    out.view = v.scalar == Scalar::kFloat64
                   ? PointView::doubles(reinterpret_cast<const double*>(out.bytes.data()), out.listed.size())
                   : PointView::floats(reinterpret_cast<const float*>(out.bytes.data()), out.listed.size());
    return out;
}

// Every point of v but the ascending `strays`: a run of v itself when they
// are its first or last points, else a packed copy (runs between strays
// copied in parallel).
PointSubset coreSubset(const PointView& v, const std::vector<uint64_t>& strays, int workers) {
    PointSubset out;
    out.core = true;
    out.shifted.resize(strays.size());
    for (size_t k = 0; k < strays.size(); ++k) out.shifted[k] = strays[k] - k;
    const size_t n = v.count - strays.size();
    size_t first = 0;  // strays before the core
    while (first < strays.size() && strays[first] == first) ++first;
    bool run = true;  // the others are v's last points
    for (size_t k = first; k < strays.size(); ++k) run = run && strays[k] == n + k;
    if (run) {
        out.view = v;
        out.view.data = static_cast<const unsigned char*>(v.data) + first * v.strideBytes;
        out.view.count = n;
        return out;
    }
    const size_t pointBytes = 3 * scalarBytes(v.scalar);
    out.bytes.resize(n * pointBytes);
    const auto* from = static_cast<const unsigned char*>(v.data);
    core::parallelChunks(n, kChunk, workers, [&](size_t begin, size_t end, int) {
        out.forIndices(begin, end, [&](uint64_t p, uint64_t i) {
            std::memcpy(out.bytes.data() + p * pointBytes, from + i * v.strideBytes, pointBytes);
        });
    });
    out.view = v.scalar == Scalar::kFloat64
                   ? PointView::doubles(reinterpret_cast<const double*>(out.bytes.data()), n)
                   : PointView::floats(reinterpret_cast<const float*>(out.bytes.data()), n);
    return out;
}

// d(p, T) in double over every target: the smallest squared distance, as
// core::exactDistance forms it, then its root (the root is monotone).
double nearestDistance(const glm::dvec3& p, const PointView& t, int threads) {
    const int workers = core::resolveThreads(threads, t.count / kChunk + 1);
    std::vector<double> best(size_t(workers), kInf);
    const auto* base = static_cast<const unsigned char*>(t.data);
    withScalar(t, [&]<class S>() {
        core::parallelChunks(t.count, kChunk, workers, [&](size_t begin, size_t end, int w) {
            double m = best[size_t(w)];
            for (size_t i = begin; i < end; ++i) {
                const glm::dvec3 d = p - pointAt<S>(base, t.strideBytes, i);
                m = std::min(m, d.x * d.x + d.y * d.y + d.z * d.z);
            }
            best[size_t(w)] = m;
        });
    });
    return std::sqrt(*std::min_element(best.begin(), best.end()));
}

// The first index of v that is not among the ascending `strays`.
uint64_t firstCoreIndex(const std::vector<uint64_t>& strays) {
    uint64_t i = 0;
    while (i < strays.size() && strays[i] == i) ++i;
    return i;
}

// R for the queries in `box` (q0 one of them): diag(box) + d(q0, T), grown.
double reachRadius(const core::Bounds& box, const glm::dvec3& q0, const PointView& t, int threads) {
    return (glm::length(box.hi - box.lo) + nearestDistance(q0, t, threads)) * (1.0 + 0x1p-30);
}

// A bound on d(q, T) for every q in `box` from a strided sample of about
// `samples` targets: the least, over them, of the farthest point of the box
// from the target, grown. Cheaper than reachRadius (no pass), looser.
double sampledReach(const core::Bounds& box, const PointView& t, size_t samples) {
    const size_t step = std::max<size_t>(1, t.count / samples);
    double best = kInf;
    for (size_t i = 0; i < t.count; i += step) {
        const glm::dvec3 p = t.at(i);
        const glm::dvec3 far = glm::max(glm::abs(p - box.lo), glm::abs(p - box.hi));
        best = std::min(best, glm::dot(far, far));
    }
    return std::sqrt(best) * (1.0 + 0x1p-30);
}

// Float fast path of the kept-target test boxDistance2(p, box) <= r2 for
// float32 points: outside `outer` on an axis fails it, inside `inner`
// passes it; each bound checked in double as the test computes it (its
// rounding is monotone in p), with 2^-40 to spare for a compiler's other
// contraction of the sum, so the kept set is the double test's.
struct FloatReach {
    glm::vec3 outerLo, outerHi, innerLo, innerHi;
};

constexpr float kFloatMax = std::numeric_limits<float>::max();

float roundDown(double x) {
    if (!(x >= -double(kFloatMax))) return -std::numeric_limits<float>::infinity();
    if (x > double(kFloatMax)) return kFloatMax;
    float f = float(x);
    if (double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

float roundUp(double x) {
    if (!(x <= double(kFloatMax))) return std::numeric_limits<float>::infinity();
    if (x < -double(kFloatMax)) return -kFloatMax;
    float f = float(x);
    if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}

FloatReach floatReach(const core::Bounds& box, double radius, double r2) {
    constexpr float kFInf = std::numeric_limits<float>::infinity();
    FloatReach f;
    for (int k = 0; k < 3; ++k) {
        // A float below outerLo is at most the float just below it: its axis
        // distance alone must exceed r (and likewise above outerHi).
        f.outerLo[k] = roundDown(box.lo[k] - radius * (1.0 + 0x1p-20));
        f.outerHi[k] = roundUp(box.hi[k] + radius * (1.0 + 0x1p-20));
        const double below = box.lo[k] - double(std::nextafter(f.outerLo[k], -kFInf));
        const double above = double(std::nextafter(f.outerHi[k], kFInf)) - box.hi[k];
        if (!(below * below > r2 * (1.0 + 0x1p-40))) f.outerLo[k] = -kFInf;
        if (!(above * above > r2 * (1.0 + 0x1p-40))) f.outerHi[k] = kFInf;
        const double in = radius * 0.577;  // below r / sqrt(3)
        f.innerLo[k] = roundUp(box.lo[k] - in);
        f.innerHi[k] = roundDown(box.hi[k] + in);
    }
    // The inner box's farthest corner from `box` passes the test, so does every point in it.
    glm::dvec3 corner;
    for (int k = 0; k < 3; ++k)
        corner[k] = box.lo[k] - double(f.innerLo[k]) > double(f.innerHi[k]) - box.hi[k]
                        ? double(f.innerLo[k])
                        : double(f.innerHi[k]);
    if (!(boxDistance2(corner, box) <= r2 * (1.0 - 0x1p-40))) {  // no point is inside an empty box
        f.innerLo = glm::vec3(kFInf);
        f.innerHi = glm::vec3(-kFInf);
    }
    return f;
}

// The targets within R of the core's box, in input order: their packed copy
// and summary, one pass to select (per chunk), one to copy; nullopt when
// none or every one is kept.
struct Kept {
    PointSubset subset;
    core::SetSummary summary;
};

std::optional<Kept> keepWithin(const PointView& t, const core::Bounds& box, double radius, int workers) {
    const double r2 = radius * radius;
    const size_t chunks = (t.count + kChunk - 1) / kChunk;
    struct Part {
        std::vector<uint64_t> kept;
        core::Bounds box = emptyBox();
        bool floatExact = true;
    };
    std::vector<Part> parts(chunks);
    const auto* base = static_cast<const unsigned char*>(t.data);
    const FloatReach f = floatReach(box, radius, r2);
    withScalar(t, [&]<class S>() {
        core::parallelChunks(t.count, kChunk, workers, [&](size_t begin, size_t end, int) {
            Part& part = parts[begin / kChunk];
            for (size_t i = begin; i < end; ++i) {
                if constexpr (std::is_same_v<S, float>) {
                    float c[3];
                    std::memcpy(c, base + i * t.strideBytes, sizeof(c));
                    const glm::vec3 p(c[0], c[1], c[2]);
                    if (glm::any(glm::lessThan(p, f.outerLo)) || glm::any(glm::greaterThan(p, f.outerHi)))
                        continue;
                    const glm::dvec3 d(p);
                    if (!(glm::all(glm::greaterThanEqual(p, f.innerLo)) &&
                          glm::all(glm::lessThanEqual(p, f.innerHi))) &&
                        !(boxDistance2(d, box) <= r2))
                        continue;
                    part.kept.push_back(i);
                    part.box.lo = glm::min(part.box.lo, d);
                    part.box.hi = glm::max(part.box.hi, d);
                } else {
                    const glm::dvec3 d = pointAt<S>(base, t.strideBytes, i);
                    if (!(boxDistance2(d, box) <= r2)) continue;
                    part.kept.push_back(i);
                    part.box.lo = glm::min(part.box.lo, d);
                    part.box.hi = glm::max(part.box.hi, d);
                    part.floatExact = part.floatExact && isFloat(d);
                }
            }
        });
    });
    size_t total = 0;
    Kept out;
    out.summary.box = emptyBox();
    std::vector<size_t> offset(chunks);
    for (size_t c = 0; c < chunks; ++c) {
        offset[c] = total;
        total += parts[c].kept.size();
        out.summary.box = core::unite(out.summary.box, parts[c].box);
        out.summary.floatExact = out.summary.floatExact && parts[c].floatExact;
    }
    if (total == 0 || total == t.count) return std::nullopt;
    PointSubset& s = out.subset;
    s.listed.resize(total);
    const size_t pointBytes = 3 * scalarBytes(t.scalar);
    s.bytes.resize(total * pointBytes);
    core::parallelChunks(chunks, 1, workers, [&](size_t c, size_t, int) {
        const std::vector<uint64_t>& kept = parts[c].kept;
        std::copy(kept.begin(), kept.end(), s.listed.begin() + ptrdiff_t(offset[c]));
        unsigned char* to = s.bytes.data() + offset[c] * pointBytes;
        for (size_t k = 0; k < kept.size(); ++k)
            std::memcpy(to + k * pointBytes, base + kept[k] * t.strideBytes, pointBytes);
    });
    s.view = t.scalar == Scalar::kFloat64
                 ? PointView::doubles(reinterpret_cast<const double*>(s.bytes.data()), total)
                 : PointView::floats(reinterpret_cast<const float*>(s.bytes.data()), total);
    return out;
}

// A lower bound on d(p, T) from T's split (its core's box and its strays;
// without one, T's box): no pass over T.
double nearestBound(const glm::dvec3& p, const PointView& t, const core::Bounds& tBox,
                    const std::optional<CoreSplit>& tSplit) {
    if (!tSplit) return std::sqrt(boxDistance2(p, tBox));
    double d2 = boxDistance2(p, tSplit->core.box);
    for (uint64_t s : tSplit->strays) {
        const glm::dvec3 d = p - t.at(s);
        d2 = std::min(d2, glm::dot(d, d));
    }
    return std::sqrt(d2) * (1.0 - 0x1p-30);
}

// Whether q's box reaches at least `far` past t's on some axis: q's point on
// that face is then at least `far` from t's box, hence from every target
// (a stray of its own, as straysOfTheirOwn finds, from the boxes alone).
bool reachesPast(const core::Bounds& q, const core::Bounds& t, double far) {
    for (int i = 0; i < 3; ++i)
        if (q.hi[i] - t.hi[i] >= far || t.lo[i] - q.lo[i] >= far) return true;
    return false;
}

// Whether q's strays are of their own: the first one at least `far` (2^-20
// of the pair's magnitude, times 2^kNarrowGainLog2) from every target, by
// nearestBound when that settles it (`exact` false), else by a pass over t.
bool straysOfTheirOwn(const PointView& q, const CoreSplit& split, const PointView& t,
                      const core::Bounds& tBox, const std::optional<CoreSplit>& tSplit, double far,
                      bool exact, int threads) {
    if (split.strays.empty()) return false;
    const glm::dvec3 s = q.at(split.strays.front());
    if (nearestBound(s, t, tBox, tSplit) >= far) return true;
    return exact && nearestDistance(s, t, threads) >= far;
}

// narrowTargets with q's split in hand (and t's, when known); whole and
// floatExact the pair's.
std::optional<NarrowedTargets> narrowWith(const PointView& q, const CoreSplit& split, const PointView& t,
                                          const core::Bounds& tBox, const std::optional<CoreSplit>& tSplit,
                                          double whole, bool floatExact, int threads) {
    if (t.count < 2) return std::nullopt;
    if (double(split.strays.size()) * double(t.count) > double(kMaxApartStrayWork)) return std::nullopt;
    const int workers = core::resolveThreads(threads, std::max(q.count, t.count) / kChunk + 1);
    // A stray query far from every target makes h far larger than the
    // whole pair's slack (2^-20 of its magnitude): the whole search then
    // settles the core's queries at once (they cannot raise h), nothing
    // to gain. Checked before any copy.
    if (straysOfTheirOwn(q, split, t, tBox, tSplit, std::ldexp(whole, kNarrowGainLog2 - 20), true, threads))
        return std::nullopt;
    const core::Bounds& coreBox = split.core.box;
    const double radius = reachRadius(coreBox, q.at(firstCoreIndex(split.strays)), t, threads);
    if (!std::isfinite(radius)) return std::nullopt;
    const core::Bounds reach{glm::max(coreBox.lo - radius, tBox.lo), glm::min(coreBox.hi + radius, tBox.hi)};
    if (!narrowingPays(whole, frameMagnitude(core::unite(coreBox, reach), floatExact))) return std::nullopt;
    std::optional<Kept> kept = keepWithin(t, coreBox, radius, workers);
    if (!kept) return std::nullopt;
    NarrowedTargets out;
    out.radius = radius;
    out.targets = std::move(kept->subset);
    out.targetsSummary = kept->summary;
    out.core = coreSubset(q, split.strays, workers);
    out.strays = listedSubset(q, split.strays, workers);
    out.coreSummary = split.core;
    return out;
}

// Whether every stray of t lies beyond the reach of q's core: farther from
// its box than any core query's nearest target (a bound from a sample of t
// first, d(q0, T) where that does not do).
bool straysBeyondReach(const PointView& q, const CoreSplit& qSplit, const PointView& t,
                       const CoreSplit& tSplit, int threads) {
    if (tSplit.strays.empty()) return true;
    const core::Bounds& box = qSplit.core.box;
    auto beyond = [&](double radius) {
        const double r2 = radius * radius;
        for (uint64_t s : tSplit.strays)
            if (!(boxDistance2(t.at(s), box) > r2)) return false;
        return true;
    };
    return beyond(sampledReach(box, t, 64)) ||
           beyond(reachRadius(box, q.at(firstCoreIndex(qSplit.strays)), t, threads));
}

}  // namespace

uint64_t PointSubset::indexOf(uint64_t position) const {
    if (!core) return listed[position];
    return position + uint64_t(std::upper_bound(shifted.begin(), shifted.end(), position) - shifted.begin());
}

double frameMagnitude(const core::Bounds& box, bool floatExact) {
    const glm::dvec3 origin = floatExact ? glm::dvec3(0.0) : (box.lo + box.hi) * 0.5;
    return core::largestMagnitude(core::Bounds{box.lo - origin, box.hi - origin});
}

Directed strayQueries(const PointSubset& strays, const PointView& t, PerPoint* perPoint, int threads) {
    const size_t n = strays.view.count;
    std::vector<core::BandNearest> nearest(n);
    std::vector<glm::dvec3> q(n);
    for (size_t k = 0; k < n; ++k) {
        nearest[k].query = k;
        q[k] = strays.view.at(k);
    }
    // core::hostBruteForce's answer (core::exactDistance, ties: the smaller
    // target), read in the targets' own type: within a chunk, in index
    // order, a target takes a stray only when its distance is smaller,
    // which needs a smaller squared distance first.
    std::mutex merge;
    const auto* base = static_cast<const unsigned char*>(t.data);
    const int workers = core::resolveThreads(threads, t.count / kChunk + 1);
    withScalar(t, [&]<class S>() {
        core::parallelChunks(t.count, kChunk, workers, [&](size_t begin, size_t end, int) {
            std::vector<core::BandNearest> local(n);
            std::vector<double> best2(n, kInf);
            for (size_t i = begin; i < end; ++i) {
                const glm::dvec3 p = pointAt<S>(base, t.strideBytes, i);
                for (size_t k = 0; k < n; ++k) {
                    const glm::dvec3 d = q[k] - p;
                    const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
                    if (!(d2 < best2[k])) continue;
                    best2[k] = d2;
                    const double r = std::sqrt(d2);
                    if (r < local[k].distance) {
                        local[k].distance = r;
                        local[k].target = i;
                    }
                }
            }
            const std::lock_guard<std::mutex> lock(merge);
            for (size_t k = 0; k < n; ++k) nearest[k].offer(local[k].target, local[k].distance);
        });
    });
    size_t win = 0;  // the largest distance, the smaller position on a tie
    for (size_t k = 1; k < n; ++k)
        if (nearest[k].distance > nearest[win].distance) win = k;
    Directed d;
    d.distance = nearest[win].distance;
    d.queryIndex = win;
    d.targetIndex = nearest[win].target;
    d.queryPoint = q[win];
    d.targetPoint = t.at(d.targetIndex);
    d.counters.queries = n;
    d.certificate.confirmed = true;
    d.certificate.query = d.queryIndex;
    d.certificate.nearest = d.targetIndex;
    d.certificate.distance = d.distance;
    d.certificate.band = n;
    if (perPoint != nullptr) {
        perPoint->nearest.resize(n);
        perPoint->distance.resize(n);
        for (size_t k = 0; k < n; ++k) {
            perPoint->nearest[k] = uint32_t(nearest[k].target);
            perPoint->distance[k] = nearest[k].distance;
        }
    }
    return d;
}

core::Bounds sampledCore(const PointView& q, size_t samples) {
    constexpr size_t kDrop = 8;
    const size_t step = std::max<size_t>(1, q.count / std::max<size_t>(samples, 1));
    std::vector<double> axis[3];
    for (size_t s = 0, first = 0; first < q.count; ++s, first += step) {
        // One point of each stride, at a fixed pseudo-random place in it: a
        // lattice in raster order (a voxel grid's points) sampled at a
        // stride that is a multiple of its row put every sample on one
        // plane, a box of no extent on that axis, and no core split off.
        const size_t i = std::min(q.count - 1, first + size_t((s * 0x9E3779B97F4A7C15ull) >> 40) % step);
        const glm::dvec3 p = q.at(i);
        for (int k = 0; k < 3; ++k) axis[k].push_back(p[k]);
    }
    core::Bounds box;
    for (int k = 0; k < 3; ++k) {
        std::vector<double>& v = axis[k];
        const size_t drop = v.size() > 4 * kDrop ? kDrop : 0;
        std::nth_element(v.begin(), v.begin() + ptrdiff_t(drop), v.end());
        const double lo = v[drop];
        std::nth_element(v.begin(), v.end() - 1 - ptrdiff_t(drop), v.end());
        const double hi = v[v.size() - 1 - drop], grow = hi - lo;
        box.lo[k] = lo - grow;
        box.hi[k] = hi + grow;
    }
    return box;
}

std::optional<CoreSplit> splitCore(const PointView& q, const core::SetSummary& summary, bool frameFloatExact,
                                   double whole, int threads) {
    if (q.count == 0) return std::nullopt;
    if (narrowingPays(whole, frameMagnitude(summary.box, frameFloatExact))) return CoreSplit{summary, {}};
    const core::Bounds sampled = sampledCore(q);
    if (!narrowingPays(whole, frameMagnitude(sampled, frameFloatExact))) return std::nullopt;
    // One pass: the strays (stopped past kMaxStrayQueries), the core's box
    // and whether its coordinates are float32 values.
    const size_t chunks = (q.count + kChunk - 1) / kChunk;
    struct Part {
        std::vector<uint64_t> strays;
        core::Bounds box = emptyBox();
        bool floatExact = true;
    };
    std::vector<Part> parts(chunks);
    std::atomic<size_t> strays{0};
    const auto* base = static_cast<const unsigned char*>(q.data);
    const int workers = core::resolveThreads(threads, chunks);
    // Float32 points are tested against the sampled box rounded outwards
    // and their box taken in float (exact): the same pass in their own type.
    const glm::vec3 lo(roundDown(sampled.lo.x), roundDown(sampled.lo.y), roundDown(sampled.lo.z));
    const glm::vec3 hi(roundUp(sampled.hi.x), roundUp(sampled.hi.y), roundUp(sampled.hi.z));
    withScalar(q, [&]<class S>() {
        using V = glm::vec<3, S>;
        const V boxLo = std::is_same_v<S, float> ? V(lo) : V(sampled.lo);
        const V boxHi = std::is_same_v<S, float> ? V(hi) : V(sampled.hi);
        core::parallelChunks(q.count, kChunk, workers, [&](size_t begin, size_t end, int) {
            if (strays.load(std::memory_order_relaxed) > kMaxStrayQueries) return;
            Part& part = parts[begin / kChunk];
            V coreLo(std::numeric_limits<S>::infinity()), coreHi(-std::numeric_limits<S>::infinity());
            bool floatExact = true;
            // Packed floats four at a time (most chunks hold no stray: their
            // box is then the chunk's); other views, and a chunk with a point
            // outside, point by point.
            bool scanned = false;
            if constexpr (std::is_same_v<S, float>) {
                if (q.strideBytes == 3 * sizeof(float)) {
                    const core::PackedScan scan = core::scanPackedFloats(
                        reinterpret_cast<const float*>(base) + 3 * begin, end - begin, lo, hi);
                    scanned = !scan.outside;
                    if (scanned) {
                        coreLo = scan.box.lo;
                        coreHi = scan.box.hi;
                    }
                }
            }
            for (size_t i = scanned ? end : begin; i < end; ++i) {
                S c[3];
                std::memcpy(c, base + i * q.strideBytes, sizeof(c));
                const V p(c[0], c[1], c[2]);
                if (glm::any(glm::lessThan(p, boxLo)) || glm::any(glm::greaterThan(p, boxHi))) {
                    part.strays.push_back(i);
                    if (part.strays.size() > kMaxStrayQueries) break;
                    continue;
                }
                coreLo = glm::min(coreLo, p);
                coreHi = glm::max(coreHi, p);
                if constexpr (std::is_same_v<S, double>) floatExact = floatExact && isFloat(p);
            }
            part.box = core::Bounds{glm::dvec3(coreLo), glm::dvec3(coreHi)};
            part.floatExact = floatExact;
            strays.fetch_add(part.strays.size(), std::memory_order_relaxed);
        });
    });
    if (strays.load() > kMaxStrayQueries) return std::nullopt;
    CoreSplit out;
    out.core.box = emptyBox();
    for (const Part& part : parts) {
        out.strays.insert(out.strays.end(), part.strays.begin(), part.strays.end());
        out.core.box = core::unite(out.core.box, part.box);
        out.core.floatExact = out.core.floatExact && part.floatExact;
    }
    if (out.strays.empty() || out.strays.size() == q.count) return std::nullopt;
    return out;
}

std::optional<NarrowedTargets> narrowTargets(const PointView& q, const core::Bounds& qBox, bool qFloatExact,
                                             const PointView& t, const core::Bounds& tBox, bool tFloatExact,
                                             int threads, const std::optional<CoreSplit>* split) {
    if (q.count == 0 || t.count < 2) return std::nullopt;
    const bool floatExact = qFloatExact && tFloatExact;
    const double whole = frameMagnitude(core::unite(qBox, tBox), floatExact);
    const std::optional<CoreSplit> own =
        split != nullptr ? *split
                         : splitCore(q, core::SetSummary{qBox, qFloatExact}, floatExact, whole, threads);
    if (!own) return std::nullopt;
    return narrowWith(q, *own, t, tBox, std::nullopt, whole, floatExact, threads);
}

std::optional<PairNarrowing> narrowPair(const PointView& a, const core::SetSummary& sa, const PointView& b,
                                        const core::SetSummary& sb, bool directedOnly, int threads,
                                        bool ownStrays) {
    if (a.count == 0 || b.count == 0) return std::nullopt;
    const bool floatExact = sa.floatExact && sb.floatExact;
    const double whole = frameMagnitude(core::unite(sa.box, sb.box), floatExact);
    // Strays of their own in every direction computed: h is far above the
    // slack, the whole search settles the cores at once (as narrowTargets
    // finds). From the boxes first: a set whose box reaches `far` past the
    // other's needs no pass to know it (the look cost 0.1-0.2 s of two
    // passes over 2 x 100M points whose strays lie kilometres apart).
    const double far = std::ldexp(whole, kNarrowGainLog2 - 20);
    // (`ownStrays`: the cores are looked for whatever the strays.)
    if (!ownStrays && reachesPast(sa.box, sb.box, far) && (directedOnly || reachesPast(sb.box, sa.box, far)))
        return std::nullopt;
    const std::optional<CoreSplit> splitA = splitCore(a, sa, floatExact, whole, threads);
    if (!splitA && directedOnly) return std::nullopt;
    const std::optional<CoreSplit> splitB = splitCore(b, sb, floatExact, whole, threads);
    if (!splitA && !splitB) return std::nullopt;
    // Then from the splits: each set's first stray against the other's.
    const bool ownA = !splitA || straysOfTheirOwn(a, *splitA, b, sb.box, splitB, far, false, threads);
    const bool ownB = !splitB || straysOfTheirOwn(b, *splitB, a, sa.box, splitA, far, false, threads);
    const bool own = ownA && (directedOnly || ownB);
    if (own && !ownStrays) return std::nullopt;
    PairNarrowing out;
    const int workers = core::resolveThreads(threads, std::max(a.count, b.count) / kChunk + 1);
    const double strayWork =
        double(splitA ? splitA->strays.size() : 0) * double(b.count) +
        (directedOnly || !splitB ? 0.0 : double(splitB->strays.size()) * double(a.count));
    if (splitA && splitB && (!splitA->strays.empty() || !splitB->strays.empty()) &&
        strayWork <= double(kMaxJointStrayWork) &&
        narrowingPays(whole, frameMagnitude(core::unite(splitA->core.box, splitB->core.box), floatExact)) &&
        straysBeyondReach(a, *splitA, b, *splitB, threads) &&
        (directedOnly || straysBeyondReach(b, *splitB, a, *splitA, threads))) {
        JointCores& j = out.joint.emplace();
        j.coreA = coreSubset(a, splitA->strays, workers);
        j.coreB = coreSubset(b, splitB->strays, workers);
        j.straysA = listedSubset(a, splitA->strays, workers);
        j.straysB = listedSubset(b, splitB->strays, workers);
        j.summaryA = splitA->core;
        j.summaryB = splitB->core;
        return out;
    }
    if (own) return std::nullopt;
    if (splitA && !ownA) out.targetsB = narrowWith(a, *splitA, b, sb.box, splitB, whole, floatExact, threads);
    if (splitB && !ownB && !directedOnly)
        out.targetsA = narrowWith(b, *splitB, a, sa.box, splitA, whole, floatExact, threads);
    if (!out.targetsA && !out.targetsB) return std::nullopt;
    return out;
}

}  // namespace rthdist::api
