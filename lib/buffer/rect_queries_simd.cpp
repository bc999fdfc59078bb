// The batched rectangle tests (detail::BufferState::test_rects) and the exact scan of one
// rectangle, compiled per instruction set with Google Highway and chosen at run time.
// - The coarse stage runs one rectangle per SIMD lane. Each lane repeats what
//   detail::BufferState::prepare and the coarse check at the start of detail::BufferState::test_rect do
//   for its rectangle, with the same double and float operations, so it decides exactly the
//   rectangles they decide there, with the same answers. On S1 about three in four are decided
//   here.
// - The others are packed with the query computed here and go on to the exact scan (ScanRect),
//   which the single test_rect's kernel (TestOneRect) and the prepared one's also run.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "buffer/rect_queries_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "buffer/buffer_state.hpp"
#include "buffer/rect_queries.hpp"
#include "common/lane_bits-inl.h"
#include "raster/rasterize.hpp"

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace homcull::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The open rectangles of a block, packed by the coarse stage: their positions in the block
// and their queries, field by field (vector stores; CompressStore may write a whole vector
// past the last one, hence the padding).
struct OpenRects {
    static constexpr std::size_t kPadding = 16;
    std::int32_t index[kRectBlock + kPadding], i0[kRectBlock + kPadding], i1[kRectBlock + kPadding], j0[kRectBlock + kPadding],
        j1[kRectBlock + kPadding];
    float d_near[kRectBlock + kPadding];
};

