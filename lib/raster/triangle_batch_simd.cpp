// The SIMD kernels of the setup front end (triangle_batch.hpp), double lanes (2 on SSE4 and
// NEON, 4 on AVX2, 8 on AVX-512), each lane computing exactly what the references in
// triangle_batch.cpp compute for it: transform_to_clip's products and sums in the same order
// (no fused multiply-add), then the comparisons of outcode, outside_frustum,
// too_large_to_clip, needs_clipping, homogeneous_det and facing_away, which are exact.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "raster/triangle_batch_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "raster/clip_fates-inl.h"
#include "common/accurate_sum-inl.h"
#include "common/float_outward-inl.h"
#include "common/lane_bits-inl.h"
#include "raster/triangle_batch.hpp"

#include <cstdint>
#include <cstring>
#include <limits>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using D = hn::CappedTag<double, 8>;  // at most 8 lanes: one byte of mask bits per vector
using V = hn::Vec<D>;
using M = hn::Mask<D>;

// transform_to_clip's row r: accurate_sum4(m[r] x, m[4 + r] y, m[8 + r] z, m[12 + r] w); with
// kPlain, transform_to_clip_plain's ((m[r] x + m[4 + r] y) + m[8 + r] z) + m[12 + r] w.
template <bool kPlain = false>
HWY_INLINE V ClipRow(D d, const std::array<float, 16>& m, int r, V x, V y, V z, V w) {
    const V p0 = hn::Mul(hn::Set(d, double(m[r])), x), p1 = hn::Mul(hn::Set(d, double(m[4 + r])), y);
    const V p2 = hn::Mul(hn::Set(d, double(m[8 + r])), z), p3 = hn::Mul(hn::Set(d, double(m[12 + r])), w);
    if (kPlain) return hn::Add(hn::Add(hn::Add(p0, p1), p2), p3);
    return AccurateSum4(p0, p1, p2, p3);
}

// orthographic_representative (triangle_setup.hpp) lane by lane, in its order of operations.
HWY_INLINE void OrthographicRepresentative(D d, V& x, V& y, V z, V& w) {
    const V h = hn::Mul(hn::Sub(hn::Mul(hn::Set(d, 3.0), w), z), hn::Set(d, 0.5));
    const auto valid = hn::And(hn::Gt(w, hn::Zero(d)), hn::Ge(h, hn::Mul(hn::Set(d, 0x1.0p-8), w)));
    const V nan = hn::Set(d, std::numeric_limits<double>::quiet_NaN());
    x = hn::IfThenElse(valid, hn::Div(x, h), nan);
    y = hn::IfThenElse(valid, hn::Div(y, h), nan);
    w = hn::IfThenElse(valid, hn::Div(w, h), nan);
}

// Transforms the lanes' positions (count of them, from vertex `at`) and stores their clip
// coordinates and outcodes into the cache.
HWY_INLINE void StoreVertexClips(const TriangleInput& in, V near, V px, V py, V pz, V pw, std::size_t at, std::size_t count,
                                 const VertexClip& cache) {
    const D d;
    const hn::Rebind<std::int32_t, D> di;
    V x = ClipRow(d, in.model_to_clip, 0, px, py, pz, pw), y = ClipRow(d, in.model_to_clip, 1, px, py, pz, pw);
    const V z = ClipRow(d, in.model_to_clip, 2, px, py, pz, pw);
    V w = ClipRow(d, in.model_to_clip, 3, px, py, pz, pw);
    if (in.orthographic) OrthographicRepresentative(d, x, y, z, w);
    hn::StoreU(x, d, cache.x + at);  // whole vectors: the planes are padded by kVertexClipPadding
    hn::StoreU(y, d, cache.y + at);
    hn::StoreU(z, d, cache.z + at);
    hn::StoreU(w, d, cache.w + at);
    // outcode(), lane by lane, as small integers in double (exact), then bytes.
    const V none = hn::Zero(d), infinity = hn::Set(d, HUGE_VAL);
    auto bit = [&](M m, OutcodeBit b) { return hn::IfThenElse(m, hn::Set(d, double(b)), none); };
    const V planes = hn::Add(hn::Add(hn::Add(bit(hn::Lt(w, near), kBehindNear), bit(hn::Gt(x, w), kBeyondRight)),
                                     hn::Add(bit(hn::Lt(x, hn::Neg(w)), kBeyondLeft), bit(hn::Gt(y, w), kBeyondTop))),
                             bit(hn::Lt(y, hn::Neg(w)), kBeyondBottom));
    const M finite = hn::And(hn::And(hn::Lt(hn::Abs(x), infinity), hn::Lt(hn::Abs(y), infinity)), hn::Lt(hn::Abs(w), infinity));
    HWY_ALIGN std::int32_t code[8];
    hn::Store(hn::DemoteTo(di, hn::IfThenElse(finite, planes, hn::Set(d, double(kNotFinite)))), di, code);
    for (std::size_t i = 0; i < count; ++i) cache.outcode[at + i] = std::uint8_t(code[i]);
}

