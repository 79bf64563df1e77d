// Distance -> colour for every output that shows distances (PLY, pictures).
//
// The ramp is Turbo (Mikhailov 2019, Google AI blog "Turbo, an improved
// rainbow colormap"), evaluated with its published 6th-degree polynomial fit:
// dark blue = the range's low end (near), through green and yellow, to dark
// red = the high end (far). Values outside the range are clamped to its ends,
// like Metro's -C min max.
#pragma once

#include <cstdint>

namespace rthdist::cli {

struct Rgb {
    uint8_t r = 0, g = 0, b = 0;
};

// Colour range [lo, hi]; hi <= lo maps everything to the low colour.
struct ColourRange {
    double lo = 0.0;
    double hi = 1.0;
};

// t in [0, 1] (clamped).
[[nodiscard]] Rgb turbo(double t);

[[nodiscard]] Rgb distanceColour(double distance, const ColourRange& range);

}  // namespace rthdist::cli
