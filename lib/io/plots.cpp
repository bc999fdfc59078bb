#include <homcull/error.hpp>
#include <homcull/io/plots.hpp>

#include "io/legend_font.hpp"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace homcull {
namespace {

std::vector<float> colour(std::uint32_t rgb) {
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
    namespace IBA = OIIO::ImageBufAlgo;
    OIIO::ImageBuf image(OIIO::ImageSpec(plot.width, plot.height, 3, OIIO::TypeDesc::UINT8));
    IBA::fill(image, {1.0f, 1.0f, 1.0f});
    const detail::LegendFont& font = detail::legend_font();
    const std::vector<float> black = {0.0f, 0.0f, 0.0f}, grid = {0.85f, 0.85f, 0.85f};
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
    for (int q = 1; q <= 4; ++q) IBA::render_line(image, left, py(top_value * q / 4), right, py(top_value * q / 4), grid);
    IBA::render_line(image, left, top, left, bottom, black);
    IBA::render_line(image, left, bottom, right, bottom, black);
    for (const PlotSeries& s : plot.series) {
        const std::vector<float> c = colour(s.rgb);
        for (std::size_t k = 1; k < s.values.size(); ++k) {
            if (!std::isfinite(s.values[k - 1]) || !std::isfinite(s.values[k])) continue;
            IBA::render_line(image, px(k - 1), py(s.values[k - 1]), px(k), py(s.values[k]), c);
        }
    }
    if (font.found) {
        IBA::render_text(image, left, 22, plot.title, 16, font.name, black);
        for (int q = 0; q <= 4; ++q) IBA::render_text(image, 4, py(top_value * q / 4) + 5, number(top_value * q / 4), 12, font.name, black);
        IBA::render_text(image, left, bottom + 18, "frame 0", 12, font.name, black);
        IBA::render_text(image, right - 90, bottom + 18, "frame " + std::to_string(frames ? frames - 1 : 0), 12, font.name, black);
        int x = left;
        for (const PlotSeries& s : plot.series) {
            IBA::render_box(image, x, bottom + 28, x + 12, bottom + 38, colour(s.rgb), true);
            IBA::render_text(image, x + 16, bottom + 38, s.name, 12, font.name, black);
            x += 22 + 8 * int(s.name.size());
        }
        IBA::render_text(image, right - 8 * int(plot.y_label.size()), 22, plot.y_label, 12, font.name, black);
    }
    if (!image.write(path)) throw Error(path + ": " + image.geterror());
    return font.found;
}

}  // namespace homcull