void TransformVertices(const TriangleInput& in, double near_w, std::size_t begin, std::size_t end, const VertexClip& cache) {
    const D d;
    const hn::Rebind<float, D> df;
    constexpr int kBlock = 8;
    static_assert(kBlock <= int(kVertexClipPadding) && hn::MaxLanes(D()) <= kVertexClipPadding,
                  "whole-block stores past a task's end stay within the padding (occlusion_buffer.cpp's tasks)");
    const int lanes = int(hn::Lanes(d));
    const V near = hn::Set(d, near_w), one = hn::Set(d, 1.0);
    std::size_t v0 = begin;
    // Packed x, y, z floats (the common layout): whole vectors of vertices deinterleaved by loads.
    const auto* packed = static_cast<const float*>(in.positions);
    if (in.position_components == 3 && in.position_stride == 3 * sizeof(float) && reinterpret_cast<std::uintptr_t>(packed) % alignof(float) == 0)
        for (; v0 + std::size_t(lanes) <= end; v0 += std::size_t(lanes)) {
            hn::Vec<decltype(df)> x, y, z;
            hn::LoadInterleaved3(df, packed + 3 * v0, x, y, z);
            StoreVertexClips(in, near, hn::PromoteTo(d, x), hn::PromoteTo(d, y), hn::PromoteTo(d, z), one, v0, std::size_t(lanes), cache);
        }
    // Any stride and 4 components, and the last few: positions to structure of arrays one by one.
    HWY_ALIGN double p[4][kBlock];
    for (; v0 < end; v0 += kBlock) {
        const int n = int(std::min<std::size_t>(kBlock, end - v0));
        for (int i = 0; i < kBlock; ++i) {  // past n: the last one again
            float f[4];
            read_position(in, std::uint32_t(v0 + std::size_t(std::min(i, n - 1))), f);
            p[0][i] = f[0], p[1][i] = f[1], p[2][i] = f[2], p[3][i] = f[3];
        }
        for (int g = 0; g < n; g += lanes)
            StoreVertexClips(in, near, hn::Load(d, p[0] + g), hn::Load(d, p[1] + g), hn::Load(d, p[2] + g), hn::Load(d, p[3] + g),
                             v0 + std::size_t(g), std::size_t(std::min(lanes, n - g)), cache);
    }
}