// The coarse stage for rectangles [0, count), count <= kRectBlock: results[k] for the ones it
// decides, and the others packed into `open`; returns how many are open.
HWY_INLINE std::size_t CoarseRectTests(const CoarseRectView& view, const ScreenRect* rects, std::size_t count, Visibility* results,
                                       OpenRects& open_rects) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    const hn::CappedTag<double, 8> dd;  // one rectangle per double lane
    const hn::Rebind<float, decltype(dd)> df;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    const hn::Rebind<std::uint32_t, decltype(dd)> du;
    using VD = hn::Vec<decltype(dd)>;
    using VF = hn::Vec<decltype(df)>;
    using VI = hn::Vec<decltype(di)>;
    const std::size_t lanes = hn::Lanes(dd);

    const VD one = hn::Set(dd, 1.0), half = hn::Set(dd, 0.5), minus_one = hn::Set(dd, -1.0);
    const VD width = hn::Set(dd, double(view.sample_width)), height = hn::Set(dd, double(view.sample_height));
    const VF infinity = hn::Set(df, INFINITY), one_f = hn::Set(df, 1.0f), minus_one_f = hn::Set(df, -1.0f);
    const VI code_visible = hn::Set(di, int(Visibility::visible)), code_occluded = hn::Set(di, int(Visibility::occluded));
    const VI code_view_culled = hn::Set(di, int(Visibility::view_culled)), code_undecided = hn::Set(di, kUndecided);

    // The lanes' answers into results[base, base + n): one vector store for a whole vector.
    static_assert(sizeof(Visibility) == 1, "answers are bytes");
    const hn::Rebind<std::uint8_t, decltype(di)> d8;
    const auto store_codes = [&](VI code, std::size_t base, std::size_t n) {
        const auto bytes = hn::DemoteTo(d8, code);  // codes are 0..2 and kUndecided: exact
        if (n == lanes) {
            hn::StoreU(bytes, d8, reinterpret_cast<std::uint8_t*>(results + base));
            return;
        }
        HWY_ALIGN std::uint8_t out[8];
        hn::Store(bytes, d8, out);
        for (std::size_t k = 0; k < n; ++k) results[base + k] = Visibility(out[k]);
    };
    std::size_t open_count = 0;
    const VI lane_index = hn::Iota(di, 0);  // once: Highway's Iota goes through memory
    static_assert(sizeof(ScreenRect) == 5 * sizeof(float), "rectangles are 5 packed floats");
    const VI field_stride = hn::Mul(hn::Iota(di, 0), hn::Set(di, 5));  // lane k reads rectangle k's fields
    for (std::size_t base = 0; base < count; base += lanes) {
        const std::size_t n = std::min(lanes, count - base);
        // To structure of arrays by gathers (scalar stores and a vector load stall on store
        // forwarding); missing lanes read rectangle 0 of the block.
        const VI index = hn::IfThenElseZero(hn::FirstN(di, n), field_stride);
        const float* fields = &rects[base].ndc_min_x;
        const VF min_x = hn::GatherIndex(df, fields, index), min_y = hn::GatherIndex(df, fields + 1, index);
        const VF max_x = hn::GatherIndex(df, fields + 2, index), max_y = hn::GatherIndex(df, fields + 3, index);
        const VF w_min = hn::GatherIndex(df, fields + 4, index);

        // prepare(): invalid input and the near plane (visible), outside the frustum.
        auto finite = hn::And(hn::And(hn::Lt(hn::Abs(min_x), infinity), hn::Lt(hn::Abs(min_y), infinity)),
                              hn::And(hn::Lt(hn::Abs(max_x), infinity), hn::Lt(hn::Abs(max_y), infinity)));
        finite = hn::And(finite, hn::Lt(hn::Abs(w_min), infinity));
        const auto valid = hn::And(finite, hn::And(hn::Ge(max_x, min_x), hn::Ge(max_y, min_y)));
        const auto visible = hn::Or(hn::Not(valid), hn::Lt(w_min, hn::Set(df, view.near_w)));
        const auto outside = hn::Or(hn::Or(hn::Lt(max_x, minus_one_f), hn::Gt(min_x, one_f)),
                                    hn::Or(hn::Lt(max_y, minus_one_f), hn::Gt(min_y, one_f)));
        VI code = hn::IfThenElse(hn::RebindMask(di, visible), code_visible,
                                 hn::IfThenElse(hn::RebindMask(di, outside), code_view_culled, code_undecided));

        // The samples whose centres lie in the rectangle (sample_span, clamped the same way).
        const VD sx0 = hn::Mul(hn::Mul(hn::Add(hn::PromoteTo(dd, min_x), one), half), width);
        const VD sx1 = hn::Mul(hn::Mul(hn::Add(hn::PromoteTo(dd, max_x), one), half), width);
        const VD sy0 = hn::Mul(hn::Mul(hn::Sub(one, hn::PromoteTo(dd, max_y)), half), height);
        const VD sy1 = hn::Mul(hn::Mul(hn::Sub(one, hn::PromoteTo(dd, min_y)), half), height);
        const auto span = [&](VD lo, VD hi, VD count_d, VI& first, VI& last) {
            const VD top = hn::Add(count_d, one);
            lo = hn::Min(hn::Max(lo, minus_one), top);
            hi = hn::Min(hn::Max(hi, minus_one), top);
            first = hn::Max(hn::DemoteTo(di, hn::Ceil(hn::Sub(lo, half))), hn::Zero(di));
            last = hn::Min(hn::DemoteTo(di, hn::Floor(hn::Sub(hi, half))), hn::Sub(hn::DemoteTo(di, count_d), hn::Set(di, 1)));
        };
        // (Invalid lanes may hold NaN here: their spans are garbage, but they are decided, and
        // their indices are zeroed before the gathers below.)
        VI i0, i1, j0, j1;
        span(sx0, sx1, width, i0, i1);
        span(sy0, sy1, height, j0, j1);
        const auto empty = hn::Or(hn::Gt(i0, i1), hn::Gt(j0, j1));
        code = hn::IfThenElse(hn::And(empty, hn::Eq(code, code_undecided)), code_occluded, code);

        // Nearest 1/w, rounded up and raised by a relative 2^-20.
        const VD d = hn::Div(one, hn::PromoteTo(dd, w_min));
        const VF f = hn::DemoteTo(df, d);
        const VF f_up = hn::BitCast(df, hn::Add(hn::BitCast(du, f), hn::Set(du, 1u)));
        const VF d_near = hn::Mul(hn::DemoteTo(df, hn::IfThenElse(hn::Lt(hn::PromoteTo(dd, f), d), hn::PromoteTo(dd, f_up), hn::PromoteTo(dd, f))),
                                  hn::Set(df, 1.0f + 0x1.0p-20f));

        // The coarse check, for the lanes still undecided (the others read cell 0).
        const auto open = hn::Eq(code, code_undecided);
        if (hn::AllFalse(di, open)) {
            store_codes(code, base, n);
            continue;
        }
        const VI tx0 = hn::IfThenElseZero(open, hn::ShiftRight<3>(i0)), tx1 = hn::IfThenElseZero(open, hn::ShiftRight<3>(i1));
        const VI ty0 = hn::IfThenElseZero(open, hn::ShiftRight<2>(j0)), ty1 = hn::IfThenElseZero(open, hn::ShiftRight<2>(j1));
        static_assert(kW == 8 && kH == 4, "the shifts above divide by the subtile size");
        // The level where the subtile range spans at most 2 x 2 cells: the count of levels where
        // it spans more, which is monotone in the level. Every level is visited: an exit when no
        // lane spans more was a branch mispredicted often enough to cost more (1.4 % of S1's
        // batch, seven interleaved rounds).
        VI level = hn::Zero(di);
        for (int l = 0; l + 1 < view.levels; ++l) {
            const auto wider = hn::Or(hn::Gt(hn::Sub(hn::ShiftRightSame(tx1, l), hn::ShiftRightSame(tx0, l)), hn::Set(di, 1)),
                                      hn::Gt(hn::Sub(hn::ShiftRightSame(ty1, l), hn::ShiftRightSame(ty0, l)), hn::Set(di, 1)));
            level = hn::Add(level, hn::IfThenElseZero(wider, hn::Set(di, 1)));
        }
        const VI offset = hn::GatherIndex(di, view.level_offset, level), row = hn::GatherIndex(di, view.level_width, level);
        const VI cx0 = hn::Shr(tx0, level), cx1 = hn::Shr(tx1, level), cy0 = hn::Shr(ty0, level), cy1 = hn::Shr(ty1, level);
        const VI row0 = hn::Add(offset, hn::Mul(cy0, row)), row1 = hn::Add(offset, hn::Mul(cy1, row));
        const VF coarse = hn::Min(hn::Min(hn::GatherIndex(df, view.pyramid, hn::Add(row0, cx0)), hn::GatherIndex(df, view.pyramid, hn::Add(row0, cx1))),
                                  hn::Min(hn::GatherIndex(df, view.pyramid, hn::Add(row1, cx0)), hn::GatherIndex(df, view.pyramid, hn::Add(row1, cx1))));
        code = hn::IfThenElse(hn::And(open, hn::RebindMask(di, hn::Lt(d_near, coarse))), code_occluded, code);
        store_codes(code, base, n);  // the open ones' are overwritten by the scan
        // Pack the lanes still open; lanes past n (which read rectangle `base`) are left out.
        const auto still_open = hn::And(hn::Eq(code, code_undecided), hn::FirstN(di, n));
        hn::CompressStore(hn::Add(lane_index, hn::Set(di, std::int32_t(base))), still_open, di, open_rects.index + open_count);
        hn::CompressStore(i0, still_open, di, open_rects.i0 + open_count);
        hn::CompressStore(i1, still_open, di, open_rects.i1 + open_count);
        hn::CompressStore(j0, still_open, di, open_rects.j0 + open_count);
        hn::CompressStore(j1, still_open, di, open_rects.j1 + open_count);
        open_count += hn::CompressStore(d_near, hn::RebindMask(df, still_open), df, open_rects.d_near + open_count);
    }
    return open_count;
}

