#include "cpu/surface_bounds.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "core/stopwatch.hpp"

namespace rthdist::cpu {
namespace {

constexpr uint32_t kNone = UINT32_MAX;
// A patch at depth k has edges of at most 2^-k of its triangle's (plus
// rounding), and tolerance >= 4 slack settles it by the Lipschitz bound
// below depth ~45 (design.md §12); past this depth an invariant broke.
constexpr uint32_t kMaxDepth = 100;

// One point of a `from` surface and its exact distance to the `to` surface.
struct Sample {
    glm::dvec3 p{0.0};
    double d = 0.0;        // |p - closest point of `to`|
    uint32_t nearest = 0;  // the nearest triangle of `to`
    uint32_t owner = 0;    // a triangle of `from` holding p
};

// The corners of a patch: exact dyadic barycentric sub-triangles of one
// triangle of `from`, their points rounded once per level.
struct Patch {
    uint32_t corner[3] = {0, 0, 0};
    uint32_t centroid = kNone;  // the sample at the centroid, once queried
    uint32_t triangle = 0;      // of `from`
    uint32_t depth = 0;
};

struct Direction {
    const MeshView* from = nullptr;
    const MeshView* to = nullptr;
    SampleSearch* search = nullptr;  // over `to`
    // core::thinTriangle of each triangle of `to`, once (the convexity
    // bound measures the rule against them ~10 times a patch).
    std::vector<uint8_t> toThin;
    std::vector<Sample> samples;
    size_t evaluated = 0;  // samples [evaluated, size) still need their query
    std::vector<Patch> work;
    // The sample of the largest exact d (the smallest index on a tie): each
    // batch's proven maximum (SampleSearch), the others' d being upper bounds.
    uint32_t best = kNone;
    double maxSettled = -std::numeric_limits<double>::infinity();  // largest bound of a settled patch
    SurfaceBoundsCounters counters;

    [[nodiscard]] double lower() const { return best == kNone ? 0.0 : samples[best].d; }
};

// Each vertex a triangle of `from` uses, once, as a sample; each triangle a patch.
void seed(Direction& dir) {
    const MeshView& m = *dir.from;
    std::vector<uint32_t> sampleOf(m.vertices.count, kNone);
    dir.work.reserve(m.triangleCount());
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        Patch patch;
        patch.triangle = uint32_t(t);
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = m.indices[3 * t + size_t(k)];
            if (sampleOf[v] == kNone) {
                sampleOf[v] = uint32_t(dir.samples.size());
                dir.samples.push_back(Sample{m.vertices.at(v), 0.0, 0, uint32_t(t)});
            }
            patch.corner[k] = sampleOf[v];
        }
        dir.work.push_back(patch);
    }
}

// The new samples' nearest triangles in one batch (SampleSearch): each
// sample's d an upper bound of its exact distance (exact on the CPU
// backend), the batch's proven maximum a candidate for the lower bound.
std::optional<Error> evaluate(Direction& dir) {
    const size_t begin = dir.evaluated, count = dir.samples.size() - begin;
    if (count == 0) return std::nullopt;
    std::vector<glm::dvec3> points(count);
    std::vector<double> distance(count);
    std::vector<uint32_t> nearest(count);
    for (size_t i = 0; i < count; ++i) points[i] = dir.samples[begin + i].p;
    Result<size_t> top = dir.search->search(points, distance, nearest);
    if (!top) return top.error();
    for (size_t i = 0; i < count; ++i) {
        dir.samples[begin + i].d = distance[i];
        dir.samples[begin + i].nearest = nearest[i];
    }
    dir.counters.queries += count;
    const auto proven = uint32_t(begin + *top);
    if (dir.best == kNone || dir.samples[proven].d > dir.samples[dir.best].d) dir.best = proven;
    dir.evaluated = dir.samples.size();
    return std::nullopt;
}

double distanceTo(const glm::dvec3& p, const Direction& dir, uint32_t t) {
    const MeshView& to = *dir.to;
    return std::sqrt(
        core::closestOnTriangle(p, to.corner(t, 0), to.corner(t, 1), to.corner(t, 2), dir.toThin[t] != 0)
            .distance2);
}

std::vector<uint8_t> thinFlags(const MeshView& mesh, int threads) {
    std::vector<uint8_t> thin(mesh.triangleCount());
    core::parallelChunks(
        thin.size(), core::balancedChunk(thin.size(), threads, 1024), threads,
        [&](size_t begin, size_t end, int) {
            for (size_t t = begin; t < end; ++t)
                thin[t] = core::thinTriangle(mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)) ? 1 : 0;
        });
    return thin;
}

// Convexity (design.md §12): d(., t) is convex, so over the patch (the hull
// of its corners) d <= d(., t) <= the largest d(corner, t), for any t.
double convexBound(const Direction& dir, const Sample* c[3], const Sample* centroid) {
    uint32_t candidates[4] = {c[0]->nearest, c[1]->nearest, c[2]->nearest,
                              centroid ? centroid->nearest : kNone};
    double bound = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 4; ++j) {
        const uint32_t t = candidates[j];
        if (t == kNone || std::find(candidates, candidates + j, t) != candidates + j) continue;
        double worst = 0.0;
        for (int k = 0; k < 3 && worst < bound; ++k)
            worst = std::max(worst, c[k]->nearest == t ? c[k]->d : distanceTo(c[k]->p, dir, t));
        bound = std::min(bound, worst);
    }
    return bound;
}

