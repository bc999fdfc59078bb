#pragma once
// The JSON pieces `cull`, `walk` and `bench --workload frame` print: per-object results in
// DESIGN.md's format, stage timings, the culler's work, the configuration.
#include <homcull/scene_culler.hpp>
#include <homcull/truth/ground_truth.hpp>
#include <homcull/truth/occluder_bound.hpp>

#include <nlohmann/json.hpp>

namespace homcull::cli {

// {"id","name","triangles","result","level_of_visibility"[,"overlap"][,"truth","visible_samples"]}
nlohmann::json object_result_json(const Scene& scene, std::size_t id, const OccludeeAnswer& answer, const TruthResult* truth);
// {"select","render","maps","tests"} in milliseconds.
nlohmann::json timings_json(const SceneCullTimings& ms);
nlohmann::json work_json(const SceneCullWork& work);
struct CullOptions;
// Every culling option as given (cull_options.hpp), so that a JSON output says which
// configuration made it: {"mode", "depth", "occludees", "clusters", "back_faces", ...}.
nlohmann::json cull_config_json(const CullOptions& options);
// {"hidden_outright","hideable","efficiency_bound","missed_hideable","missed_not_hideable"}.
nlohmann::json occluder_bound_json(const OccluderBoundTally& bound);

}  // namespace homcull::cli