// The exact stage on the subtiles [sx0, sx1] x [sy0, sy1] of the rectangle, a vector of
// subtiles of a row at a time: false when one shows it. Every lane computes what
// subtile_unhidden_samples computes for its subtile, without a branch: the samples of the
// subtile in the rectangle (a byte of sample columns per lane, repeated over the sample rows the
// rectangle covers there), shown where d_near is not below d0 and, in the working layer's mask,
// not below max(d0, d1). One branch per row and vector, taken when some lane shows the
// rectangle: a branch per showing subtile was mispredicted about as often as not.
HWY_INLINE bool SubtilesHide(const SubtileView& view, const RectQuery& q, int sx0, int sx1, int sy0, int sy1) {
    constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;
    static_assert(kW == 8 && kH == 4, "a subtile's samples are 4 rows of a byte");
    const hn::CappedTag<float, kMaxSimdLanes> df;  // rows are padded for this many (rasterize.hpp)
    const hn::RebindToSigned<decltype(df)> di;
    const hn::RebindToUnsigned<decltype(df)> du;
    const int lanes = int(hn::Lanes(df));
    const auto d_near = hn::Set(df, q.d_near);
    const auto lane_first_sample = hn::ShiftLeft<3>(hn::Iota(di, 0));  // once: Highway's Iota goes through memory
    const auto byte = hn::Set(du, 0xFFu);
    for (int tx = sx0; tx <= sx1; tx += lanes) {
        // The sample columns [lo, hi] of each lane's subtile in the rectangle. Lanes past sx1 read
        // the row's padding or its next subtiles: their hi is clamped to -1 (no column).
        const auto first = hn::Sub(hn::Set(di, q.i0 - tx * kW), lane_first_sample);
        const auto last = hn::Sub(hn::Set(di, std::min(q.i1, sx1 * kW + kW - 1) - tx * kW), lane_first_sample);
        const auto lo = hn::BitCast(du, hn::Max(first, hn::Zero(di)));
        const auto hi = hn::BitCast(du, hn::Min(hn::Max(last, hn::Set(di, -1)), hn::Set(di, kW - 1)));
        const auto columns = hn::And(hn::Shl(byte, lo), hn::Shr(byte, hn::Sub(hn::Set(du, kW - 1), hi)));
        const auto column_rows = hn::Or(columns, hn::ShiftLeft<8>(columns));
        const auto all_rows = hn::Or(column_rows, hn::ShiftLeft<16>(column_rows));
        for (int ty = sy0; ty <= sy1; ++ty) {
            const int r0 = std::max(0, q.j0 - ty * kH), r1 = std::min(kH - 1, q.j1 - ty * kH);
            const std::uint32_t rows = (0xFFFFFFFFu << (kW * r0)) & (0xFFFFFFFFu >> (kW * (kH - 1 - r1)));
            const std::size_t at = std::size_t(ty) * view.stride + std::size_t(tx);
            const auto d0 = hn::LoadU(df, view.d0 + at);
            const auto layer = hn::LoadU(du, view.mask + at);
            const auto samples = hn::And(all_rows, hn::Set(du, rows));
            const auto above_d0 = hn::RebindMask(du, hn::Lt(d_near, d0));
            const auto above_layers = hn::RebindMask(du, hn::Lt(d_near, hn::Max(d0, hn::LoadU(df, view.d1 + at))));
            const auto shown = hn::IfThenZeroElse(above_d0, hn::IfThenElse(above_layers, hn::AndNot(layer, samples), samples));
            if (!hn::AllTrue(du, hn::Eq(shown, hn::Zero(du)))) return false;
        }
    }
    return true;
}

