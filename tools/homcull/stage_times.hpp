#pragma once
// A view's stage times over a benchmark's rounds (SceneCullTimings), and their medians: what
// bench --workload frame reports per view and over the views, for one thread or several.
#include "options.hpp"

#include <homcull/scene_culler.hpp>

#include <nlohmann/json.hpp>

#include <vector>

namespace homcull::cli {

struct StageTimes {
    std::vector<double> select, render, maps, tests;

    void add(const SceneCullTimings& t) {
        select.push_back(t.select_ms), render.push_back(t.render_ms), maps.push_back(t.maps_ms), tests.push_back(t.test_ms);
    }
    // {"select", "render", "maps", "tests"}: each stage's median over the rounds.
    nlohmann::json medians() const {
        return {{"select", median(select)}, {"render", median(render)}, {"maps", median(maps)}, {"tests", median(tests)}};
    }
};

// The mean over the views of each stage's median, keyed as StageTimes::medians.
inline nlohmann::json stage_means(const std::vector<StageTimes>& views) {
    nlohmann::json mean = {{"select", 0.0}, {"render", 0.0}, {"maps", 0.0}, {"tests", 0.0}};
    for (const StageTimes& v : views) {
        const nlohmann::json m = v.medians();
        for (const char* stage : {"select", "render", "maps", "tests"})
            mean[stage] = mean[stage].get<double>() + m[stage].get<double>() / double(views.size());
    }
    return mean;
}

}  // namespace homcull::cli
