// homcull accuracy: false and missed culls of the occlusion buffer on workload S1's 1M
// rectangles, against an exact double-precision depth at the same sample centres.
#include "commands.hpp"
#include "options.hpp"

#include <homcull/io/workload_s1.hpp>
#include <homcull/occlusion_buffer.hpp>
#include <homcull/truth/exact_depth.hpp>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <memory>

namespace homcull::cli {

void register_accuracy(CLI::App& app) {
    struct Options {
        std::string resolution = "1920x1080", s1_folder = "../shared/workloads/s1";
        int samples = 1;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("accuracy", "False and missed culls on workload S1's rectangles against exact depth");
    cmd->add_option("--resolution", o->resolution, "Occlusion buffer resolution WxH (pixels)")->capture_default_str();
    cmd->add_option("--samples", o->samples, "S x S samples per pixel (1, 2 or 4)")->capture_default_str();
    cmd->add_option("--s1", o->s1_folder, "Folder of workload S1")->capture_default_str();
    cmd->add_flag("--json", o->json, "Print JSON on stdout");
    cmd->callback([o] {
        const Resolution res = parse_resolution(o->resolution);
        const WorkloadS1 s1 = load_workload_s1(o->s1_folder);
        BufferConfig config;
        config.width = res.width;
        config.height = res.height;
        config.samples = o->samples;
        config.near_w = 1.0f;
        OcclusionBuffer buffer(config);
        buffer.render(s1.occluder_input());
        const long long start = now_ns();
        const ExactDepth exact = exact_depth_of_triangles(s1.occluders.data(), s1.occluder_count(), buffer.sample_width(),
                                                          buffer.sample_height(), /*cull_clockwise=*/true);
        const double exact_ms = elapsed_ms(start);
        const RectAccuracy a = count_rect_accuracy(buffer, exact, s1.rects.data(), s1.rect_count());
        const std::size_t hidden = a.truly_hidden, culled = a.culled, false_culls = a.false_culls, missed = a.missed_culls;
        const double missed_share = hidden ? double(missed) / double(hidden) : 0.0;
        if (o->json) {
            fmt::print("{}\n", nlohmann::json{{"resolution", {res.width, res.height}}, {"samples", o->samples},
                                              {"rects", s1.rect_count()}, {"truly_hidden", hidden}, {"culled", culled},
                                              {"false_culls", false_culls}, {"missed_culls", missed},
                                              {"missed_share_of_hidden", missed_share}, {"exact_ms", exact_ms}}.dump(1));
            return;
        }
        fmt::print("S1 at {}x{}, {}x{} samples: {} of {} rectangles truly hidden; culled {}; false culls {}; missed {} ({:.2f} % of hidden)\n",
                   res.width, res.height, o->samples, o->samples, hidden, s1.rect_count(), culled, false_culls, missed,
                   100.0 * missed_share);
    });
}

}  // namespace homcull::cli
