#pragma once
// The culling options `cull` and `accuracy` share: display, buffer, mode, depth test,
// occluder choice.
#include <homcull/scene.hpp>
#include <homcull/scene_culler.hpp>

#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

namespace homcull::cli {

// --complexity F: Zhang's complexity filter on the candidates (filter_by_complexity). The
// default drops what is 256 times denser than the median candidate: on the shared scenes only
// FZK-Haus's densest objects, a third of its occluder triangles, with no object less culled on its
// walk or from random views (docs/scene-culling.md, "Occluder selection"); 128 culls 0.5 points
// less there.
constexpr double kDefaultComplexity = 256.0;
struct CullOptions {
    std::string resolution = "1280x720", buffer, mode = "conservative", depth = "masked", occluders = "role";
    int samples = 0;  // 0: automatic_samples (scene_culler.hpp)
    double hole = 0.0, distribution = 1.0, transparency = 0.0;
    int finest_level = 0, coarsest_level = -1;
    int occludee_parts = 16;
    std::string deb = "64x64", occludees = "auto", sample_depth = "on", clusters = "on", closed_back_faces = "skip", back_faces = "draw",
                pyramid = "lazy", merge_coplanar = "on";
    std::string strategy = "temporal", rank = "none", hierarchy = "on", grid, lod = "off";
    std::size_t budget = 0, batch = 1024;
    double cut_step = TemporalCut{}.step_in_near_planes, cut_turn = TemporalCut{}.turn_degrees;
    double complexity = kDefaultComplexity;
    double min_occluder_size = 0.0;  // square radians (OccluderBudget::min_projected_size)
};

// with_display: also --resolution and --samples (commands that define their own leave them out
// and fill CullOptions::resolution and samples themselves).
void add_cull_options(CLI::App& app, CullOptions& options, bool with_display = true);
// Throws homcull::Error on inconsistent options (a hole size in conservative mode, ...).
// `threads`: the command's --threads; with one, the culler reserves no room for a job system's
// draws (SceneCullerConfig::job_system), as an engine culling on its own thread would say.
SceneCullerConfig scene_culler_config(const CullOptions& options, int threads);
// role: objects with role=occluder (all when none has a role); all; auto: role when the scene
// marks occluders, otherwise objects whose box diagonal is at least 2 % of the scene's
// (Zhang's static size filter).
std::vector<std::uint32_t> choose_occluders(const Scene& scene, const std::string& choice, double complexity = kDefaultComplexity);
// What a culler's configuration points at, loaded or built for one scene: it must outlive the culler.
struct CullResources {
    std::vector<std::uint32_t> occluders;  // the candidates (--occluders)
    std::unique_ptr<VisibilityGrid> grid;  // --rank baked: --grid, read for this scene
    std::unique_ptr<OccluderLods> lods;    // --lod on: built for the candidates
};
// Chooses the candidates, reads the grid and builds the LODs the options ask for, and points
// `config` at them.
CullResources prepare_cull_resources(const CullOptions& options, const Scene& scene, SceneCullerConfig& config);

const char* visibility_name(Visibility v);
const char* overlap_exit_name(OverlapExit e);

}  // namespace homcull::cli
