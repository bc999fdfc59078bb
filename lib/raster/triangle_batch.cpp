#include "raster/triangle_batch.hpp"

#include <cstring>

namespace homcull::detail {

void gather_triangle_batch(const TriangleInput& in, std::size_t first, int count, TriangleBatch& batch) {
    const auto* bytes = static_cast<const unsigned char*>(in.positions);
    const bool has_w = in.position_components == 4;
    batch.first = first;
    batch.count = count;
    for (int t = 0; t < TriangleBatch::kSize; ++t) {
        std::uint32_t index[3] = {0, 0, 0};
        bool valid = t < count;
        for (int k = 0; k < 3 && valid; ++k) {
            const std::size_t n = 3 * (first + std::size_t(t)) + std::size_t(k);
            if (!in.indices) index[k] = std::uint32_t(n);
            else if (in.indices_16bit) index[k] = static_cast<const std::uint16_t*>(in.indices)[n];
            else index[k] = static_cast<const std::uint32_t*>(in.indices)[n];
            valid = index[k] < in.vertex_count;
        }
        batch.indices_valid[t] = valid;
        for (int k = 0; k < 3; ++k) {
            // Component by component, fixed-size copies (see fetch_clip_triangle).
            float p[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            if (valid) {
                const unsigned char* vertex = bytes + std::size_t(index[k]) * in.position_stride;
                for (int c = 0; c < 3; ++c) std::memcpy(&p[c], vertex + sizeof(float) * std::size_t(c), sizeof(float));
                if (has_w) std::memcpy(&p[3], vertex + 3 * sizeof(float), sizeof(float));
            }
            batch.px[k][t] = p[0], batch.py[k][t] = p[1], batch.pz[k][t] = p[2], batch.pw[k][t] = p[3];
        }
    }
}

void classify_triangle_batch_reference(const TriangleInput& in, double near_w, TriangleBatch& batch) {
    for (int t = 0; t < TriangleBatch::kSize; ++t) {
        glm::dvec4 clip[3];
        bool finite = true;
        for (int k = 0; k < 3; ++k) {
            clip[k] = transform_to_clip(in.model_to_clip, batch.px[k][t], batch.py[k][t], batch.pz[k][t], batch.pw[k][t]);
            batch.cx[k][t] = clip[k].x, batch.cy[k][t] = clip[k].y, batch.cz[k][t] = clip[k].z, batch.cw[k][t] = clip[k].w;
            finite = finite && finite_clip(clip[k]);
        }
        batch.fate[t] = !batch.indices_valid[t] || !finite ? TriangleFate::invalid : unclipped_fate(clip, in.backface, near_w);
    }
}

}  // namespace homcull::detail
