// homcull bake: the visibility grid of a scene (Zhang's visibility preprocessing) for the
// baked occluder ranking (`--rank baked --grid FILE` on cull, walk and accuracy). A bake can
// be split into shards (--shard i/N, one job each on a cluster) and merged afterwards
// (--merge); docs/scene-culling.md shows Slurm and GNU parallel job arrays.
#include "commands.hpp"
#include "cull_options.hpp"
#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/scene_io.hpp>
#include <homcull/io/visibility_grid_io.hpp>
#include <homcull/truth/visibility_bake.hpp>

#include <fmt/core.h>
#include <tbb/global_control.h>

#include <charconv>
#include <cstdio>
#include <memory>
#include <optional>

namespace homcull::cli {
namespace {

struct BakeCommandOptions {
    SceneChoice scene;
    std::string occluders = "role", layout = "floors", shard = "0/1", out;
    double spacing = 0.0, eye_height = 0.0, complexity = kDefaultComplexity;
    std::uint32_t rays = 4096, keep = 128;
    int threads = 0;
    std::vector<std::string> merge;
    bool quiet = false;
};

GridShard parse_shard(const std::string& text) {
    // Digits only (from_chars takes no sign), both within 32 bits, i < N.
    std::uint32_t index = 0, count = 0;
    const char* end = text.data() + text.size();
    const auto [after_index, e1] = std::from_chars(text.data(), end, index);
    bool ok = e1 == std::errc() && after_index < end && *after_index == '/';
    if (ok) {
        const auto [after_count, e2] = std::from_chars(after_index + 1, end, count);
        ok = e2 == std::errc() && after_count == end && index < count;
    }
    if (!ok) throw Error("--shard must be i/N with 0 <= i < N, got \"" + text + "\"");
    return {index, count};
}

void print_summary(const VisibilityGrid& grid, const std::string& out, double ms) {
    std::size_t listed = 0;
    for (const GridPoint& p : grid.points) listed += p.occluders.size();
    const VisibilityGridHeader& h = grid.header;
    fmt::print("{}: {} points in {} x {} columns of {:.3g} ({}), {:.1f} occluders per point; {:.1f} s\n", out, grid.points.size(),
               h.columns_x, h.columns_z, h.spacing, grid_layout_name(h.layout),
               grid.points.empty() ? 0.0 : double(listed) / double(grid.points.size()), ms / 1000.0);
}

void run_merge(const BakeCommandOptions& o) {
    std::vector<VisibilityGridPart> parts;
    for (const std::string& file : o.merge) parts.push_back(read_visibility_grid_part(file));
    const long long start = now_ns();
    const VisibilityGrid grid = merge_visibility_grid_parts(parts);
    write_visibility_grid(grid, {}, o.out);
    print_summary(grid, o.out, elapsed_ms(start));
}

void run_bake(const BakeCommandOptions& o) {
    if (!o.merge.empty()) {
        if (!o.scene.file.empty()) throw Error("--merge takes the shards' files, not --scene");
        run_merge(o);
        return;
    }
    if (o.scene.file.empty()) throw Error("bake needs --scene (or --merge with the shards' files)");
    std::optional<tbb::global_control> limit;
    if (o.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(o.threads));
    const Scene scene = load_chosen_scene(o.scene);
    BakeOptions b;
    b.candidates = choose_occluders(scene, o.occluders, o.complexity);
    b.candidates_name = o.occluders;
    b.layout = o.layout == "volume" ? GridLayout::volume : GridLayout::floors;
    b.spacing = o.spacing;
    b.eye_height = o.eye_height;
    b.rays = o.rays;
    b.keep = o.keep;
    b.shard = parse_shard(o.shard);
    const long long start = now_ns();
    const RayScene rays(scene);
    const VisibilityGrid grid = bake_visibility_grid(rays, scene, b, [&](std::size_t done, std::size_t total) {
        if (o.quiet || (done != total && done % 16 != 0)) return;
        fmt::print(stderr, "\rbaking column {}/{}", done, total);
        if (done == total) fmt::print(stderr, "\n");
        std::fflush(stderr);
    });
    write_visibility_grid(grid, b.shard, o.out);
    print_summary(grid, o.out, elapsed_ms(start));
}

}  // namespace

void register_bake(CLI::App& app) {
    auto o = std::make_shared<BakeCommandOptions>();
    CLI::App* cmd = app.add_subcommand("bake", "Bake a visibility grid: sample points in free space with the occluders seen from each, "
                                               "ranked by what they hide (for --rank baked)");
    add_scene_option(*cmd, o->scene, /*required=*/false);
    cmd->add_option("--occluders", o->occluders, "Occluder candidates: role, all, or auto (as for cull)")
        ->capture_default_str()->check(CLI::IsMember({"role", "all", "auto"}));
    cmd->add_option("--complexity", o->complexity, "Zhang's complexity filter on the candidates (as for cull); 0: keep all")
        ->capture_default_str()->check(kAtLeastZero);
    cmd->add_option("--layout", o->layout, "floors: points at eye height above each floor (walkthroughs); volume: a 3D lattice of "
                                           "free points (flying cameras)")
        ->capture_default_str()->check(CLI::IsMember({"floors", "volume"}));
    cmd->add_option("--spacing", o->spacing, "Lattice step in scene units (0: the scene's longer horizontal extent / 64)")
        ->capture_default_str()->check(kAtLeastZero);
    cmd->add_option("--eye-height", o->eye_height, "floors: eye above the floor (0: as homcull path's walk)")
        ->capture_default_str()->check(kAtLeastZero);
    cmd->add_option("--rays", o->rays, "Directions cast from each point")->capture_default_str()->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--keep", o->keep, "Occluders kept per point, best first")->capture_default_str()->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--shard", o->shard, "Bake only shard i of N (columns c with c % N == i), e.g. $SLURM_ARRAY_TASK_ID/64")
        ->capture_default_str();
    cmd->add_option("--threads", o->threads, "Threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
    cmd->add_option("--merge", o->merge, "Merge these shard files (every shard of one bake) into --out instead of baking");
    cmd->add_option("--out", o->out, "Output grid file (JSON)")->required();
    cmd->add_flag("--quiet", o->quiet, "No progress on stderr");
    cmd->callback([o] { run_bake(*o); });
}

}  // namespace homcull::cli
