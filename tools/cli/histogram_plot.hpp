// --histogram-png: a bar chart of the per-point distance histograms drawn in
// software (cli/image.hpp): A->B and B->A bars side by side in each bin, the
// x axis in distance units with the range's ticks, the y axis in points, and
// vertical markers at HD95 (symmetric) and H.
#pragma once

#include <string>

#include "cli/image.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {

// The legend and the x axis' title; the defaults are the point sets'.
struct HistogramLabels {
    std::string aToB = "A->B";  // the legend of stats.aToB
    std::string axis = "nearest-neighbour distance";
};

[[nodiscard]] Image plotHistogram(const HausdorffStats& stats, double hausdorff, bool directedOnly,
                                  const HistogramLabels& labels = {});

}  // namespace rthdist::cli