// gather_triangle_batch for a full batch of triangles without indices and with 4 float
// components per vertex (engines' clip-space soups, workload S1), consecutive or listed in
// `order`: four vertices at a time, one 128-bit load each, a 4 x 4 transpose into x, y, z and
// w, widened to double. The same values as the scalar gather (float to double is exact).
void GatherDirectBatch(const TriangleInput& in, std::size_t first, const std::uint32_t* order, TriangleBatch& batch) {
    constexpr int kSize = TriangleBatch::kSize;
    const unsigned char* positions = static_cast<const unsigned char*>(in.positions);
    const std::size_t stride = in.position_stride;
    for (int t = 0; t < kSize; ++t) batch.triangle[t] = order ? std::size_t(order[first + std::size_t(t)]) : first + std::size_t(t);
    const auto vertex = [&](int t, int k) {
        return reinterpret_cast<const float*>(positions + (3 * batch.triangle[t] + std::size_t(k)) * stride);
    };
#if HWY_TARGET == HWY_SCALAR
    for (int k = 0; k < 3; ++k)
        for (int t = 0; t < kSize; ++t) {
            float p[4];
            std::memcpy(p, vertex(t, k), sizeof p);
            batch.px[k][t] = p[0], batch.py[k][t] = p[1], batch.pz[k][t] = p[2], batch.pw[k][t] = p[3];
        }
#else
    const hn::Full128<float> d4;
    const hn::Full64<float> d2;
    const hn::Full128<double> dd;
    const auto store = [&](hn::Vec<decltype(d4)> v, double* out) {  // 4 floats as 4 doubles
        hn::Store(hn::PromoteTo(dd, hn::LowerHalf(d2, v)), dd, out);
        hn::Store(hn::PromoteTo(dd, hn::UpperHalf(d2, v)), dd, out + 2);
    };
    for (int k = 0; k < 3; ++k)
        for (int t = 0; t < kSize; t += 4) {
            const auto v0 = hn::LoadU(d4, vertex(t, k)), v1 = hn::LoadU(d4, vertex(t + 1, k));
            const auto v2 = hn::LoadU(d4, vertex(t + 2, k)), v3 = hn::LoadU(d4, vertex(t + 3, k));
            const auto xy01 = hn::InterleaveLower(d4, v0, v1), xy23 = hn::InterleaveLower(d4, v2, v3);  // x0 x1 y0 y1
            const auto zw01 = hn::InterleaveUpper(d4, v0, v1), zw23 = hn::InterleaveUpper(d4, v2, v3);  // z0 z1 w0 w1
            store(hn::ConcatLowerLower(d4, xy23, xy01), batch.px[k] + t);
            store(hn::ConcatUpperUpper(d4, xy23, xy01), batch.py[k] + t);
            store(hn::ConcatLowerLower(d4, zw23, zw01), batch.pz[k] + t);
            store(hn::ConcatUpperUpper(d4, zw23, zw01), batch.pw[k] + t);
        }
#endif
    batch.indices_valid = (1u << kSize) - 1u;
}

template <bool kPlain>
HWY_INLINE void TransformBatchWith(const TriangleInput& in, TriangleBatch& batch) {
    const D d;
    const int lanes = int(hn::Lanes(d));
    if (is_identity(in.model_to_clip) && !in.orthographic) {
        // Positions already in clip space (S1, and engines that transform their own vertices,
        // as MOC's API allows): the product is the position itself, bit for bit, but for a
        // position with a coordinate that is not finite, where the product's zero terms make
        // every coordinate NaN. A NaN x is all classify_batch needs to call it invalid, as it
        // calls the product. (The sign of a zero coordinate may differ; nothing downstream
        // tells -0 from +0: comparisons, products summed into a determinant compared with 0,
        // and x/w plus a nonzero offset.) S1 at 1080p: 8.19 -> 7.93 ms.
        const V nan = hn::Set(d, std::numeric_limits<double>::quiet_NaN());
        for (int g = 0; g < TriangleBatch::kSize; g += lanes)
            for (int k = 0; k < 3; ++k) {
                const V px = hn::Load(d, batch.px[k] + g), py = hn::Load(d, batch.py[k] + g), pz = hn::Load(d, batch.pz[k] + g),
                        pw = hn::Load(d, batch.pw[k] + g);
                const auto finite = hn::And(hn::And(hn::IsFinite(px), hn::IsFinite(py)), hn::And(hn::IsFinite(pz), hn::IsFinite(pw)));
                hn::Store(hn::IfThenElse(finite, px, nan), d, batch.cx[k] + g);
                hn::Store(py, d, batch.cy[k] + g);
                hn::Store(pz, d, batch.cz[k] + g);
                hn::Store(pw, d, batch.cw[k] + g);
            }
        return;
    }
    for (int g = 0; g < TriangleBatch::kSize; g += lanes)
        for (int k = 0; k < 3; ++k) {
            const V px = hn::Load(d, batch.px[k] + g), py = hn::Load(d, batch.py[k] + g), pz = hn::Load(d, batch.pz[k] + g),
                    pw = hn::Load(d, batch.pw[k] + g);
            V x = ClipRow<kPlain>(d, in.model_to_clip, 0, px, py, pz, pw), y = ClipRow<kPlain>(d, in.model_to_clip, 1, px, py, pz, pw);
            const V z = ClipRow<kPlain>(d, in.model_to_clip, 2, px, py, pz, pw);
            V w = ClipRow<kPlain>(d, in.model_to_clip, 3, px, py, pz, pw);
            if (in.orthographic) OrthographicRepresentative(d, x, y, z, w);
            hn::Store(x, d, batch.cx[k] + g);
            hn::Store(y, d, batch.cy[k] + g);
            hn::Store(z, d, batch.cz[k] + g);
            hn::Store(w, d, batch.cw[k] + g);
        }
}

