// A deliberately broken search, for the certificate's tests only (issue 32):
// while set, the GPU backends' neighbourhood pass skips each query's own cell
// and their refinement drops every third candidate pair, and the CPU
// backend's tree search skips every third bucket, so that queries settle
// with a target that is not their nearest; the GPU backends' surface
// search skips every third triangle (its host proof must still give the
// brute force: api/surface_certify.hpp). The certificate must catch every
// wrong value this makes and the Engine recompute it (api/certify.hpp), whose
// CPU recomputation runs with the mutant paused. Off unless a test sets it;
// one process-wide flag, read when a backend call starts.
#pragma once

#include <atomic>

namespace rthdist::core {

[[nodiscard]] std::atomic<bool>& searchMutant();

// Pauses the mutant for its lifetime (the Engine's recomputation).
class SearchMutantPause {
public:
    SearchMutantPause() : m_was(searchMutant().exchange(false)) {}
    ~SearchMutantPause() { searchMutant().store(m_was); }
    SearchMutantPause(const SearchMutantPause&) = delete;
    SearchMutantPause& operator=(const SearchMutantPause&) = delete;

private:
    bool m_was;
};

}  // namespace rthdist::core
