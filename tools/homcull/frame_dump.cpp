#include "frame_dump.hpp"

#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/dumps.hpp>
#include <homcull/io/id_image.hpp>
#include <homcull/truth/answer_overlay.hpp>

#include <fmt/core.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

namespace homcull::cli {

void prepare_dump_folder(const std::string& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir))
        throw Error(dir + ": cannot create the output folder" + (ec ? " (" + ec.message() + ")" : ""));
}

std::vector<std::uint32_t> write_frame_dump(const SceneCuller& culler, const RayScene& rays, const Camera& camera,
                                            const std::vector<OccludeeAnswer>& answers, const std::string& dir,
                                            bool print_to_stderr) {
    std::FILE* to = print_to_stderr ? stderr : stdout;
    prepare_dump_folder(dir);
    // The parts are read once and written twice, so the EXR and the PNGs show the same frame.
    long long start = now_ns();
    const std::vector<DumpPart> parts = dump_parts(culler.buffer(), culler.maps());
    const std::string exr = dir + "/maps.exr";
    write_maps_exr(parts, exr);
    const double exr_ms = elapsed_ms(start);
    start = now_ns();
    const std::vector<ColormapPng> pngs = write_colormap_pngs(parts, dir);
    const double png_ms = elapsed_ms(start);
    start = now_ns();
    const AnswerOverlay overlay = render_answer_overlay(rays, camera, culler.config().display, answers, culler.drawn_occluders());
    const std::string overlay_png = dir + "/overlay.png";
    write_rgb_image(overlay_png, overlay.width, overlay.height, overlay.rgb);
    const AnswerOverlay map = render_answer_map(rays, culler.scene().bounds(), camera, culler.config().display, answers,
                                                culler.drawn_occluders(), overlay.false_culls);
    const std::string map_png = dir + "/overlay_top.png";
    write_rgb_image(map_png, map.width, map.height, map.rgb);
    const double overlay_ms = elapsed_ms(start);

    const OcclusionBuffer& buffer = culler.buffer();
    fmt::print(to, "buffer     {}x{} pixels of {}x{} samples; {} pyramid levels\n", buffer.config().width, buffer.config().height,
               buffer.config().samples, buffer.config().samples, culler.maps().levels());
    fmt::print(to, "wrote      {} ({} parts, {} bytes, {:.0f} ms)\n", exr, parts.size(), std::filesystem::file_size(exr), exr_ms);
    for (const ColormapPng& p : pngs) {
        const std::string range = p.finite ? fmt::format("[{:.5g}, {:.5g}]", p.range_min, p.range_max) : "no finite values";
        fmt::print(to, "wrote      {} ({}x{}, range {}{})\n", p.path, p.width, p.height, range,
                   p.no_occluder ? fmt::format(", {} px no occluder", p.no_occluder) : "");
    }
    fmt::print(to, "wrote      {}/colormaps.json (every PNG's range; {:.0f} ms for the PNGs)\n", dir, png_ms);
    if (!pngs.empty() && !pngs.front().text_drawn) fmt::print(to, "note       legend text not drawn: {}\n", pngs.front().note);
    fmt::print(to, "wrote      {} ({}x{}: occluders drawn blue, kept grey, culled yet seen magenta: {} false-cull pixels, "
                   "{} objects; {:.0f} ms)\n",
               overlay_png, overlay.width, overlay.height, overlay.false_cull_pixels, overlay.false_culls.size(), overlay_ms);
    fmt::print(to, "wrote      {} ({}x{}: the answers from above; also occluded orange, view-culled slate, the frustum yellow)\n",
               map_png, map.width, map.height);
    return overlay.false_culls;
}

}  // namespace homcull::cli