void TransformBatch(const TriangleInput& in, TriangleBatch& batch) { TransformBatchWith<false>(in, batch); }
void TransformBatchPlain(const TriangleInput& in, TriangleBatch& batch) { TransformBatchWith<true>(in, batch); }

void ClassifyBatch(Backface backface, double near_w, TriangleBatch& batch, RasterStats& stats) {
    const D d;
    const int lanes = int(hn::Lanes(d));
    const V zero = hn::Zero(d);
    batch.needs_setup = 0;
    batch.simple = 0;
    for (int g = 0; g < batch.count; g += lanes) {
        const M live = hn::FirstN(d, std::size_t(batch.count - g));
        M finite, outside, unsettled, away;
        V det;
        ClipFates(d, backface, near_w, hn::Load(d, batch.cx[0] + g), hn::Load(d, batch.cy[0] + g), hn::Load(d, batch.cw[0] + g),
                  hn::Load(d, batch.cx[1] + g), hn::Load(d, batch.cy[1] + g), hn::Load(d, batch.cw[1] + g), hn::Load(d, batch.cx[2] + g),
                  hn::Load(d, batch.cy[2] + g), hn::Load(d, batch.cw[2] + g), finite, outside, unsettled, det, away);

        // The fates in unclipped_fate's order of precedence, each live lane in exactly one.
        const std::uint8_t index_bits[8] = {std::uint8_t(batch.indices_valid >> g)};
        const M invalid = hn::And(live, hn::Not(hn::And(finite, hn::LoadMaskBits(d, index_bits))));
        const M valid = hn::AndNot(invalid, live);
        const M out = hn::And(valid, outside);
        const M open = hn::AndNot(hn::Or(outside, unsettled), valid);  // neither decided nor set up
        const M degenerate = hn::And(open, hn::Eq(det, zero));
        const M backfacing = hn::And(hn::AndNot(degenerate, open), away);
        stats.invalid += hn::CountTrue(d, invalid);
        stats.outside += hn::CountTrue(d, out);
        stats.degenerate += hn::CountTrue(d, degenerate);
        stats.backface_culled += hn::CountTrue(d, backfacing);
        batch.needs_setup |= LaneBits(d, hn::AndNot(hn::Or(hn::Or(invalid, out), hn::Or(degenerate, backfacing)), live)) << g;
        batch.simple |= LaneBits(d, hn::AndNot(hn::Or(degenerate, backfacing), open)) << g;
    }
}

