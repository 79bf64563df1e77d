// Tuning: every knob of the library that is not an option of a call or an
// engine, in one struct, each with the reason it exists. None changes a
// result: each trades one cost against another, or turns a diagnostic on.
// The library reads them from the environment in exactly one place
// (tuningFromEnvironment, src/core/tuning.cpp; README "Tuning" lists the
// variables); an Engine takes EngineOptions::tuning where set, else that.
// Tests and benchmarks set fields. An empty optional keeps the library's
// choice for the device at hand (it differs between GPUs and lavapipe).
// Threading: a plain value; tuningFromEnvironment may run on any thread
// (it only reads the environment).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "rthdist/export.hpp"

namespace rthdist {

struct Tuning {
    // Pairs of at most this many queries x targets take the small-pair scan
    // (one exact compute pass, no index) instead of the RT search; 0: every
    // pair takes the RT path (the GPU oracle tests, so that they test it).
    // RTHDIST_SMALL_PAIR_WORK.
    std::optional<uint64_t> smallPairWork;
    // Search radii recorded per submission at most, 1-16 (fewer: the search's
    // submissions can be counted by tests). RTHDIST_SEARCH_RADII.
    std::optional<uint32_t> searchRadiiPerSubmission;
    // The radius of a far tail of queries grows by its square, not by the
    // growth factor (false: the plain schedule, for tests and benchmarks).
    // RTHDIST_SEARCH_TAIL (0: false).
    std::optional<bool> squaredTailGrowth;
    // The far tail's whole-level scan takes a level of at most this many
    // query x cell pairs after the radii (0: never). RTHDIST_TAIL_SCAN_WORK.
    std::optional<uint64_t> tailScanWork;
    // The same before the first radius (0: never, the default).
    // RTHDIST_TAIL_SCAN_START.
    std::optional<uint64_t> tailScanStartWork;
    // The search's sweep (every open query against every target, no rays)
    // takes over while open queries x targets is at most this (0: never).
    // RTHDIST_SWEEP_WORK.
    std::optional<uint64_t> sweepWork;
    // Point to surface on a GPU backend: the queries the radii leave open
    // are measured exactly on the host (no tree, no second submission)
    // while open queries x triangles is at most this (default 2^19 per
    // host thread); past it they descend the tail's tree on the device (0:
    // always the tree). RTHDIST_SURFACE_HOST_WORK.
    std::optional<uint64_t> surfaceHostWork;
    // Point to surface on a GPU backend: true, every query descends the
    // tail's tree from none in one submission (no radii, no BLAS); false,
    // the radii first; unset, the radii unless the triangles are at most
    // 4,096 (and the queries at most 2^20) or the queries at most 1,024
    // (gpu_algo::descendOnly).
    // RTHDIST_SURFACE_DESCEND=0|1.
    std::optional<bool> surfaceDescend;
    // Point to surface on a GPU backend: the threads that share each query's
    // descent of the tail's tree (rounded down to a power of two, 1 to 32;
    // unset: on a GPU as many as keep about 2^18 threads busy, on a CPU
    // device one; gpu_algo::tailLaneBits).
    // The answer is the same whatever the lanes. RTHDIST_SURFACE_TAIL_LANES.
    std::optional<uint32_t> surfaceTailLanes;
    // Read host arrays in place (VK_EXT_external_memory_host) instead of
    // copying them: off by default, on the H200 pinning cost more than the
    // copy it saves (docs/bench/prepared). RTHDIST_HOST_IMPORT=1.
    bool hostImport = false;
    // A packed float32 pair of at most 2^22 points in all (the device
    // ingest's) takes its boxes on the host, one pass per set, to look for
    // narrowed targets before the device ingests it; else from the ingest's
    // own bounds, whose upload a pair that narrows then throws away. Default:
    // on a CPU device (lavapipe: the ingest is host work as well, about 55 of
    // cluster-1M's 590-650 ms on 2 cores), off on a GPU (where the ingest is
    // cheap and the pass would cost every pair that does not narrow).
    // Larger pairs look from the ingest's bounds whatever this says.
    // RTHDIST_NARROW_HOST_BOUNDS (0: off, else on).
    std::optional<bool> narrowHostBounds;
    // A narrowed pair's calls (its cores, or a direction's core and kept
    // targets, packed float32) take the device ingest, which converts the
    // points on the device; else the host views' route, which reuses the
    // boxes the narrowing took and stages the points from the host. Default:
    // on a GPU (on an H200 the host staging was ~2 of cluster-200k's 5 ms),
    // off on a CPU device (lavapipe: the ingest's pass is host work too,
    // 63 -> 80 ms on that row on 2 cores). RTHDIST_NARROWED_INGEST (0: off,
    // else on).
    std::optional<bool> narrowedIngest;
    // A pair whose strays are their own (kilometres from the other set both
    // ways) runs on its two cores for h alone too, not whole (per-point
    // calls always do). Default: on a GPU backend, whose whole search left
    // such a pair's cluster queries uncut (2M double points beside one km
    // stray a set: 3.0 s -> 66-83 ms on an H200, docs/bench/per_point). Off
    // keeps the whole search (the tail sweep's tests). RTHDIST_CORES_FOR_OWN_STRAYS
    // (0: off, else on).
    std::optional<bool> coresForOwnStrays;
    // Debug names and labels on Vulkan objects and command buffers without
    // validation, for GPU captures (~0.1 ms per prepared set on an H100).
    // RTHDIST_DEBUG_LABELS (set and not 0).
    bool debugLabels = false;
    // One line per submission on stderr (host and device times).
    // RTHDIST_SUBMIT_TRACE (set).
    bool traceSubmits = false;
    // How long the host polls a fence before it sleeps, microseconds
    // (default 2000 on a GPU, 0 on lavapipe, where the polling thread takes a
    // core from the device's own). RTHDIST_FENCE_SPIN_US.
    std::optional<uint32_t> fenceSpinMicros;
    // How long the worker pool's waiting threads poll before they sleep,
    // microseconds (default 200; 0: never). The pool is one per process:
    // the last Engine created with a value sets it. RTHDIST_POOL_SPIN_US.
    std::optional<uint32_t> poolSpinMicros;
    // Where the pipeline cache file goes when EngineOptions::pipelineCacheDir
    // is empty: $RTHDIST_CACHE_DIR, else $XDG_CACHE_HOME/rthdist, else
    // $HOME/.cache/rthdist; empty: no file.
    std::string pipelineCacheDir;
};

// The tuning the environment asks for (the variables named above; unset or
// unparsable ones leave the field empty or false).
[[nodiscard]] RTHDIST_API Tuning tuningFromEnvironment();

}  // namespace rthdist
