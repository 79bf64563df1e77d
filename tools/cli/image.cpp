#include "cli/image.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "cli/output_file.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_easy_font.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace rthdist::cli {

Image::Image(int width, int height, Rgb background)
    : m_width(width), m_height(height), m_rgb(size_t(width) * size_t(height) * 3) {
    for (size_t i = 0; i < m_rgb.size(); i += 3) {
        m_rgb[i] = background.r;
        m_rgb[i + 1] = background.g;
        m_rgb[i + 2] = background.b;
    }
}

Rgb Image::at(int x, int y) const {
    const size_t i = (size_t(y) * size_t(m_width) + size_t(x)) * 3;
    return {m_rgb[i], m_rgb[i + 1], m_rgb[i + 2]};
}

void Image::set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= m_width || y >= m_height) return;
    const size_t i = (size_t(y) * size_t(m_width) + size_t(x)) * 3;
    m_rgb[i] = c.r;
    m_rgb[i + 1] = c.g;
    m_rgb[i + 2] = c.b;
}

void Image::fillRect(int x0, int y0, int x1, int y1, Rgb c) {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, m_width);
    y1 = std::min(y1, m_height);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) set(x, y, c);
    }
}

void Image::fillDisc(double cx, double cy, double radius, Rgb c) {
    const int x0 = int(std::floor(cx - radius)), x1 = int(std::ceil(cx + radius));
    const int y0 = int(std::floor(cy - radius)), y1 = int(std::ceil(cy + radius));
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
            if (dx * dx + dy * dy <= radius * radius) set(x, y, c);
        }
    }
}

void Image::drawLine(double x0, double y0, double x1, double y1, double thickness, Rgb c) {
    const double length = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, int(std::ceil(length * 2.0)));
    for (int s = 0; s <= steps; ++s) {
        const double t = double(s) / steps;
        fillDisc(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, thickness * 0.5, c);
    }
}

void Image::drawText(int x, int y, const std::string& text, Rgb c, int scale) {
    static char buffer[64000];  // stb_easy_font quads: 4 vertices of 16 bytes
    std::string copy = text;
    unsigned char colour[4] = {c.r, c.g, c.b, 255};
    const int quads = stb_easy_font_print(0, 0, copy.data(), colour, buffer, sizeof buffer);
    for (int q = 0; q < quads; ++q) {
        const float* v = reinterpret_cast<const float*>(buffer + q * 64);
        // Vertices 0 and 2 are opposite corners of an axis-aligned quad.
        const float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];
        fillRect(x + int(std::lround(qx0 * scale)), y + int(std::lround(qy0 * scale)),
                 x + int(std::lround(qx1 * scale)), y + int(std::lround(qy1 * scale)), c);
    }
}

int Image::textWidth(const std::string& text, int scale) {
    std::string copy = text;
    return stb_easy_font_width(copy.data()) * scale;
}

Result<bool> Image::writePng(const std::string& path) const {
    // Encoded in memory, then written through writeOutputFile (temporary
    // file, fsync, rename): stb's own file writer ignores fclose's result.
    std::string png;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
    };
    if (stbi_write_png_to_func(append, &png, m_width, m_height, 3, m_rgb.data(), m_width * 3) == 0) {
        return Error{ErrorCode::kInternal, "cannot write output '" + path + "': PNG encoding failed"};
    }
    return writeOutputFile(path, png);
}

}  // namespace rthdist::cli
