// A small RGB raster for the CLI's pictures: pixels, filled rectangles and
// discs, thick lines, text (stb_easy_font's bitmap-free quad font), and PNG
// output through stb_image_write (Debian libstb-dev). Software only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cli/colour_ramp.hpp"
#include "rthdist/result.hpp"

namespace rthdist::cli {

class Image {
public:
    Image(int width, int height, Rgb background);

    [[nodiscard]] int width() const { return m_width; }
    [[nodiscard]] int height() const { return m_height; }
    [[nodiscard]] Rgb at(int x, int y) const;

    void set(int x, int y, Rgb c);                         // ignored outside the image
    void fillRect(int x0, int y0, int x1, int y1, Rgb c);  // [x0, x1) x [y0, y1)
    void fillDisc(double cx, double cy, double radius, Rgb c);
    // Line of `thickness` pixels between two points (discs along the segment).
    void drawLine(double x0, double y0, double x1, double y1, double thickness, Rgb c);
    // Text with its top-left at (x, y); scale 1 = stb_easy_font's ~7 px glyphs.
    void drawText(int x, int y, const std::string& text, Rgb c, int scale = 2);
    [[nodiscard]] static int textWidth(const std::string& text, int scale = 2);

    // Writes an 8-bit RGB PNG through writeOutputFile (cli/output_file.hpp):
    // an Error naming the path and the reason when it cannot.
    [[nodiscard]] Result<bool> writePng(const std::string& path) const;

private:
    int m_width, m_height;
    std::vector<uint8_t> m_rgb;
};

}  // namespace rthdist::cli
