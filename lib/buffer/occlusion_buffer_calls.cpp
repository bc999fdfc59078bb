// OcclusionBuffer's calls, each forwarded to its state (buffer/buffer_state.hpp), where the
// implementation lives (occlusion_buffer.cpp, clustered_render.cpp, occludee_queries.cpp,
// occludee_triangles.cpp).
#include "buffer/buffer_state.hpp"

namespace homcull {

// The state comes from the memory hooks current where the buffer is made (the C interface's
// account, or the global heap), like every array it then holds.
OcclusionBuffer::OcclusionBuffer(const BufferConfig& config) : state_(detail::make_hooked<detail::BufferState>(config)) {}
OcclusionBuffer::~OcclusionBuffer() = default;
OcclusionBuffer::OcclusionBuffer(OcclusionBuffer&&) noexcept = default;
OcclusionBuffer& OcclusionBuffer::operator=(OcclusionBuffer&&) noexcept = default;

void OcclusionBuffer::configure(const BufferConfig& config) { state_->configure(config); }
void OcclusionBuffer::set_near_w(float near_w) { state_->set_near_w(near_w); }
void OcclusionBuffer::reserve(const BufferReserve& reserve) { state_->reserve(reserve); }
void OcclusionBuffer::clear() { state_->clear(); }

void OcclusionBuffer::render(const TriangleInput& input, const ParallelFor& parallel) { state_->render(input, parallel); }
void OcclusionBuffer::render_frame(const TriangleInput& input, const ParallelFor& parallel) { state_->render_frame(input, parallel); }
void OcclusionBuffer::render(const ClusteredInput& input, const ParallelFor& parallel) { state_->render(input, parallel); }
void OcclusionBuffer::render_frame(const ClusteredInput& input, const ParallelFor& parallel) { state_->render_frame(input, parallel); }

void OcclusionBuffer::begin_tasks(bool clear_first) { state_->begin_tasks(clear_first); }
void OcclusionBuffer::record(const ClusteredInput& draw, const ParallelFor& parallel) { state_->record(draw, parallel); }
std::size_t OcclusionBuffer::close_tasks() { return state_->close_tasks(); }
void OcclusionBuffer::run_task(std::size_t index) noexcept { state_->run_task(index); }
void OcclusionBuffer::finish_tasks() { state_->finish_tasks(); }
std::size_t OcclusionBuffer::finish_tasks(std::nothrow_t) noexcept { return state_->finish_tasks(std::nothrow); }

Visibility OcclusionBuffer::test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    return state_->test_rect(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min);
}
Visibility OcclusionBuffer::test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const {
    return state_->test_rect_exhaustive(ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min);
}
Visibility OcclusionBuffer::test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const {
    return state_->test_aabb(box_min, box_max, model_to_clip);
}
Visibility OcclusionBuffer::test_aabb_by_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const {
    return state_->test_aabb_by_rectangle(box_min, box_max, model_to_clip);
}
void OcclusionBuffer::test_rects(const ScreenRect* rects, std::size_t count, Visibility* results) const {
    state_->test_rects(rects, count, results);
}
void OcclusionBuffer::test_aabbs(const Aabb* boxes, std::size_t count, const std::array<float, 16>& model_to_clip, Visibility* results) const {
    state_->test_aabbs(boxes, count, model_to_clip, results);
}
OcclusionBuffer::TriangleTest OcclusionBuffer::test_triangles(const TriangleInput& occludee, std::uint64_t tolerated_samples,
                                                              std::size_t first_triangle) const {
    return state_->test_triangles(occludee, tolerated_samples, first_triangle);
}
OcclusionBuffer::TriangleTest OcclusionBuffer::test_triangles(const TriangleInput& occludee, std::uint64_t tolerated_samples,
                                                              std::size_t first_triangle, const ClosedSolid& solid) const {
    return state_->test_triangles(occludee, tolerated_samples, first_triangle, &solid);
}

const BufferConfig& OcclusionBuffer::config() const { return state_->config(); }
int OcclusionBuffer::sample_width() const { return state_->sample_width(); }
int OcclusionBuffer::sample_height() const { return state_->sample_height(); }
const RasterStats& OcclusionBuffer::stats() const { return state_->stats(); }
OcclusionBuffer::Subtile OcclusionBuffer::subtile(int tx, int ty) const { return state_->subtile(tx, ty); }
std::vector<OcclusionBuffer::Subtile> OcclusionBuffer::subtiles() const { return state_->subtiles(); }
int OcclusionBuffer::subtiles_x() const { return state_->subtiles_x(); }
int OcclusionBuffer::subtiles_y() const { return state_->subtiles_y(); }
void OcclusionBuffer::read_coverage(std::vector<std::uint8_t>& covered) const { state_->read_coverage(covered); }
void OcclusionBuffer::read_depth(std::vector<float>& w) const { state_->read_depth(w); }
void OcclusionBuffer::read_sample_depth(std::vector<float>& d) const { state_->read_sample_depth(d); }
void OcclusionBuffer::read_pyramid(std::vector<float>& cells) const { state_->read_pyramid(cells); }

}  // namespace homcull
