// SceneCuller's calls, each forwarded to its state (scene/scene_culler_state.hpp), where the
// implementation lives (scene_culler.cpp, scene_traversal.cpp).
#include "scene/scene_culler_state.hpp"

namespace homcull {

SceneCuller::SceneCuller(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                         const ParallelFor& parallel)
    : state_(detail::make_hooked<detail::SceneCullerState>(scene, occluders, config, parallel)) {}
SceneCuller::~SceneCuller() = default;
SceneCuller::SceneCuller(SceneCuller&&) noexcept = default;
SceneCuller& SceneCuller::operator=(SceneCuller&&) noexcept = default;

void SceneCuller::cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    state_->cull(camera, answers, parallel);
}
void SceneCuller::reset_history() { state_->reset_history(); }

const SceneCullerConfig& SceneCuller::config() const { return state_->config(); }
const Scene& SceneCuller::scene() const { return state_->scene(); }
const OcclusionBuffer& SceneCuller::buffer() const { return state_->buffer(); }
const OcclusionMaps& SceneCuller::maps() const { return state_->maps(); }
const SceneCullTimings& SceneCuller::timings() const { return state_->timings(); }
const SceneCullWork& SceneCuller::work() const { return state_->work(); }
const OverlapExitCounts& SceneCuller::overlap_exits() const { return state_->overlap_exits(); }
const std::vector<std::uint32_t>& SceneCuller::drawn_occluders() const { return state_->drawn_occluders(); }
const ObjectHierarchy& SceneCuller::hierarchy() const { return state_->hierarchy(); }
std::size_t SceneCuller::occluder_objects() const { return state_->occluder_objects(); }
std::size_t SceneCuller::occluder_triangles() const { return state_->occluder_triangles(); }

}  // namespace homcull