// beyond_side_plane_reference, lane by lane: the same operations (the largest |model
// coordinate| of the lane's corners, the margins scale * p, the differences x - w and
// -x - w against them).
std::uint32_t BeyondSidePlane(const TriangleBatch& batch, int count, double scale_x, double scale_y) {
    const D d;
    const int lanes = int(hn::Lanes(d));
    const V infinity = hn::Set(d, HUGE_VAL);
    std::uint32_t bits = 0;
    for (int g = 0; g < count; g += lanes) {
        const std::uint8_t index_bits[8] = {std::uint8_t(batch.indices_valid >> g)};
        const M valid = hn::And(hn::FirstN(d, std::size_t(count - g)), hn::LoadMaskBits(d, index_bits));
        V p = hn::Zero(d);
        for (int k = 0; k < 3; ++k)
            p = hn::Max(p, hn::Max(hn::Max(hn::Abs(hn::Load(d, batch.px[k] + g)), hn::Abs(hn::Load(d, batch.py[k] + g))),
                                   hn::Max(hn::Abs(hn::Load(d, batch.pz[k] + g)), hn::Abs(hn::Load(d, batch.pw[k] + g)))));
        const V margin_x = hn::Mul(hn::Set(d, scale_x), p), margin_y = hn::Mul(hn::Set(d, scale_y), p);
        M finite = valid, right = valid, left = valid, above = valid, below = valid;
        for (int k = 0; k < 3; ++k) {
            const V x = hn::Load(d, batch.cx[k] + g), y = hn::Load(d, batch.cy[k] + g), w = hn::Load(d, batch.cw[k] + g);
            finite = hn::And(finite, hn::And(hn::And(hn::Lt(hn::Abs(x), infinity), hn::Lt(hn::Abs(y), infinity)), hn::Lt(hn::Abs(w), infinity)));
            right = hn::And(right, hn::Gt(hn::Sub(x, w), margin_x));
            left = hn::And(left, hn::Gt(hn::Sub(hn::Neg(x), w), margin_x));
            above = hn::And(above, hn::Gt(hn::Sub(y, w), margin_y));
            below = hn::And(below, hn::Gt(hn::Sub(hn::Neg(y), w), margin_y));
        }
        bits |= LaneBits(d, hn::And(finite, hn::Or(hn::Or(right, left), hn::Or(above, below)))) << g;
    }
    return bits;
}

// prepare_float_row_edges for edge k of lanes [g, g + lanes), as a silhouette edge (threshold
// edge_threshold(false, ...)): the same double operations lane by lane. Returns the lanes it
// accepts.
HWY_INLINE M FloatRowEdge(int k, int g, V ox, V oy, V sa, V sb, V inverse_sa, double edge_margin, V i0, V i1, BatchSetup& out) {
    const D d;
    const hn::Rebind<float, D> df;
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
    const V threshold = hn::Mul(hn::Set(d, edge_margin), hn::Add(hn::Abs(sa), hn::Abs(sb)));
    const V limit = hn::Set(d, 0x1.0p22);
    const M in_range = hn::And(hn::Lt(hn::Abs(ox), limit), hn::Lt(hn::Abs(oy), limit));
    const V ox_int = hn::Floor(ox), oy_int = hn::Floor(oy);
    const V slope = hn::Mul(sb, inverse_sa), offset = hn::Mul(threshold, inverse_sa);
    const V reach = hn::Add(hn::Max(hn::Abs(hn::Sub(ox, hn::Sub(i0, hn::Set(d, 3.0)))), hn::Abs(hn::Sub(ox, hn::Add(i1, hn::Set(d, 3.0))))), one);
    const V error = hn::Mul(hn::Set(d, 0x1.0p-20), hn::Add(hn::Add(hn::Add(reach, hn::Abs(slope)), hn::Abs(offset)), hn::Set(d, 2.0)));
    const M lower = hn::Gt(sa, zero);
    const V h = hn::IfThenElse(lower, hn::Sub(half, error), hn::Add(half, error));
    hn::Store(hn::DemoteTo(df, oy_int), df, out.row_origin[k] + g);
    hn::Store(hn::DemoteTo(df, hn::Sub(hn::Sub(oy, oy_int), half)), df, out.y_offset[k] + g);
    hn::Store(hn::DemoteTo(df, slope), df, out.slope[k] + g);
    hn::Store(hn::DemoteTo(df, hn::Sub(hn::Add(hn::Sub(ox, ox_int), offset), h)), df, out.base[k] + g);
    hn::Store(hn::DemoteTo(df, hn::Sub(hn::Sub(i0, hn::Set(d, 2.0)), ox_int)), df, out.lo_clamp[k] + g);
    hn::Store(hn::DemoteTo(df, hn::Sub(hn::Add(i1, hn::Set(d, 2.0)), ox_int)), df, out.hi_clamp[k] + g);
    hn::Store(hn::DemoteTo(df, hn::IfThenElse(lower, hn::Add(ox_int, one), hn::Sub(ox_int, one))), df, out.column_shift[k] + g);
    return hn::AndNot(hn::Eq(sa, zero), hn::And(in_range, hn::Le(error, hn::Set(d, 0x1.0p-8))));
}