// The exact stage: occluded when every subtile the rectangle reaches hides it. Rectangles of
// more than 16 subtile rows first read the farthest-d0 pyramid's cells of kCellLevel (4 x 4
// subtiles): a cell whose minimum d0 is above d_near hides the rectangle wherever it reaches
// it, and only the others are scanned subtile by subtile (Greene's pruned search, one level
// deep and a vector of cells at a time). Shorter ones are scanned row by row at once: on S1,
// reading cells first was slower below 16 rows (4 rows: 7 % fewer single calls a second at
// 640x360). Same answers as test_rect_exhaustive.
HWY_INLINE Visibility ScanRect(const SubtileView& view, const RectQuery& q) {
    constexpr int kCellLevel = 2, kCell = 1 << kCellLevel;
    const auto [tx0, tx1, ty0, ty1] = subtile_range(q);
    constexpr int kDirectRows = 16;
    if (ty1 - ty0 < kDirectRows || view.level_count <= kCellLevel)
        return SubtilesHide(view, q, tx0, tx1, ty0, ty1) ? Visibility::occluded : Visibility::visible;

    const hn::CappedTag<float, kMaxSimdLanes> df;
    const int lanes = int(hn::Lanes(df));
    const auto d_near = hn::Set(df, q.d_near);
    const PyramidLevel& level = view.levels[kCellLevel];
    const int cx0 = tx0 >> kCellLevel, cx1 = tx1 >> kCellLevel;
    for (int cy = ty0 >> kCellLevel; cy <= ty1 >> kCellLevel; ++cy) {
        const float* row = view.pyramid + level.offset + std::size_t(cy) * std::size_t(level.width);
        const int sy0 = std::max(ty0, cy * kCell), sy1 = std::min(ty1, cy * kCell + kCell - 1);
        for (int cx = cx0; cx <= cx1; cx += lanes) {
            // Lanes past cx1 read the next row or the pyramid's padding: masked out.
            const auto reached = hn::FirstN(df, std::size_t(cx1 - cx + 1));
            const auto open = hn::And(reached, hn::Not(hn::Lt(d_near, hn::LoadU(df, row + cx))));
            if (hn::AllFalse(df, open)) continue;
            // The subtiles from the first open cell to the last, in one scan: the closed cells
            // between them hide the rectangle in every lane, and a branch per open cell was
            // mispredicted about as often as not.
            const std::uint32_t bits = LaneBits(df, open);
            const int first = cx + __builtin_ctz(bits), last = cx + 31 - __builtin_clz(bits);
            if (!SubtilesHide(view, q, std::max(tx0, first * kCell), std::min(tx1, last * kCell + kCell - 1), sy0, sy1))
                return Visibility::visible;
        }
    }
    return Visibility::occluded;
}

