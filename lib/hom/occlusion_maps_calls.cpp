// OcclusionMaps' calls, each forwarded to its state (hom/maps_state.hpp), where the
// implementation lives (occlusion_maps.cpp, occlusion_maps_depth.cpp).
#include "hom/maps_state.hpp"

namespace homcull {

OcclusionMaps::OcclusionMaps(const OcclusionBuffer& buffer, const OcclusionMapsConfig& config)
    : state_(detail::make_hooked<detail::MapsState>(buffer, config)) {}
OcclusionMaps::~OcclusionMaps() = default;
OcclusionMaps::OcclusionMaps(OcclusionMaps&&) noexcept = default;
OcclusionMaps& OcclusionMaps::operator=(OcclusionMaps&&) noexcept = default;

void OcclusionMaps::clear() { state_->clear(); }
void OcclusionMaps::set_near_w(float near_w) { state_->set_near_w(near_w); }
void OcclusionMaps::add_occluder_box(const Aabb& box, const std::array<float, 16>& model_to_clip) { state_->add_occluder_box(box, model_to_clip); }
void OcclusionMaps::build(const OcclusionBuffer& buffer) { state_->build(buffer); }
void OcclusionMaps::build_pyramid() { state_->build_pyramid(); }
bool OcclusionMaps::pyramid_built() const { return state_->pyramid_built_; }
OccludeeAnswer OcclusionMaps::test_rect(const ScreenRect& rect) const { return state_->test_rect(rect); }
OccludeeAnswer OcclusionMaps::test_aabb(const Aabb& box, const std::array<float, 16>& model_to_clip) const { return state_->test_aabb(box, model_to_clip); }
OccludeeAnswer OcclusionMaps::test_aabb_by_rectangle(const Aabb& box, const std::array<float, 16>& model_to_clip) const {
    return state_->test_aabb_by_rectangle(box, model_to_clip);
}
double OcclusionMaps::hole_budget() const { return state_->hole_budget(); }
OccludeeAnswer OcclusionMaps::test_rect_within(const ScreenRect& rect, double& budget) const { return state_->test_rect_within(rect, budget); }
const OcclusionMapsConfig& OcclusionMaps::config() const { return state_->config(); }
int OcclusionMaps::levels() const { return state_->levels(); }
int OcclusionMaps::level_width(int k) const { return state_->level_width(k); }
int OcclusionMaps::level_height(int k) const { return state_->level_height(k); }
const std::uint32_t* OcclusionMaps::covered_samples(int k) const { return state_->covered_samples(k); }
std::uint32_t OcclusionMaps::cell_samples(int k, int x, int y) const { return state_->cell_samples(k, x, y); }
float OcclusionMaps::opacity(int k, int x, int y) const { return state_->opacity(k, x, y); }
double OcclusionMaps::opacity_threshold(int k) const { return state_->opacity_threshold(k); }
double OcclusionMaps::transparency_threshold(int k) const { return state_->transparency_threshold(k); }
const float* OcclusionMaps::farthest_depth(int k) const { return state_->farthest_depth(k); }
const float* OcclusionMaps::nearest_depth(int k) const { return state_->nearest_depth(k); }
const std::vector<float>& OcclusionMaps::depth_estimation() const { return state_->depth_estimation(); }
float OcclusionMaps::plane_depth() const { return state_->plane_depth(); }

}  // namespace homcull
