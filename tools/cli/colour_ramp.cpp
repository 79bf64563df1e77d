#include "cli/colour_ramp.hpp"

#include <algorithm>
#include <cmath>

namespace rthdist::cli {

Rgb turbo(double t) {
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
    // Polynomial fit of the Turbo colormap (Apache-2.0 snippet by A. Mikhailov).
    const double r =
        0.13572138 +
        t * (4.61539260 + t * (-42.66032258 + t * (132.13108234 + t * (-152.94239396 + t * 59.28637943))));
    const double g =
        0.09140261 +
        t * (2.19418839 + t * (4.84296658 + t * (-14.18503333 + t * (4.27729857 + t * 2.82956604))));
    const double b =
        0.10667330 +
        t * (12.64194608 + t * (-60.58204836 + t * (110.36276771 + t * (-89.90310912 + t * 27.34824973))));
    auto byte = [](double v) { return uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
    return {byte(r), byte(g), byte(b)};
}

Rgb distanceColour(double distance, const ColourRange& range) {
    if (!(range.hi > range.lo)) return turbo(0.0);
    return turbo((distance - range.lo) / (range.hi - range.lo));
}

}  // namespace rthdist::cli
