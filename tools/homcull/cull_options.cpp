#include "cull_options.hpp"

#include "options.hpp"

#include <homcull/error.hpp>
#include <homcull/io/visibility_grid_io.hpp>
#include <homcull/truth/occluder_lod_build.hpp>

#include <cstdio>


namespace homcull::cli {

namespace {

// A count given on the command line: digits only. (Read into a size_t, "-1" would wrap.)
const CLI::Validator kWholeNumber(
    [](const std::string& v) {
        return !v.empty() && v.find_first_not_of("0123456789") == std::string::npos ? std::string() : "must be a whole number >= 0";
    },
    "N >= 0");

}  // namespace

void add_cull_options(CLI::App& app, CullOptions& o, bool with_display) {
    if (with_display) {
        app.add_option("--resolution", o.resolution, "Display resolution WxH: the answers are right for its pixel centres")
            ->capture_default_str();
        app.add_option("--samples", o.samples,
                       "S x S coverage samples per buffer pixel (1, 2 or 4; default: the largest whose buffer x S samples fit "
                       "within the display, so 4 for a buffer a quarter of the display or smaller)")
            ->check(CLI::IsMember({1, 2, 4}));
    }
    app.add_option("--buffer", o.buffer, "Occlusion buffer WxH (default: display / samples, the display's own pixel centres; with --samples unset, the display)");
    app.add_option("--mode", o.mode, "conservative (never hides a visible object) or approximate (tolerates --hole)")
        ->capture_default_str()->check(CLI::IsMember({"conservative", "approximate"}));
    app.add_option("--hole", o.hole, "approximate: largest negligible hole L, in display pixels")->capture_default_str();
    app.add_option("--distribution", o.distribution, "approximate: Zhang's distribution factor D in [1, 4]")->capture_default_str();
    app.add_option("--transparency", o.transparency, "approximate: level-0 transparency threshold in [0, 1)")->capture_default_str();
    app.add_option("--depth", o.depth, "Depth test: masked, hzb, deb, nbz (not conservative) or plane")
        ->capture_default_str()->check(CLI::IsMember({"masked", "hzb", "deb", "nbz", "plane"}));
    app.add_option("--deb", o.deb, "Depth estimation buffer cells WxH")->capture_default_str();
    app.add_option("--pyramid", o.pyramid,
                   "lazy: with --mode conservative and --depth masked, build no opacity pyramid (the buffer's depth test "
                   "decides alone, the overlap test does not run); always: build it every frame and run the overlap test "
                   "(the same answers; its exits and estimates reported)")
        ->capture_default_str()->check(CLI::IsMember({"lazy", "always"}));
    app.add_option("--finest-level", o.finest_level, "Finest active level of the opacity pyramid")->capture_default_str();
    app.add_option("--coarsest-level", o.coarsest_level, "Coarsest active level (-1: the pyramid's last)")->capture_default_str();
    app.add_option("--occludees", o.occludees,
                   "box: each object's world box; where the box is visible, also its triangles: rects (their screen rectangles, "
                   "through the maps' depth test) or samples (sample by sample against the masked depth); auto: samples with "
                   "--depth masked, else rects")
        ->capture_default_str()->check(CLI::IsMember({"box", "rects", "samples", "auto"}));
    app.add_option("--occludee-parts", o.occludee_parts,
                   "Split each object's triangles into up to N parts with a box each: an object is hidden when every part's "
                   "box is (or, with samples occludees, every visible part's triangles); 0 or 1: the object's box alone")
        ->capture_default_str()->check(CLI::Range(0, 64));
    app.add_option("--sample-depth", o.sample_depth,
                   "on: with samples occludees, keep the occluders' depth per sample (precise at silhouettes); off: the "
                   "subtile layers alone (faster render)")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    app.add_option("--clusters", o.clusters,
                   "on: split each occluder into clusters when the scene is loaded, and draw the frame's clusters nearest first, "
                   "skipping those outside the view or hidden (faster render); off: every drawn triangle is set up")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    app.add_option("--closed-back-faces", o.closed_back_faces,
                   "skip: draw closed occluder meshes without their triangles facing away from the eye (they lie behind the "
                   "front ones); draw: every triangle")
        ->capture_default_str()->check(CLI::IsMember({"skip", "draw"}));
    app.add_option("--back-faces", o.back_faces,
                   "draw: occluder triangles facing away from the eye are drawn (ground truth sees back faces; closed meshes' "
                   "are skipped, --closed-back-faces); cull: none is drawn (front faces counter-clockwise, glTF's convention, "
                   "as the peers' drivers draw): a faster render, and less culled where a back face is all that hides an object")
        ->capture_default_str()->check(CLI::IsMember({"draw", "cull"}));
    app.add_option("--merge-coplanar", o.merge_coplanar,
                   "on: when the scene is loaded, re-triangulate each occluder's exactly coplanar regions with fewer triangles "
                   "covering the same points (the OpenArena maps: 40-46 % fewer); off: draw the triangles as the scene has them")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    app.add_option("--occluders", o.occluders, "Occluder candidates: role, all, or auto (role when marked, else objects by size)")
        ->capture_default_str()->check(CLI::IsMember({"role", "all", "auto"}));
    app.add_option("--complexity", o.complexity,
                   "Drop candidates with more than F times the median triangles per unit of their surface (Zhang's "
                   "complexity filter); 0: keep all")
        ->capture_default_str()->check(kAtLeastZero);
    app.add_option("--strategy", o.strategy,
                   "one-pass (select, render, test), progressive (render visible candidates in batches while traversing front "
                   "to back) or temporal (last frame's visible candidates plus those new in the frustum; one-pass on the "
                   "first frame and at a camera cut)")
        ->capture_default_str()->check(CLI::IsMember({"one-pass", "progressive", "temporal"}));
    // Checked by SceneCuller (at least 0, infinity allowed), whose error names the value.
    app.add_option("--cut-step", o.cut_step,
                   "temporal: a frame whose eye moved more than this many near-plane distances since the last one is a camera "
                   "cut (works as one-pass); inf: never")
        ->capture_default_str();
    app.add_option("--cut-turn", o.cut_turn,
                   "temporal: a frame whose view direction turned more than this many degrees since the last one is a camera cut")
        ->capture_default_str()->check(CLI::Range(0.0, 180.0));
    app.add_option("--rank", o.rank, "Per-frame ranking of the candidates in the frustum under --budget: none, distance, area, or "
                                     "baked (the --grid point nearest the eye)")
        ->capture_default_str()->check(CLI::IsMember({"none", "distance", "area", "baked"}));
    app.add_option("--grid", o.grid, "Visibility grid for --rank baked (homcull bake)");
    app.add_option("--lod", o.lod, "on: draw occluders with simplified, verified-inner LODs (meshoptimizer) where their box lies "
                                   "beyond the near plane; never hides more than the originals")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
    app.add_option("--budget", o.budget, "Occluder triangles per frame at most (0: no limit)")
        ->capture_default_str()
        ->check(kWholeNumber);
    app.add_option("--min-occluder-size", o.min_occluder_size,
                   "Draw only the occluder candidates whose box looks at least this large from the eye: (box diagonal / "
                   "distance)^2, in square radians (a box whose diagonal is as long as it is far: 1); 0: every one")
        ->capture_default_str()->check(kAtLeastZero);
    app.add_option("--batch", o.batch, "progressive: render the waiting occluders every time this many triangles wait")
        ->capture_default_str()->check(CLI::PositiveNumber);
    app.add_option("--hierarchy", o.hierarchy, "on: test the object hierarchy's nodes and skip what a hidden node holds; off: test "
                                               "every object")
        ->capture_default_str()->check(CLI::IsMember({"on", "off"}));
}

SceneCullerConfig scene_culler_config(const CullOptions& o, int threads) {
    SceneCullerConfig c;
    c.job_system = threads > 1;
    c.display = parse_resolution(o.resolution);
    if (!o.buffer.empty()) c.buffer = parse_resolution(o.buffer, "--buffer");
    c.samples = o.samples;
    if (o.mode == "conservative" && o.hole != 0.0) throw Error("--hole needs --mode approximate (conservative mode tolerates no hole)");
    if (o.mode == "approximate" && !(o.hole > 0.0)) throw Error("--mode approximate needs --hole L with L > 0 display pixels");
    c.maps.hole_pixels = o.mode == "approximate" ? o.hole : 0.0;
    c.maps.distribution = o.distribution;
    c.maps.transparency = o.transparency;
    c.maps.finest_level = o.finest_level;
    c.maps.coarsest_level = o.coarsest_level;
    const Resolution deb = parse_resolution(o.deb, "--deb");
    c.maps.deb_width = deb.width;
    c.maps.deb_height = deb.height;
    c.maps.depth = o.depth == "hzb" ? DepthTest::hzb : o.depth == "deb" ? DepthTest::deb : o.depth == "nbz" ? DepthTest::nbz
                 : o.depth == "plane" ? DepthTest::plane : DepthTest::masked;
    c.maps.pyramid = o.pyramid == "always" ? PyramidBuild::always : PyramidBuild::lazy;
    c.occludee_parts = o.occludee_parts;
    c.occludees = o.occludees == "box" ? OccludeeShape::box : o.occludees == "rects" ? OccludeeShape::rectangles
                : o.occludees == "samples" ? OccludeeShape::samples : OccludeeShape::automatic;
    c.sample_depth = o.sample_depth == "on";
    c.occluder_clusters = o.clusters == "on";
    c.skip_closed_back_faces = o.closed_back_faces == "skip";
    c.merge_coplanar_occluders = o.merge_coplanar == "on";
    c.backface = o.back_faces == "cull" ? Backface::cw : Backface::none;  // cw on screen: the back of a counter-clockwise front
    c.strategy = o.strategy == "progressive" ? CullStrategy::progressive : o.strategy == "temporal" ? CullStrategy::temporal
                                                                                                 : CullStrategy::one_pass;
    c.temporal_cut = {o.cut_step, o.cut_turn};
    c.occluder_budget.ranking = o.rank == "distance" ? OccluderRanking::distance : o.rank == "area" ? OccluderRanking::area
                              : o.rank == "baked"  ? OccluderRanking::baked
                                                   : OccluderRanking::none;
    if ((o.rank == "baked") != !o.grid.empty()) throw Error("--rank baked and --grid FILE (from homcull bake) go together");
    c.occluder_budget.triangles = o.budget;
    c.occluder_budget.min_projected_size = o.min_occluder_size;
    c.progressive_batch_triangles = o.batch;
    c.hierarchy = o.hierarchy == "on";
    return c;
}

std::vector<std::uint32_t> choose_occluders(const Scene& scene, const std::string& choice, double complexity) {
    const OccluderFilter filter = choice == "all" ? OccluderFilter::all : choice == "auto" ? OccluderFilter::size : OccluderFilter::role;
    return filter_by_complexity(scene, occluder_candidates(scene, filter), complexity);
}

CullResources prepare_cull_resources(const CullOptions& o, const Scene& scene, SceneCullerConfig& config) {
    CullResources r;
    r.occluders = choose_occluders(scene, o.occluders, o.complexity);
    if (o.rank == "baked") {
        r.grid = std::make_unique<VisibilityGrid>(read_visibility_grid(o.grid, scene));
        if (r.grid->header.occluders != o.occluders)
            std::fprintf(stderr, "homcull: warning: %s was baked for --occluders %s, ranking --occluders %s\n", o.grid.c_str(),
                         r.grid->header.occluders.c_str(), o.occluders.c_str());
        config.occluder_budget.grid = r.grid.get();
    }
    if (o.lod == "on") {
        r.lods = std::make_unique<OccluderLods>(build_occluder_lods(scene, r.occluders));
        config.lods = r.lods.get();
    }
    return r;
}

const char* visibility_name(Visibility v) {
    return v == Visibility::visible ? "visible" : v == Visibility::occluded ? "occluded" : "view_culled";
}

const char* overlap_exit_name(OverlapExit e) {
    switch (e) {
    case OverlapExit::not_run: return "not_run";
    case OverlapExit::passed: return "passed";
    case OverlapExit::conservative_rejection: return "conservative_rejection";
    case OverlapExit::predictive_rejection: return "predictive_rejection";
    case OverlapExit::transparent_cell: return "transparent_cell";
    case OverlapExit::finest_level: return "finest_level";
    case OverlapExit::samples: return "samples";
    }
    return "unknown";
}

}  // namespace homcull::cli
