// Which voxels of a label volume a LabelSelect picks, read straight from the
// stored labels (no mask is materialized). Internal to rthdist_masks.
#pragma once

#include <cstdint>
#include <limits>

#include "masks/masks.hpp"

namespace rthdist::masks::detail {

// Is voxel i selected: label != 0, or label == value (a value the type cannot
// hold selects nothing).
template <class T>
struct Selected {
    const T* data;
    T value;
    bool any;
    bool none;

    Selected(const T* d, LabelSelect s) : data(d), value(0), any(s.anyNonZero), none(false) {
        if (!any) {
            none = int64_t(s.value) < int64_t(std::numeric_limits<T>::min()) ||
                   int64_t(s.value) > int64_t(std::numeric_limits<T>::max());
            value = none ? T(0) : T(s.value);
        }
    }
    bool operator()(int64_t i) const { return any ? data[i] != 0 : (!none && data[i] == value); }
    // Selected voxels in [begin, end): a loop the compiler vectorizes.
    unsigned countRow(int64_t begin, int64_t end) const {
        unsigned c = 0;
        if (none) return 0;
        if (any) {
            for (int64_t i = begin; i < end; ++i) c += data[i] != 0;
        } else {
            for (int64_t i = begin; i < end; ++i) c += data[i] == value;
        }
        return c;
    }
};

// Calls fn(labels) with the stored array's typed pointer.
template <class Fn>
auto withLabels(const Volume& v, Fn&& fn) {
    if (!v.labels8.empty()) return fn(v.labels8.data());
    return fn(v.labels.data());
}

}  // namespace rthdist::masks::detail