// 1-Lipschitz (design.md §12): a point of the patch with barycentric weights
// w lies within (1 - max w) <= 2/3 of the longest edge of the corner of
// largest weight; with the centroid c, within max |corner - c| of c.
double lipschitzBound(const Sample* c[3], const Sample* centroid) {
    const double edge = std::max(
        {glm::distance(c[0]->p, c[1]->p), glm::distance(c[1]->p, c[2]->p), glm::distance(c[2]->p, c[0]->p)});
    double bound = std::max({c[0]->d, c[1]->d, c[2]->d}) + edge * (2.0 / 3.0);
    if (centroid != nullptr) {
        const double reach =
            std::max({glm::distance(c[0]->p, centroid->p), glm::distance(c[1]->p, centroid->p),
                      glm::distance(c[2]->p, centroid->p)});
        bound = std::min(bound, centroid->d + reach);
    }
    return bound;
}

double patchBound(const Direction& dir, const Patch& patch) {
    const Sample* c[3] = {&dir.samples[patch.corner[0]], &dir.samples[patch.corner[1]],
                          &dir.samples[patch.corner[2]]};
    const Sample* centroid = patch.centroid == kNone ? nullptr : &dir.samples[patch.centroid];
    return std::min(lipschitzBound(c, centroid), convexBound(dir, c, centroid));
}

std::vector<double> patchBounds(const Direction& dir, int threads) {
    std::vector<double> bounds(dir.work.size());
    core::parallelChunks(dir.work.size(), core::heavyItemChunk(dir.work.size(), threads), threads,
                         [&](size_t lo, size_t hi, int) {
                             for (size_t i = lo; i < hi; ++i) bounds[i] = patchBound(dir, dir.work[i]);
                         });
    return bounds;
}

uint32_t addSample(Direction& dir, const glm::dvec3& p, uint32_t owner) {
    dir.samples.push_back(Sample{p, 0.0, 0, owner});
    return uint32_t(dir.samples.size() - 1);
}

// The midpoint of two samples, shared by the patches split in this round.
uint32_t midpoint(Direction& dir, std::unordered_map<uint64_t, uint32_t>& shared, uint32_t i, uint32_t j,
                  uint32_t owner) {
    const uint64_t key = (uint64_t(std::min(i, j)) << 32) | std::max(i, j);
    const auto [it, inserted] = shared.try_emplace(key, 0);
    if (inserted) it->second = addSample(dir, (dir.samples[i].p + dir.samples[j].p) * 0.5, owner);
    return it->second;
}

