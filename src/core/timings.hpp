// Summing the stage timings of several backend calls (out-of-core pieces,
// the masks' calls): every stage field of Timings, wall and device time.
// `setup` and `total` are left to the caller (a sum of calls' totals is not
// always the whole's).
#pragma once

#include "rthdist/rthdist.hpp"

namespace rthdist::core {

inline void addStageTimings(Timings& into, const Timings& t) {
    into.upload += t.upload;
    into.index += t.index;
    into.cull += t.cull;
    into.search += t.search;
    into.refine += t.refine;
    into.check += t.check;
    into.gpuIndex += t.gpuIndex;
    into.gpuCull += t.gpuCull;
    into.gpuSearch += t.gpuSearch;
    into.gpuRefine += t.gpuRefine;
    into.gpuUpload += t.gpuUpload;
    into.certificate += t.certificate;
    into.gpuCertificate += t.gpuCertificate;
}

}  // namespace rthdist::core
