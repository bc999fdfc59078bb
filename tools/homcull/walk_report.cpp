#include "walk_report.hpp"

#include <homcull/error.hpp>
#include <homcull/io/plots.hpp>
#include <homcull/io/write_file.hpp>

#include <fmt/core.h>

#include <filesystem>
#include <fstream>

namespace homcull::cli {
namespace {

// Text for HTML: the five characters that matter escaped.
std::string escape(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

template <class Get>
std::vector<double> per_frame(const std::vector<WalkFrame>& frames, Get get) {
    std::vector<double> v;
    for (const WalkFrame& f : frames) v.push_back(get(f));
    return v;
}

}  // namespace

std::vector<std::string> write_walk_report(const std::string& dir, const std::string& title,
                                           const std::vector<std::pair<std::string, std::string>>& settings,
                                           const std::vector<WalkFrame>& frames, const nlohmann::json& summary,
                                           const std::string& frame_dump) {
    const bool truth = !frames.empty() && frames.front().has_truth;
    const double nan = std::nan("");
    LinePlot triangles{"Culling graph: triangles per frame (Zhang)", "triangles", {}, 960, 360};
    triangles.series = {
        {"in total", 0x808080, per_frame(frames, [](const WalkFrame& f) { return double(f.triangles.total); })},
        {"after frustum culling", 0x1f77b4, per_frame(frames, [](const WalkFrame& f) { return double(f.triangles.after_frustum); })},
        {"after occlusion culling", 0xd62728, per_frame(frames, [](const WalkFrame& f) { return double(f.triangles.after_occlusion); })},
        {"exactly visible", 0x2ca02c,
         per_frame(frames, [&](const WalkFrame& f) { return truth ? double(f.triangles.exactly_visible) : nan; })}};
    LinePlot objects{"Culling graph: objects per frame", "objects", {}, 960, 360};
    objects.series = {
        {"after frustum culling", 0x1f77b4, per_frame(frames, [](const WalkFrame& f) { return double(f.objects.after_frustum); })},
        {"after occlusion culling", 0xd62728, per_frame(frames, [](const WalkFrame& f) { return double(f.objects.after_occlusion); })},
        {"exactly visible", 0x2ca02c,
         per_frame(frames, [&](const WalkFrame& f) { return truth ? double(f.objects.exactly_visible) : nan; })},
        {"false culls", 0xff00ff, per_frame(frames, [&](const WalkFrame& f) { return truth ? double(f.truth.false_culls) : nan; })}};
    LinePlot times{"Time per frame", "ms", {}, 960, 360};
    times.series = {
        {"select", 0x9467bd, per_frame(frames, [](const WalkFrame& f) { return f.ms.select_ms; })},
        {"render", 0x1f77b4, per_frame(frames, [](const WalkFrame& f) { return f.ms.render_ms; })},
        {"maps", 0xff7f0e, per_frame(frames, [](const WalkFrame& f) { return f.ms.maps_ms; })},
        {"tests", 0x2ca02c, per_frame(frames, [](const WalkFrame& f) { return f.ms.test_ms; })},
        {"cull total", 0x000000,
         per_frame(frames, [](const WalkFrame& f) { return f.ms.select_ms + f.ms.render_ms + f.ms.maps_ms + f.ms.test_ms; })}};
    std::vector<std::string> written;
    for (const auto& [plot, file] : {std::pair{&triangles, "culling_graph.png"}, {&objects, "objects_graph.png"}, {&times, "frame_ms.png"}}) {
        write_line_plot(*plot, dir + "/" + file);
        written.push_back(dir + "/" + file);
    }

    std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + escape(title) +
                       "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1100px}"
                       "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}"
                       "td:first-child,th:first-child{text-align:left}img{max-width:100%;border:1px solid #ddd}"
                       ".parts img{width:32%}</style></head><body>\n<h1>" + escape(title) + "</h1>\n<table>\n";
    for (const auto& [name, value] : settings) html += "<tr><td>" + escape(name) + "</td><td>" + escape(value) + "</td></tr>\n";
    html += "</table>\n<h2>Culling graph</h2>\n<img src=\"culling_graph.png\" alt=\"triangles per frame\">\n"
            "<img src=\"objects_graph.png\" alt=\"objects per frame\">\n<h2>Time per frame</h2>\n"
            "<img src=\"frame_ms.png\" alt=\"milliseconds per frame\">\n<h2>Summary</h2>\n<table>\n"
            "<tr><th>figure</th><th>mean</th><th>max</th></tr>\n";
    for (const auto& [name, value] : summary.items()) {
        if (value.is_object() && value.contains("mean"))
            html += fmt::format("<tr><td>{}</td><td>{:.3f}</td><td>{:.3f}</td></tr>\n", escape(name), value["mean"].get<double>(),
                                value["max"].get<double>());
        else if (value.is_number())
            html += fmt::format("<tr><td>{}</td><td colspan=\"2\">{}</td></tr>\n", escape(name), value.dump());
    }
    html += "</table>\n";
    if (!frame_dump.empty()) {
        const std::string d = escape(frame_dump);
        html += "<h2>First frame</h2>\n<p>The scene from the eye, coloured by the answers: occluders drawn in blue, kept "
                "objects in grey, false culls in magenta. Below, the occlusion buffer and the finest pyramid levels (every "
                "level is a part of <a href=\"" + d + "/maps.exr\">maps.exr</a>).</p>\n<img src=\"" + d +
                "/overlay.png\" alt=\"answer overlay\">\n<div class=\"parts\">\n";
        for (const char* part : {"buffer.coverage", "buffer.depth", "opacity.L0", "maxz.L0", "nbz.L0", "opacity.L3"})
            if (std::filesystem::exists(dir + "/" + frame_dump + "/" + part + ".png"))
                html += "<img src=\"" + d + "/" + part + ".png\" alt=\"" + part + "\">\n";
        html += "</div>\n";
    }
    // A self-check a headless browser can read back (--dump-dom): how many images loaded.
    html += "<p id=\"image-check\">images not checked yet</p>\n"
            "<script>window.addEventListener('load', function () {\n"
            "  var images = Array.from(document.images);\n"
            "  var loaded = images.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length;\n"
            "  document.getElementById('image-check').textContent = loaded + ' of ' + images.length + ' images loaded';\n"
            "});</script>\n";
    html += "</body></html>\n";
    const std::string page = dir + "/report.html";
    write_file(page, html, "the report");
    written.push_back(page);
    return written;
}

}  // namespace homcull::cli