// prepare_rect for a rectangle that needs the buffer, in SIMD lanes: false for those it leaves
// to prepare_rect (invalid, before the near plane, outside the view: one branch for all, rarely
// taken), else the query prepare_rect makes, with the same double operations (a pair of lanes
// per axis: x's (min, max), y's (max, min), both giving (first, last) samples), which the
// rectangle's empty span checks afterwards.
HWY_INLINE bool PrepareRectInLanes(const CoarseRectView& view, const ScreenRect& rect, RectQuery& q) {
#if HWY_TARGET == HWY_SCALAR  // one lane: prepare_rect does it all (a kernel the scalar choice never runs)
    (void)view, (void)rect, (void)q;
    return false;
#else
    const hn::FixedTag<float, 4> df;
    const hn::FixedTag<double, 2> dd;
    const hn::Rebind<std::int32_t, decltype(dd)> di;
    static_assert(sizeof(ScreenRect) == 5 * sizeof(float), "rectangles are 5 packed floats");
    const auto bounds = hn::LoadU(df, &rect.ndc_min_x);  // min x, min y, max x, max y
    const auto maxima = hn::Shuffle1032(bounds);           // max x, max y, min x, min y
    const auto finite = hn::Lt(hn::Abs(bounds), hn::Set(df, INFINITY));
    const auto ordered = hn::Or(hn::Le(bounds, maxima), hn::Not(hn::FirstN(df, 2)));  // lanes 0 and 1: min <= max
    // Outside the view: min > 1 (lanes 0, 1) or -max > 1 (lanes 2, 3).
    alignas(16) static constexpr float kSigns[4] = {1.0f, 1.0f, -1.0f, -1.0f};
    const auto inside = hn::Not(hn::Gt(hn::Mul(bounds, hn::Load(df, kSigns)), hn::Set(df, 1.0f)));
    const bool near_enough = std::fabs(rect.w_min) < INFINITY && !(rect.w_min < view.near_w);
    if (!(hn::AllTrue(df, hn::And(hn::And(finite, ordered), inside)) & near_enough)) return false;

    const auto paired = hn::InterleaveLower(df, bounds, maxima);  // min x, max x, min y, max y
    const auto x = hn::PromoteTo(dd, hn::LowerHalf(paired));
    const auto y = hn::Shuffle01(hn::PromoteTo(dd, hn::UpperHalf(hn::Half<decltype(df)>(), paired)));  // max y, min y
    const auto one = hn::Set(dd, 1.0), half = hn::Set(dd, 0.5), minus_one = hn::Set(dd, -1.0);
    const auto width = hn::Set(dd, double(view.sample_width)), height = hn::Set(dd, double(view.sample_height));
    const auto span = [&](hn::Vec<decltype(dd)> edges, hn::Vec<decltype(dd)> count) {  // sample_span, both ends
        edges = hn::Min(hn::Max(edges, minus_one), hn::Add(count, one));
        const auto shifted = hn::Sub(edges, half);
        auto sample = hn::OddEven(hn::Floor(shifted), hn::Ceil(shifted));  // lane 0 first, lane 1 last
        sample = hn::Min(hn::Max(sample, hn::OddEven(hn::Set(dd, -INFINITY), hn::Zero(dd))),
                         hn::OddEven(hn::Sub(count, one), hn::Set(dd, INFINITY)));
        return hn::DemoteTo(di, sample);
    };
    const auto xs = span(hn::Mul(hn::Mul(hn::Add(x, one), half), width), width);
    const auto ys = span(hn::Mul(hn::Mul(hn::Sub(one, y), half), height), height);
    q.i0 = hn::GetLane(xs);
    q.i1 = hn::ExtractLane(xs, 1);
    q.j0 = hn::GetLane(ys);
    q.j1 = hn::ExtractLane(ys, 1);
    q.d_near = nearest_depth_bound(rect.w_min);
    return true;
#endif
}

