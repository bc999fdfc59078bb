#include "cull_report.hpp"

#include "cull_options.hpp"

namespace homcull::cli {

nlohmann::json object_result_json(const Scene& scene, std::size_t id, const OccludeeAnswer& a, const TruthResult* truth) {
    nlohmann::json item = {{"id", id},
                           {"name", scene.objects[id].name},
                           {"triangles", scene.triangle_count(scene.objects[id])},
                           {"result", visibility_name(a.visibility)},
                           {"level_of_visibility", a.level_of_visibility}};
    if (a.overlap_exit) item["overlap"] = overlap_exit_name(OverlapExit(a.overlap_exit));
    if (truth) {
        const ObjectVisibility& t = truth->objects[id];
        item["truth"] = truth_result_name(t);
        item["visible_samples"] = t.visible_samples;
        // DESIGN.md's robust samples, and the samples where only a tie hid it: why a miss or a
        // false cull may be a tie rather than a real one.
        item["robust_samples"] = t.robust_samples;
        item["tie_samples"] = t.tie_samples;
    }
    return item;
}

nlohmann::json timings_json(const SceneCullTimings& ms) {
    return {{"select", ms.select_ms}, {"render", ms.render_ms}, {"maps", ms.maps_ms}, {"tests", ms.test_ms}};
}

nlohmann::json work_json(const SceneCullWork& w) {
    return {{"occluder_objects", w.occluder_objects}, {"occluder_triangles", w.occluder_triangles},
            {"occluder_lods", w.occluder_lods},       {"renders", w.renders},
            {"nodes_tested", w.nodes_tested},         {"objects_tested", w.objects_tested},
            {"occludee_parts_tested", w.occludee_parts_tested}, {"solid_parts_tested", w.solid_parts_tested},
            {"back_faces_skipped", w.back_faces_skipped}, {"used_history", w.used_history}};
}

nlohmann::json cull_config_json(const CullOptions& o) {
    return {{"mode", o.mode},
            {"hole", o.hole},
            {"distribution", o.distribution},
            {"transparency", o.transparency},
            {"depth", o.depth},
            {"deb", o.deb},
            {"pyramid", o.pyramid},
            {"finest_level", o.finest_level},
            {"coarsest_level", o.coarsest_level},
            {"occludees", o.occludees},
            {"occludee_parts", o.occludee_parts},
            {"sample_depth", o.sample_depth},
            {"clusters", o.clusters},
            {"closed_back_faces", o.closed_back_faces},
            {"back_faces", o.back_faces},
            {"merge_coplanar", o.merge_coplanar},
            {"occluders", o.occluders},
            {"complexity", o.complexity},
            {"strategy", o.strategy},
            {"cut_step", o.cut_step},
            {"cut_turn", o.cut_turn},
            {"rank", o.rank},
            {"grid", o.grid},
            {"lod", o.lod},
            {"budget", o.budget},
            {"min_occluder_size", o.min_occluder_size},
            {"batch", o.batch},
            {"hierarchy", o.hierarchy}};
}

nlohmann::json occluder_bound_json(const OccluderBoundTally& bound) {
    return {{"hidden_outright", bound.hidden},
            {"hideable", bound.hideable},
            {"efficiency_bound", bound.efficiency_bound()},
            {"missed_hideable", bound.missed_hideable},
            {"missed_not_hideable", bound.missed_not_hideable}};
}

}  // namespace homcull::cli
