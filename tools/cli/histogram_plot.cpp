#include "cli/histogram_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rthdist::cli {
namespace {

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

constexpr Rgb kWhite{255, 255, 255}, kBlack{0, 0, 0}, kGrey{200, 200, 200};
constexpr Rgb kColourA{31, 119, 180}, kColourB{255, 127, 14}, kMarker{214, 39, 40};

}  // namespace

Image plotHistogram(const HausdorffStats& stats, double hausdorff, bool directedOnly,
                    const HistogramLabels& labels) {
    const int width = 1000, height = 560;
    const int left = 90, right = 30, top = 60, bottom = 80;
    Image img(width, height, kWhite);
    const Histogram& ha = stats.aToB.histogram;
    const Histogram& hb = stats.bToA.histogram;
    const size_t bins = ha.counts.size();
    uint64_t peak = 1;
    for (size_t i = 0; i < bins; ++i) {
        peak = std::max(peak, ha.counts[i]);
        if (!directedOnly) peak = std::max(peak, hb.counts[i]);
    }
    const int plotW = width - left - right, plotH = height - top - bottom;
    auto xOf = [&](double d) { return left + (d - ha.lo) / (ha.hi - ha.lo) * plotW; };

    // Grid lines and y ticks.
    for (int k = 0; k <= 4; ++k) {
        const int y = top + plotH - plotH * k / 4;
        img.fillRect(left, y, left + plotW, y + 1, kGrey);
        const std::string label = number(double(peak) * k / 4);
        img.drawText(left - 10 - Image::textWidth(label), y - 6, label, kBlack);
    }
    // Bars.
    const double binW = double(plotW) / double(bins);
    for (size_t i = 0; i < bins; ++i) {
        const int x0 = left + int(std::lround(binW * double(i))) + 1;
        const int x1 = left + int(std::lround(binW * double(i + 1))) - 1;
        const int mid = directedOnly ? x1 : (x0 + x1) / 2;
        const int ya = top + plotH - int(std::lround(double(ha.counts[i]) / double(peak) * plotH));
        img.fillRect(x0, ya, mid, top + plotH, kColourA);
        if (!directedOnly) {
            const int yb = top + plotH - int(std::lround(double(hb.counts[i]) / double(peak) * plotH));
            img.fillRect(mid, yb, x1, top + plotH, kColourB);
        }
    }
    // Axes and x ticks.
    img.fillRect(left, top + plotH, left + plotW, top + plotH + 2, kBlack);
    img.fillRect(left - 2, top, left, top + plotH + 2, kBlack);
    for (int k = 0; k <= 5; ++k) {
        const double d = ha.lo + (ha.hi - ha.lo) * k / 5;
        const int x = int(std::lround(xOf(d)));
        img.fillRect(x, top + plotH, x + 1, top + plotH + 8, kBlack);
        const std::string label = number(d);
        img.drawText(x - Image::textWidth(label) / 2, top + plotH + 12, label, kBlack);
    }
    img.drawText(left + plotW / 2 - Image::textWidth(labels.axis) / 2, height - 36, labels.axis, kBlack);
    img.drawText(10, top - 30, "points", kBlack);

    // Markers: HD95 (symmetric) and H, when inside the range.
    double hd95 = -1;
    const bool hasHd95 = percentileVariant(stats, "max", 95.0, hd95);
    auto marker = [&](double d, const std::string& label, int row) {
        if (d < ha.lo || d > ha.hi) return;
        const int x = int(std::lround(xOf(d)));
        for (int y = top; y < top + plotH; y += 8) img.fillRect(x - 1, y, x + 1, y + 5, kMarker);
        img.drawText(std::min(x + 4, width - right - Image::textWidth(label)), top + 4 + 18 * row, label,
                     kMarker);
    };
    if (hasHd95) marker(hd95, "HD95 " + number(hd95), 0);
    marker(hausdorff, "H " + number(hausdorff), 1);

    // Title and legend.
    img.drawText(left, 14, "Per-point distance histogram", kBlack, 3);
    int lx = width - right - 330;
    img.fillRect(lx, 18, lx + 16, 32, kColourA);
    img.drawText(lx + 22, 19, labels.aToB + " (" + std::to_string(stats.aToB.count) + ")", kBlack);
    if (!directedOnly) {
        lx += 170;
        img.fillRect(lx, 18, lx + 16, 32, kColourB);
        img.drawText(lx + 22, 19, "B->A (" + std::to_string(stats.bToA.count) + ")", kBlack);
    }
    return img;
}

}  // namespace rthdist::cli
