// The search mutant (core::searchMutant) on for a scope and off after it,
// also when the scope is left early (an assertion): for the tests that
// check a wrong search is caught (the certificate, the surface proof).
#pragma once

#include "core/search_mutant.hpp"

namespace rthdist::test {

class ScopedSearchMutant {
public:
    ScopedSearchMutant() { core::searchMutant() = true; }
    ~ScopedSearchMutant() { core::searchMutant() = false; }
    ScopedSearchMutant(const ScopedSearchMutant&) = delete;
    ScopedSearchMutant& operator=(const ScopedSearchMutant&) = delete;
};

}  // namespace rthdist::test
