// The package's masks component (rthdist::masks, rthdist/masks.hpp): two
// cubes in a 10^3 label array, one shifted by two voxels along i, compared
// in every convention on the CPU backend; the Hausdorff distance is 2 for
// each (the shifted faces), in voxel units (spacing 1).
#include <rthdist/masks.hpp>

#include <cstdint>
#include <cstdio>
#include <vector>

namespace masks = rthdist::masks;

static rthdist::Result<masks::Volume> cube(int64_t from, const char* name) {
    std::vector<uint8_t> labels(1000, 0);
    for (int64_t k = 3; k < 7; ++k)
        for (int64_t j = 3; j < 7; ++j)
            for (int64_t i = from; i < from + 4; ++i) labels[size_t(i + 10 * (j + 10 * k))] = 1;
    masks::LabelArray array{labels.data(), {10, 10, 10}, true, "u1"};
    return masks::volumeFromArray(array, glm::dmat4(1.0), name);
}

int main() {
    auto a = cube(2, "a"), b = cube(4, "b");
    rthdist::Options options;
    options.backend = rthdist::Backend::kCpu;
    auto engine = masks::makeMaskEngine(options);
    if (!a || !b || !engine) {
        std::fprintf(stderr, "masks: setup failed\n");
        return 1;
    }
    for (masks::Convention c : masks::kAllConventions) {
        masks::MaskOptions o;
        o.convention = c;
        auto r = masks::compareMasks(*engine, *a, {}, *b, {}, o);
        if (!r || r->hd != 2.0) {
            std::fprintf(stderr, "masks: %s: %s\n", masks::conventionName(c),
                         r ? "H is not 2" : r.error().message.c_str());
            return 1;
        }
        std::printf("masks %s: H = %g (%s)\n", masks::conventionName(c), r->hd, masks::conventionRule(c));
    }
    return 0;
}