// Both stages for one rectangle (single test_rect calls): one dispatch, and prepare_rect and
// the coarse check compiled for this instruction set with the scan.
Visibility TestOneRect(const BufferState& buffer, const ScreenRect& rect) {
    const CoarseRectView view = buffer.coarse_view();
    RectQuery q;
    Visibility decided;
    if (!PrepareRectInLanes(view, rect, q)) {
        if (!prepare_rect(view, rect, q, decided)) return decided;
    } else if (q.i0 > q.i1 || q.j0 > q.j1) {
        return Visibility::occluded;  // covers no sample (prepare_rect's answer)
    }
    if (coarse_rect_hides(view, q)) return Visibility::occluded;
    return ScanRect(buffer.subtile_view(), q);
}

// The coarse check and the scan of a prepared rectangle in one dispatch (the occlusion maps'
// box tests, which prepare their rectangles themselves).
Visibility TestPreparedRect(const BufferState& buffer, const RectQuery& q) {
    if (coarse_rect_hides(buffer.coarse_view(), q)) return Visibility::occluded;
    return ScanRect(buffer.subtile_view(), q);
}

// Both stages for a block of rectangles: the coarse stage one rectangle per lane, then the scan
// of the ones it leaves open, which it has packed: no branch per rectangle on whether it is
// open (about one in four on S1, at random: a branch mispredicted that often cost more than
// the packing), and one dispatch per block instead of one per open rectangle.
void TestRectBlock(const CoarseRectView& view, const SubtileView& subtiles, const ScreenRect* rects, std::size_t count,
                   Visibility* results) {
    OpenRects open;
    const std::size_t open_count = CoarseRectTests(view, rects, count, results, open);
    for (std::size_t k = 0; k < open_count; ++k)
        results[open.index[k]] = ScanRect(subtiles, {open.i0[k], open.i1[k], open.j0[k], open.j1[k], open.d_near[k]});
}

}  // namespace homcull::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "buffer/buffer_kernels.hpp"

namespace homcull::detail {

HWY_EXPORT(TestRectBlock);
HWY_EXPORT(TestOneRect);
HWY_EXPORT(TestPreparedRect);

void resolve_rect_query_kernels(const IsaChoice& choice, BufferKernels& k) {
    k.rect_block = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, TestRectBlock);
    k.rect_one = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, TestOneRect);
    k.rect_prepared = choice.scalar ? nullptr : HOMCULL_KERNEL_FOR(choice, TestPreparedRect);
}

}  // namespace homcull::detail
#endif  // HWY_ONCE
