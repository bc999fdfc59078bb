#include <homcull/error.hpp>
#include <homcull/io/id_image.hpp>
#include <homcull/io/plots.hpp>

#include "io/image_backend.hpp"
#include "io/legend_font.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace homcull {
namespace {

std::array<float, 3> colour(std::uint32_t rgb) {
    return {float((rgb >> 16) & 0xFF) / 255.0f, float((rgb >> 8) & 0xFF) / 255.0f, float(rgb & 0xFF) / 255.0f};
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, std::abs(v) >= 1e4 ? "%.0f" : "%.4g", v);
    return text;
}

}  // namespace

bool write_line_plot(const LinePlot& plot, const std::string& path) {
    if (plot.width < 200 || plot.height < 120) throw Error(path + ": a plot needs at least 200 x 120 pixels");
    const detail::ImageBackend& images = detail::image_backend();
    std::vector<std::uint8_t> pixels(std::size_t(plot.width) * std::size_t(plot.height) * 3, 255);  // white
    const detail::RgbCanvas canvas{plot.width, plot.height, pixels.data()};
    const detail::LegendFont& font = detail::legend_font();
    const auto line = [&](int x0, int y0, int x1, int y1, const float* rgb) { images.render_line(canvas, x0, y0, x1, y1, rgb); };
    // Text is drawn only with a font that renders (legend_font), as before without checking.
    std::string ignored;
    const auto text = [&](int x, int y, const std::string& s, int size, const float* rgb) {
        images.render_text(canvas, x, y, s, size, font.name, rgb, false, &ignored);
    };
    const float black[3] = {0.0f, 0.0f, 0.0f}, grid[3] = {0.85f, 0.85f, 0.85f};
    // The plotting area, leaving room for the title, the axis numbers and the legend.
    const int left = 70, right = plot.width - 20, top = 34, bottom = plot.height - 46;
    std::size_t frames = 0;
    double top_value = 0.0;
    for (const PlotSeries& s : plot.series) {
        frames = std::max(frames, s.values.size());
        for (double v : s.values)
            if (std::isfinite(v)) top_value = std::max(top_value, v);
    }
    if (!(top_value > 0.0)) top_value = 1.0;
    const auto px = [&](std::size_t k) { return left + int(std::lround(double(k) * (right - left) / double(std::max<std::size_t>(frames, 2) - 1))); };
    const auto py = [&](double v) { return bottom - int(std::lround(v / top_value * (bottom - top))); };
    // Grid lines at quarters of the range, then the axes.
    for (int q = 1; q <= 4; ++q) line(left, py(top_value * q / 4), right, py(top_value * q / 4), grid);
    line(left, top, left, bottom, black);
    line(left, bottom, right, bottom, black);
    for (const PlotSeries& s : plot.series) {
        const std::array<float, 3> c = colour(s.rgb);
        for (std::size_t k = 1; k < s.values.size(); ++k) {
            if (!std::isfinite(s.values[k - 1]) || !std::isfinite(s.values[k])) continue;
            line(px(k - 1), py(s.values[k - 1]), px(k), py(s.values[k]), c.data());
        }
    }
    if (font.found) {
        text(left, 22, plot.title, 16, black);
        for (int q = 0; q <= 4; ++q) text(4, py(top_value * q / 4) + 5, number(top_value * q / 4), 12, black);
        text(left, bottom + 18, "frame 0", 12, black);
        text(right - 90, bottom + 18, "frame " + std::to_string(frames ? frames - 1 : 0), 12, black);
        int x = left;
        for (const PlotSeries& s : plot.series) {
            images.render_box(canvas, x, bottom + 28, x + 12, bottom + 38, colour(s.rgb).data(), true);
            text(x + 16, bottom + 38, s.name, 12, black);
            x += 22 + 8 * int(s.name.size());
        }
        text(right - 8 * int(plot.y_label.size()), 22, plot.y_label, 12, black);
    }
    write_rgb_image(path, plot.width, plot.height, pixels);
    return font.found;
}

}  // namespace homcull
