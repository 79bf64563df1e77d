#include "core/search_mutant.hpp"

namespace rthdist::core {

std::atomic<bool>& searchMutant() {
    static std::atomic<bool> mutant{false};
    return mutant;
}

}  // namespace rthdist::core
