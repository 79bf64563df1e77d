// The one place the library reads the environment (include/rthdist/tuning.hpp).
#include "rthdist/tuning.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string_view>

namespace rthdist {
namespace {

std::optional<uint64_t> number(const char* name) {
    const char* v = std::getenv(name);
    if (v == nullptr || *v == '\0') return std::nullopt;
    char* end = nullptr;
    errno = 0;
    const unsigned long long n = std::strtoull(v, &end, 10);
    if (errno != 0 || *end != '\0' || *v == '-') return std::nullopt;
    return uint64_t(n);
}

std::optional<uint32_t> number32(const char* name) {
    const std::optional<uint64_t> n = number(name);
    if (!n) return std::nullopt;
    return uint32_t(std::min<uint64_t>(*n, UINT32_MAX));
}

std::string text(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr ? std::string(v) : std::string();
}

}  // namespace

Tuning tuningFromEnvironment() {
    Tuning t;
    t.smallPairWork = number("RTHDIST_SMALL_PAIR_WORK");
    t.searchRadiiPerSubmission = number32("RTHDIST_SEARCH_RADII");
    if (const char* v = std::getenv("RTHDIST_SEARCH_TAIL")) t.squaredTailGrowth = std::string_view(v) != "0";
    t.tailScanWork = number("RTHDIST_TAIL_SCAN_WORK");
    t.tailScanStartWork = number("RTHDIST_TAIL_SCAN_START");
    t.sweepWork = number("RTHDIST_SWEEP_WORK");
    t.surfaceHostWork = number("RTHDIST_SURFACE_HOST_WORK");
    if (const char* v = std::getenv("RTHDIST_SURFACE_DESCEND")) t.surfaceDescend = std::string_view(v) != "0";
    t.surfaceTailLanes = number32("RTHDIST_SURFACE_TAIL_LANES");
    t.hostImport = text("RTHDIST_HOST_IMPORT") == "1";
    if (const char* v = std::getenv("RTHDIST_NARROW_HOST_BOUNDS"))
        t.narrowHostBounds = std::string_view(v) != "0";
    if (const char* v = std::getenv("RTHDIST_NARROWED_INGEST")) t.narrowedIngest = std::string_view(v) != "0";
    if (const char* v = std::getenv("RTHDIST_CORES_FOR_OWN_STRAYS"))
        t.coresForOwnStrays = std::string_view(v) != "0";
    const std::string labels = text("RTHDIST_DEBUG_LABELS");
    t.debugLabels = !labels.empty() && labels != "0";
    t.traceSubmits = std::getenv("RTHDIST_SUBMIT_TRACE") != nullptr;
    t.fenceSpinMicros = number32("RTHDIST_FENCE_SPIN_US");
    t.poolSpinMicros = number32("RTHDIST_POOL_SPIN_US");
    if (const std::string d = text("RTHDIST_CACHE_DIR"); !d.empty())
        t.pipelineCacheDir = d;
    else if (const std::string x = text("XDG_CACHE_HOME"); !x.empty())
        t.pipelineCacheDir = x + "/rthdist";
    else if (const std::string h = text("HOME"); !h.empty())
        t.pipelineCacheDir = h + "/.cache/rthdist";
    return t;
}

}  // namespace rthdist
