#pragma once
// Line plots as PNG, for walkthrough reports: Zhang's culling graph (triangles per frame in
// total, after frustum culling, after occlusion culling, exactly visible) and the time per
// frame. Drawn with OpenImageIO's ImageBufAlgo (lines, text), so that the project needs no
// plotting library.
#include <cstdint>
#include <string>
#include <vector>

namespace homcull {

struct PlotSeries {
    std::string name;
    std::uint32_t rgb = 0x000000;  // 0xRRGGBB
    std::vector<double> values;    // one per frame; non-finite values leave a gap
};

struct LinePlot {
    std::string title, y_label;  // the x axis is the frame number
    std::vector<PlotSeries> series;
    int width = 960, height = 360;
};

// Writes the plot; the y axis spans 0 to the largest finite value. Throws homcull::Error
// naming the file when it cannot be written, or when the plot is smaller than 200 x 120.
// Returns whether its text could be drawn (see LegendFont: fonts-dejavu-core).
bool write_line_plot(const LinePlot& plot, const std::string& path);

}  // namespace homcull