// setup_clip_triangle's projection of an unclipped triangle and the parts of
// setup_raster_triangle's double work that do not need the edges (orient_triangle,
// sample_span, depth_plane_terms, finish_depth_plane), lane by lane with the same operations
// in the same order; then nearest_conservative_depth over each lane's sample box, with
// conservative_depth's float operations.
void SetupPlanes(const TriangleBatch& batch, int sample_width, int sample_height, BatchSetup& out) {
    const D d;
    const hn::Rebind<std::int32_t, D> di;
    const hn::Rebind<float, D> df;
    const int lanes = int(hn::Lanes(d));
    const V one = hn::Set(d, 1.0), half = hn::Set(d, 0.5), zero = hn::Zero(d), minus_one = hn::Set(d, -1.0);
    const V width = hn::Set(d, double(sample_width)), height = hn::Set(d, double(sample_height));
    out.flipped = 0;
    out.has_plane = 0;
    for (int g = 0; g < batch.count; g += lanes) {
        // Projection to the sample grid, depth 1/w. (No arrays of vectors: SVE vectors cannot
        // be array elements.)
        auto project = [&](int k, V& x, V& y, V& depth) {
            const V inv_w = hn::Div(one, hn::Load(d, batch.cw[k] + g));
            x = hn::Mul(hn::Mul(hn::Add(hn::Mul(hn::Load(d, batch.cx[k] + g), inv_w), one), half), width);
            y = hn::Mul(hn::Mul(hn::Sub(one, hn::Mul(hn::Load(d, batch.cy[k] + g), inv_w)), half), height);
            depth = inv_w;
        };
        V x0 = zero, y0 = zero, d0 = zero, px1 = zero, py1 = zero, pd1 = zero, px2 = zero, py2 = zero, pd2 = zero;
        project(0, x0, y0, d0);
        project(1, px1, py1, pd1);
        project(2, px2, py2, pd2);
        // orient_triangle: counter-clockwise, swapping vertices 1 and 2 when the area is negative.
        const V area2 = hn::Sub(hn::Mul(hn::Sub(px1, x0), hn::Sub(py2, y0)), hn::Mul(hn::Sub(py1, y0), hn::Sub(px2, x0)));
        const M flip = hn::Lt(area2, zero);
        out.flipped |= LaneBits(d, flip) << g;
        const V x1 = hn::IfThenElse(flip, px2, px1), x2 = hn::IfThenElse(flip, px1, px2);
        const V y1 = hn::IfThenElse(flip, py2, py1), y2 = hn::IfThenElse(flip, py1, py2);
        const V d1 = hn::IfThenElse(flip, pd2, pd1), d2 = hn::IfThenElse(flip, pd1, pd2);
        const V area = hn::IfThenElse(flip, hn::Neg(area2), area2);
        hn::Store(area, d, out.area2 + g);
        hn::Store(x0, d, out.x[0] + g);
        hn::Store(x1, d, out.x[1] + g);
        hn::Store(x2, d, out.x[2] + g);
        hn::Store(y0, d, out.y[0] + g);
        hn::Store(y1, d, out.y[1] + g);
        hn::Store(y2, d, out.y[2] + g);

        // sample_span of the bounding box (min and max are exact).
        auto span = [&](V lo, V hi, V count, std::int32_t* first, std::int32_t* last) {
            const V top = hn::Add(count, one);
            lo = hn::Min(hn::Max(lo, minus_one), top);
            hi = hn::Min(hn::Max(hi, minus_one), top);
            hn::Store(hn::Max(hn::DemoteTo(di, hn::Ceil(hn::Sub(lo, half))), hn::Zero(di)), di, first + g);
            hn::Store(hn::Min(hn::DemoteTo(di, hn::Floor(hn::Sub(hi, half))), hn::Sub(hn::DemoteTo(di, count), hn::Set(di, 1))), di,
                      last + g);
        };
        span(hn::Min(hn::Min(x0, x1), x2), hn::Max(hn::Max(x0, x1), x2), width, out.i0, out.i1);
        span(hn::Min(hn::Min(y0, y1), y2), hn::Max(hn::Max(y0, y1), y2), height, out.j0, out.j1);

        // depth_plane_terms.
        const V dzdx = hn::Div(hn::Sub(hn::Mul(hn::Sub(d1, d0), hn::Sub(y2, y0)), hn::Mul(hn::Sub(d2, d0), hn::Sub(y1, y0))), area);
        const V dzdy = hn::Div(hn::Sub(hn::Mul(hn::Sub(d2, d0), hn::Sub(x1, x0)), hn::Mul(hn::Sub(d1, d0), hn::Sub(x2, x0))), area);
        const V a = hn::Sub(hn::Sub(d0, hn::Mul(dzdx, x0)), hn::Mul(dzdy, y0));
        const V magnitude = hn::Add(hn::Add(hn::Abs(a), hn::Mul(hn::Abs(dzdx), width)), hn::Mul(hn::Abs(dzdy), height));
        const V terms = hn::Add(hn::Add(hn::Abs(d0), hn::Abs(hn::Mul(dzdx, x0))), hn::Abs(hn::Mul(dzdy, y0)));
        const V error = hn::Add(hn::Add(hn::Mul(hn::Set(d, 0x1.0p-20), magnitude), hn::Mul(hn::Set(d, 0x1.0p-40), terms)), hn::Set(d, 0x1.0p-126));
        // finish_depth_plane: the plane in float where it is usable, else none.
        const M usable = hn::And(hn::Lt(hn::Abs(error), hn::Set(d, HUGE_VAL)), hn::Lt(magnitude, hn::Set(d, 0x1.0p100)));
        const auto usable_f = FloatLaneMask(D(), usable);
        const auto a_f = hn::IfThenElseZero(usable_f, hn::DemoteTo(df, a));
        const auto dzdx_f = hn::IfThenElseZero(usable_f, hn::DemoteTo(df, dzdx));
        const auto dzdy_f = hn::IfThenElseZero(usable_f, hn::DemoteTo(df, dzdy));
        const auto error_f = hn::IfThenElseZero(usable_f, FloatOutward<true>(D(), hn::IfThenElseZero(usable, error)));
        const auto z_vertex_min = FloatOutward<false>(D(), hn::Min(hn::Min(d0, d1), d2));
        hn::Store(a_f, df, out.plane_a + g);
        hn::Store(dzdx_f, df, out.plane_dzdx + g);
        hn::Store(dzdy_f, df, out.plane_dzdy + g);
        hn::Store(error_f, df, out.plane_error + g);
        hn::Store(z_vertex_min, df, out.z_vertex_min + g);
        out.has_plane |= LaneBits(d, usable) << g;

        // nearest_conservative_depth over the box [i0, i1] x [j0, j1]: conservative_depth at the
        // corner opposite the plane's far corner (set_far_corner), in the same float operations.
        const auto zero_f = hn::Zero(df), half_f = hn::Set(df, 0.5f);
        const auto column = hn::IfThenElse(hn::RebindMask(di, hn::Gt(dzdx_f, zero_f)), hn::Load(di, out.i1 + g), hn::Load(di, out.i0 + g));
        const auto row = hn::IfThenElse(hn::RebindMask(di, hn::Gt(dzdy_f, zero_f)), hn::Load(di, out.j1 + g), hn::Load(di, out.j0 + g));
        const auto x = hn::Add(hn::ConvertTo(df, column), half_f), y = hn::Add(hn::ConvertTo(df, row), half_f);
        const auto plane = hn::Add(hn::Add(a_f, hn::Mul(dzdy_f, y)), hn::Mul(dzdx_f, x));
        const auto bound = hn::Max(hn::Sub(plane, error_f), z_vertex_min);
        hn::Store(hn::Mul(bound, hn::Set(df, 1.0f - 0x1.0p-20f)), df, out.nearest + g);
    }
}