void split(Direction& dir, const Patch& p, std::unordered_map<uint64_t, uint32_t>& shared,
           std::vector<Patch>& next) {
    const uint32_t a = p.corner[0], b = p.corner[1], c = p.corner[2];
    const uint32_t ab = midpoint(dir, shared, a, b, p.triangle);
    const uint32_t bc = midpoint(dir, shared, b, c, p.triangle);
    const uint32_t ca = midpoint(dir, shared, c, a, p.triangle);
    const uint32_t children[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
    for (const auto& k : children) next.push_back(Patch{{k[0], k[1], k[2]}, kNone, p.triangle, p.depth + 1});
    ++dir.counters.splits;
    dir.counters.maxDepth = std::max<uint64_t>(dir.counters.maxDepth, p.depth + 1);
}

// One round's decisions: a patch whose bound cannot raise H past the
// threshold is settled; one without its centroid gets it queried first;
// the others split in four.
void refine(Direction& dir, const std::vector<double>& bounds, double threshold) {
    std::vector<Patch> next;
    std::unordered_map<uint64_t, uint32_t> shared;
    for (size_t i = 0; i < dir.work.size(); ++i) {
        Patch p = dir.work[i];
        if (bounds[i] <= threshold) {
            dir.maxSettled = std::max(dir.maxSettled, bounds[i]);
        } else if (p.centroid == kNone) {
            const Sample* c[3] = {&dir.samples[p.corner[0]], &dir.samples[p.corner[1]],
                                  &dir.samples[p.corner[2]]};
            p.centroid = addSample(dir, (c[0]->p + c[1]->p + c[2]->p) / 3.0, p.triangle);
            next.push_back(p);
        } else {
            split(dir, p, shared, next);
        }
    }
    dir.counters.patches += dir.work.size();
    dir.work = std::move(next);
}

// The witness of a direction's lower bound, its closest point and both
// barycentric coordinates, by the rule on the recorded triangles.
void witness(const Direction& dir, double slack, SurfaceBoundsDirected& out) {
    const Sample& s = dir.samples[dir.best];
    const MeshView& from = *dir.from;
    const MeshView& to = *dir.to;
    const core::TriangleClosest onTo = core::closestOnTriangle(
        s.p, to.corner(s.nearest, 0), to.corner(s.nearest, 1), to.corner(s.nearest, 2));
    const core::TriangleClosest onFrom = core::closestOnTriangle(
        s.p, from.corner(s.owner, 0), from.corner(s.owner, 1), from.corner(s.owner, 2));
    out.distance = s.d;
    out.lower = std::max(0.0, s.d - slack);
    out.upper = std::max(dir.maxSettled, s.d) + slack;
    out.fromTriangle = s.owner;
    out.fromPoint = s.p;
    out.fromBarycentric = onFrom.barycentric;
    out.toTriangle = s.nearest;
    out.toPoint = onTo.point;
    out.toBarycentric = onTo.barycentric;
    out.counters = dir.counters;
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

struct Refinement {
    std::vector<Direction> dirs;
    double tolerance = 0.0, slack = 0.0;
    const SurfaceBoundsOptions* options = nullptr;
    size_t roundsRun = 0;

    [[nodiscard]] double lower() const {
        double l = 0.0;
        for (const Direction& d : dirs) l = std::max(l, d.lower());
        return l;
    }
    [[nodiscard]] size_t sampleCount() const {
        size_t n = 0;
        for (const Direction& d : dirs) n += d.samples.size();
        return n;
    }
    [[nodiscard]] bool open() const {
        return std::any_of(dirs.begin(), dirs.end(), [](const Direction& d) { return !d.work.empty(); });
    }
    std::optional<Error> round();
};

Error tooManyQueries(const Refinement& r, double openBound) {
    double upper = openBound;
    for (const Direction& d : r.dirs) upper = std::max(upper, d.maxSettled);
    return Error{ErrorCode::kOutOfMemory,
                 "surface to surface: the tolerance " + number(r.tolerance) + " needs more than " +
                     std::to_string(r.options->maxQueries) +
                     " point-to-surface queries (SurfaceBoundsOptions::maxQueries); bounds reached [" +
                     number(std::max(0.0, r.lower() - r.slack)) + ", " + number(upper + r.slack) + "]"};
}

std::optional<Error> Refinement::round() {
    // Each direction's batch (neither reads the other's); the order turns
    // every round, so that a GPU search meets the same mesh twice in a row
    // at each turn (its device keeps the last mesh's descent tree).
    const bool turn = (roundsRun++ % 2) == 1;
    for (size_t k = 0; k < dirs.size(); ++k) {
        if (std::optional<Error> err = evaluate(dirs[turn ? dirs.size() - 1 - k : k])) return err;
    }
    // Settled: the bound plus its slack cannot pass lower - slack + tolerance.
    const double threshold = lower() + tolerance - 2.0 * slack;
    double openBound = -std::numeric_limits<double>::infinity();
    for (Direction& d : dirs) {
        if (d.work.empty()) continue;
        const std::vector<double> bounds = patchBounds(d, options->threads);
        for (double b : bounds) openBound = std::max(openBound, b);
        refine(d, bounds, threshold);
        ++d.counters.rounds;
        if (d.counters.maxDepth > kMaxDepth)
            return Error{ErrorCode::kInternal, "surface to surface: a patch split past depth " +
                                                   std::to_string(kMaxDepth) +
                                                   " (the tolerance floor broke)"};
    }
    if (sampleCount() > options->maxQueries || sampleCount() >= kNone)
        return tooManyQueries(*this, openBound);
    return std::nullopt;
}

}  // namespace

Result<SurfaceBoundsResult> surfaceBounds(const MeshView& a, const MeshView& b, double tolerance,
                                          double slack, const SurfaceBoundsOptions& options,
                                          SampleSearch& aToB, SampleSearch* bToA) {
    if (!options.directedOnly && bToA == nullptr)
        return Error{ErrorCode::kInternal, "surface to surface: no search for the direction B -> A"};
    Refinement r;
    r.tolerance = tolerance;
    r.slack = slack;
    r.options = &options;
    r.dirs.resize(options.directedOnly ? 1 : 2);
    r.dirs[0].from = &a;
    r.dirs[0].to = &b;
    r.dirs[0].search = &aToB;
    if (!options.directedOnly) {
        r.dirs[1].from = &b;
        r.dirs[1].to = &a;
        r.dirs[1].search = bToA;
    }
    for (Direction& d : r.dirs) {
        seed(d);
        d.toThin = thinFlags(*d.to, options.threads);
    }
    SurfaceBoundsResult result;
    const core::Clock::time_point searchStart = core::Clock::now();
    while (r.open()) {
        if (std::optional<Error> err = r.round()) return *err;
    }
    result.searchMs = core::msSince(searchStart);
    witness(r.dirs[0], slack, result.aToB);
    if (!options.directedOnly) witness(r.dirs[1], slack, result.bToA);
    result.directed = options.directedOnly;
    result.lower = std::max(result.aToB.lower, result.bToA.lower);
    result.upper = std::max(result.aToB.upper, result.bToA.upper);
    result.slack = slack;
    return result;
}

}  // namespace rthdist::cpu