// setup_raster_triangle's edge_functions and prepare_float_row_edges for the lanes of
// `lanes` (whole vectors of them: the others compute too, and their results go unused), from
// SetupPlanes' oriented vertices and sample box.
void SetupEdges(int count, double edge_margin, std::uint32_t silhouette_only, std::uint32_t lanes_wanted, BatchSetup& out) {
    const D d;
    const hn::Rebind<std::int32_t, D> di;
    const int lanes = int(hn::Lanes(d));
    const V one = hn::Set(d, 1.0), zero = hn::Zero(d), minus_one = hn::Set(d, -1.0);
    out.float_ready = 0;
    for (int g = 0; g < count; g += lanes) {
        const std::uint32_t group = (1u << lanes) - 1u;  // lanes <= 8
        if (((lanes_wanted >> g) & group) == 0) continue;
        const V i0 = hn::PromoteTo(d, hn::Load(di, out.i0 + g)), i1 = hn::PromoteTo(d, hn::Load(di, out.i1 + g));
        const bool any_float = ((silhouette_only >> g) & group) != 0;
        M float_ready = hn::FirstN(d, any_float ? std::size_t(lanes) : 0);

        // edge_functions: edge k from vertex k to vertex k + 1, measured from its lower end (by
        // y, then x), its normal signed to be positive inside.
        auto edge = [&](int k, V fx, V fy, V tx, V ty) {
            const M vertical_order = hn::Ne(fy, ty);
            const M forward = hn::Or(hn::And(vertical_order, hn::Lt(fy, ty)), hn::AndNot(vertical_order, hn::Lt(fx, tx)));
            const V lo_x = hn::IfThenElse(forward, fx, tx), lo_y = hn::IfThenElse(forward, fy, ty);
            const V hi_x = hn::IfThenElse(forward, tx, fx), hi_y = hn::IfThenElse(forward, ty, fy);
            const V sign = hn::IfThenElse(forward, one, minus_one);
            const V sa = hn::Mul(sign, hn::Neg(hn::Sub(hi_y, lo_y))), sb = hn::Mul(sign, hn::Sub(hi_x, lo_x));
            hn::Store(lo_x, d, out.ox[k] + g);
            hn::Store(lo_y, d, out.oy[k] + g);
            hn::Store(sa, d, out.sa[k] + g);
            hn::Store(sb, d, out.sb[k] + g);
            const V inverse_sa = hn::IfThenElse(hn::Eq(sa, zero), zero, hn::Div(one, sa));
            hn::Store(inverse_sa, d, out.inverse_sa[k] + g);
            if (any_float) float_ready = hn::And(float_ready, FloatRowEdge(k, g, lo_x, lo_y, sa, sb, inverse_sa, edge_margin, i0, i1, out));
        };
        const V x0 = hn::Load(d, out.x[0] + g), x1 = hn::Load(d, out.x[1] + g), x2 = hn::Load(d, out.x[2] + g);
        const V y0 = hn::Load(d, out.y[0] + g), y1 = hn::Load(d, out.y[1] + g), y2 = hn::Load(d, out.y[2] + g);
        edge(0, x0, y0, x1, y1);
        edge(1, x1, y1, x2, y2);
        edge(2, x2, y2, x0, y0);
        out.float_ready |= LaneBits(d, float_ready) << g;
    }
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "raster/raster_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(TransformVertices);
HWY_EXPORT(TransformBatch);
HWY_EXPORT(TransformBatchPlain);
HWY_EXPORT(GatherDirectBatch);
HWY_EXPORT(ClassifyBatch);
HWY_EXPORT(SetupPlanes);
HWY_EXPORT(SetupEdges);
HWY_EXPORT(BeyondSidePlane);

void resolve_front_end_kernels(const IsaChoice& choice, RasterKernels& k) {
    if (choice.scalar) {
        k.front_end = {&transform_vertices_reference, &transform_batch_reference, &classify_batch_reference, nullptr, nullptr, nullptr,
                       &beyond_side_plane_reference, &transform_batch_plain_reference, nullptr};
        return;
    }
    k.front_end = {HOMCULL_KERNEL_FOR(choice, TransformVertices), HOMCULL_KERNEL_FOR(choice, TransformBatch), HOMCULL_KERNEL_FOR(choice, ClassifyBatch),
                   HOMCULL_KERNEL_FOR(choice, SetupPlanes),       HOMCULL_KERNEL_FOR(choice, SetupEdges),     HOMCULL_KERNEL_FOR(choice, GatherDirectBatch),
                   HOMCULL_KERNEL_FOR(choice, BeyondSidePlane),   HOMCULL_KERNEL_FOR(choice, TransformBatchPlain),
                   margin_free_kernel_for(choice)};
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
