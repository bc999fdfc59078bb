// The reference cells (raster/reference_cells.hpp): their refresh, and the draw order's notes
// that let one thread drop a triangle behind them unread. That the drops change no bit on real
// input is HiddenTriangleSkip.ChangesNoBitOnS1's to show (every instruction set against a render
// without any skip); here, each piece's own promise.
#include "raster/draw_order.hpp"
#include "raster/raster_kernels.hpp"
#include "raster/reference_cells.hpp"
#include "support.hpp"

#include <homcull/occlusion_buffer.hpp>
#include <homcull/tbb_parallel_for.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace homcull::detail {
namespace {

constexpr int kW = OcclusionBuffer::kSubtileWidth, kH = OcclusionBuffer::kSubtileHeight;

// Every cell of the refreshed rows holds the smallest d0 of its subtiles, those of the grid
// only (the rows' padding holds smaller values that must not count); other rows are left alone.
// Each trial plants every cell's smallest value at a random subtile of it, edges included.
TEST(ReferenceCells, RefreshGivesTheSmallestD0OfEachCellOfTheRows) {
    const int subtiles_x = 37, subtiles_y = 21;  // cells of 5 and 5 subtiles at the right and bottom edges
    const std::size_t stride = 64;               // padded rows, as the buffer's
    const int width = reference_cells_width(subtiles_x), height = reference_cells_height(subtiles_y);
    ASSERT_EQ(width, 5);
    ASSERT_EQ(height, 3);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> depth(0.5f, 1.0f);
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<float> d0(stride * std::size_t(subtiles_y), -1.0f);
        for (int ty = 0; ty < subtiles_y; ++ty)
            for (int tx = 0; tx < subtiles_x; ++tx) d0[std::size_t(ty) * stride + std::size_t(tx)] = depth(rng);
        std::vector<float> smallest(std::size_t(width * height));
        for (int cy = 0; cy < height; ++cy)
            for (int cx = 0; cx < width; ++cx) {
                const int tx = std::min(subtiles_x - 1, cx * 8 + int(rng() % 8)), ty = std::min(subtiles_y - 1, cy * 8 + int(rng() % 8));
                smallest[std::size_t(cy * width + cx)] = d0[std::size_t(ty) * stride + std::size_t(tx)] = 0.25f * depth(rng);
            }
        const SubtilePlanes planes{d0.data(), nullptr, nullptr, nullptr, stride, nullptr, 0};
        for (const std::string& isa : available_isas()) {
            const RefreshCellsKernel refresh = raster_kernels(isa_choice(isa)).refresh_cells;
            if (isa == "scalar") {  // the reference sets triangles up one by one, without cells
                EXPECT_EQ(refresh, nullptr);
                continue;
            }
            ASSERT_NE(refresh, nullptr) << isa;
            std::vector<float> cells(std::size_t(width * height), 99.0f);
            refresh(planes, subtiles_x, subtiles_y, 1, 3, {cells.data(), width});
            for (int cy = 0; cy < height; ++cy)
                for (int cx = 0; cx < width; ++cx)
                    ASSERT_EQ(cells[std::size_t(cy * width + cx)], cy == 0 ? 99.0f : smallest[std::size_t(cy * width + cx)])
                        << isa << ", trial " << trial << ", cell " << cx << ", " << cy;
        }
    }
}

// Random clip-space triangles (x, y, z, w floats): small and large, on screen, beyond its sides
// and the guard band, behind the near plane, degenerate, with coordinates not finite, very far.
std::vector<float> random_soup(std::size_t triangles, std::mt19937_64& rng) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), w(0.3f, 60.0f), fraction(0.0f, 1.0f);
    std::vector<float> xyzw(12 * triangles);
    for (std::size_t t = 0; t < triangles; ++t) {
        const float cx = unit(rng) * 1.2f, cy = unit(rng) * 1.2f;
        const float spread = t % 11 == 0 ? 40.0f : t % 5 == 0 ? 0.6f : t % 3 == 0 ? 0.002f : 0.1f;
        float* p = &xyzw[12 * t];
        for (int k = 0; k < 3; ++k) {
            const float wv = t % 17 == 0 ? 1e25f * w(rng) : t % 23 == 0 && k == 1 ? -w(rng) : w(rng);
            p[4 * k + 0] = (cx + unit(rng) * spread) * wv, p[4 * k + 1] = (cy + unit(rng) * spread) * wv;
            p[4 * k + 2] = unit(rng), p[4 * k + 3] = wv;
        }
        if (t % 19 == 0) {  // degenerate: the third vertex on the line through the first two
            const float s = fraction(rng);
            for (int c = 0; c < 4; ++c) p[8 + c] = p[c] + s * (p[4 + c] - p[c]);
        }
        if (t % 29 == 0) p[4 * (t % 3) + t % 4] = std::numeric_limits<float>::quiet_NaN();
        if (t % 31 == 0) p[4 * (t % 3) + 2] = std::numeric_limits<float>::infinity();  // z alone
    }
    return xyzw;
}

// A note promises what drawing the triangle can do: the setup counts it as rasterized (so
// dropping it keeps the statistics), every subtile it covers lies in the noted cells, and every
// depth it writes (d0, d1 and per-sample depth) is at most the noted depth. Checked by drawing
// each noted triangle alone, for every backface mode; the notes are the same on every
// instruction set.
TEST(ReferenceCells, NotesBoundWhatDrawingTheTriangleCanDo) {
    std::mt19937_64 rng(17);
    const std::size_t n = 3000;
    const std::vector<float> xyzw = random_soup(n, rng);
    const int width = 203, height = 117, samples = 2;
    const float near_w = 0.5f;
    OcclusionBuffer alone(test::buffer_config(width, height, samples, near_w, true));
    const int subtiles_x = (alone.sample_width() + kW - 1) / kW, subtiles_y = (alone.sample_height() + kH - 1) / kH;
    std::size_t noted = 0, not_noted = 0, covering = 0;
    for (const Backface backface : {Backface::none, Backface::cw, Backface::ccw}) {
        const CellNoteSpec spec{alone.sample_width(), alone.sample_height(), reference_cells_width(subtiles_x),
                                  reference_cells_height(subtiles_y), near_w, backface};
        const float row[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // the identity's last row
        std::vector<CellNote> records, first_records;
        for (const std::string& isa : available_isas()) {
            if (isa == "scalar") continue;
            std::vector<std::uint16_t> bucket(n);
            std::vector<std::uint32_t> count(kDrawOrderBuckets, 0u);
            records.assign(n, CellNote{});
            raster_kernels(isa_choice(isa)).bucket_packed_soup(xyzw.data(), 4, 0, n, row, near_w, bucket.data(), count.data(), &spec, records.data());
            if (first_records.empty()) first_records = records;
            else EXPECT_EQ(std::memcmp(records.data(), first_records.data(), n * sizeof(CellNote)), 0) << isa;
        }
        if (records.empty()) GTEST_SKIP() << "no SIMD instruction set";
        for (std::size_t t = 0; t < n; ++t) {
            const CellNote& r = records[t];
            if (std::isnan(r.nearest)) {
                ++not_noted;
                continue;
            }
            ++noted;
            const std::string where = "triangle " + std::to_string(t) + ", backface " + std::to_string(int(backface));
            ASSERT_LE(r.cx0, r.cx1) << where;
            ASSERT_LE(r.cy0, r.cy1) << where;
            ASSERT_LT(int(r.cx1), spec.cells_width) << where;
            ASSERT_LT(int(r.cy1), spec.cells_height) << where;
            ASSERT_GE(r.nearest, 0x1.0p-64f) << where;
            const std::vector<float> one(xyzw.begin() + std::ptrdiff_t(12 * t), xyzw.begin() + std::ptrdiff_t(12 * t + 12));
            TriangleInput in = test::clip_space_input(one);
            in.backface = backface;
            alone.render_frame(in);
            const RasterStats& stats = alone.stats();
            ASSERT_EQ(stats.triangles_in, 1u) << where;
            ASSERT_EQ(stats.rasterized, 1u) << where;
            ASSERT_EQ(stats.invalid + stats.outside + stats.degenerate + stats.backface_culled + stats.near_clipped + stats.too_large, 0u)
                << where;
            bool covers = false;
            for (int ty = 0; ty < subtiles_y; ++ty)
                for (int tx = 0; tx < subtiles_x; ++tx) {
                    const OcclusionBuffer::Subtile s = alone.subtile(tx, ty);
                    if (s.covered == 0) continue;
                    covers = true;
                    EXPECT_TRUE((tx >> kReferenceCellShift) >= r.cx0 && (tx >> kReferenceCellShift) <= r.cx1 &&
                                (ty >> kReferenceCellShift) >= r.cy0 && (ty >> kReferenceCellShift) <= r.cy1)
                        << where << ": subtile " << tx << ", " << ty << " outside the noted cells";
                    EXPECT_LE(s.d0, r.nearest) << where;
                    EXPECT_LE(s.d1, r.nearest) << where;
                }
            covering += covers;
            std::vector<float> depth;
            alone.read_sample_depth(depth);
            EXPECT_LE(*std::max_element(depth.begin(), depth.end()), r.nearest) << where;
        }
    }
    EXPECT_GT(noted, 3000u);
    EXPECT_GT(covering, 2000u);
    EXPECT_GT(not_noted, 1500u);
}

// The cells are a render's scratch: a frame after another, or a render after clear(), must
// not drop triangles behind the last frame's cells. A near frame that fills the screen, then a
// far one: drawn after it (render_frame, or clear() and render()), the far frame gives what it
// gives in a new buffer; drawn over it (render), what a render without any skip gives.
TEST(ReferenceCells, ANewFrameForgetsTheLastFramesCells) {
    const auto quads = [](float w, int copies) {  // the screen as two triangles, `copies` times
        std::vector<float> xyzw;
        for (int c = 0; c < copies; ++c)
            for (const float v : {-1.0f, -1.0f, 0.0f, 1.0f, 1.0f, -1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.0f, 1.0f,  // (x, y) corners; z; w = 1
                                  -1.0f, -1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 0.0f, 1.0f, -1.0f, 1.0f, 0.0f, 1.0f})
                xyzw.push_back(v * w);
        return xyzw;
    };
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<float> unit(-0.9f, 0.9f);
    std::vector<float> far_soup;  // small triangles all over the screen, far away
    for (int t = 0; t < 400; ++t) {
        const float cx = unit(rng), cy = unit(rng), w = 20.0f;
        const float corners[6] = {cx, cy, cx + 0.1f, cy, cx, cy + 0.1f};
        for (int k = 0; k < 3; ++k) far_soup.insert(far_soup.end(), {corners[2 * k] * w, corners[2 * k + 1] * w, 0.0f, w});
    }
    const std::vector<float> near_soup = quads(1.0f, 16);
    const TriangleInput near_in = test::clip_space_input(near_soup), far_in = test::clip_space_input(far_soup);
    const BufferConfig config = test::buffer_config(320, 180, 1, 0.5f);
    for (const bool threads : {false, true}) {
        const ParallelFor parallel = threads ? test::parallel_jobs() : ParallelFor{};
        const std::string where = threads ? "two threads" : "one thread";
        OcclusionBuffer fresh(config);
        fresh.render_frame(far_in, parallel);
        ASSERT_GT(fresh.stats().subtiles_updated, 100u) << where;
        OcclusionBuffer next_frame(config), after_clear(config), over(config), over_oracle(config);
        next_frame.render_frame(near_in, parallel);
        next_frame.render_frame(far_in, parallel);
        EXPECT_TRUE(test::same_subtiles(next_frame, fresh)) << where;
        EXPECT_TRUE(next_frame.stats() == fresh.stats()) << where;
        after_clear.render_frame(near_in, parallel);
        after_clear.clear();
        after_clear.render(far_in, parallel);
        EXPECT_TRUE(test::same_subtiles(after_clear, fresh)) << where;
        over.render_frame(near_in, parallel);
        over.render(far_in, parallel);
        set_hidden_skip(false);
        over_oracle.render_frame(near_in, parallel);
        over_oracle.render(far_in, parallel);
        set_hidden_skip(true);
        EXPECT_TRUE(test::same_subtiles(over, over_oracle)) << where;
        EXPECT_TRUE(over.stats() == over_oracle.stats()) << where;
    }
}

// The vector drop (block tables) decides every note as the scalar loop over the cells does
// (drop_hidden_noted, on hidden_by_note): boxes of 1 x 1 to 6 x 9 cells (more than 8: the
// kernel's own fallback), notes missing (NaN depth, box zeroed as the notes kernel leaves it),
// depths equal to a cell's, counts that leave a partial vector. Then the tables follow changed
// rows (update_cell_blocks on those rows only).
TEST(ReferenceCells, TheDropKernelKeepsWhatTheScalarDropKeeps) {
    const int width = 30, height = 34;  // 1080p's cells
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<float> depth(0.0f, 1.0f);
    std::vector<float> cells(std::size_t(kCellTables * width * height));
    for (std::size_t c = 0; c < std::size_t(width * height); ++c)
        cells[c] = depth(rng) < 0.3f ? std::numeric_limits<float>::infinity() : depth(rng);  // infinite: another part's rows
    const std::size_t n = 5000 + 7;
    std::vector<TriangleNote> notes(n);
    for (std::size_t k = 0; k < n; ++k) {
        notes[k].triangle = std::uint32_t(rng());
        CellNote& r = notes[k].note;
        const int span_x = rng() % 4 == 0 ? int(rng() % 6) : int(rng() % 2), span_y = rng() % 4 == 0 ? int(rng() % 9) : int(rng() % 2);
        r.cx0 = std::uint8_t(rng() % std::uint64_t(width - span_x)), r.cy0 = std::uint8_t(rng() % std::uint64_t(height - span_y));
        r.cx1 = std::uint8_t(r.cx0 + span_x), r.cy1 = std::uint8_t(r.cy0 + span_y);
        r.nearest = rng() % 3 == 0 ? cells[std::size_t(r.cy0 * width + r.cx0)] : depth(rng);
        if (rng() % 10 == 0) r = CellNote{0, 0, 0, 0, std::numeric_limits<float>::quiet_NaN()};
    }
    const ReferenceCells view{cells.data(), width, height};
    update_cell_blocks(view, 0, height);
    std::vector<std::uint32_t> all_kept(n);
    const std::size_t kept_of_all = drop_hidden_noted(view, notes.data(), n, all_kept.data());
    ASSERT_GT(kept_of_all, n / 5);
    ASSERT_LT(kept_of_all, 4 * n / 5);
    for (const std::string& isa : available_isas()) {
        const DropHiddenKernel drop_hidden = raster_kernels(isa_choice(isa)).drop_hidden;
        for (const std::size_t count : {n, std::size_t(5), std::size_t(0)}) {
            std::vector<std::uint32_t> got(n, 0), want(n, 0);
            const std::size_t got_kept = drop_hidden(view, notes.data(), count, got.data());
            const std::size_t want_kept = drop_hidden_noted(view, notes.data(), count, want.data());
            ASSERT_EQ(got_kept, want_kept) << isa << ", " << count << " notes";
            EXPECT_TRUE(std::equal(want.begin(), want.begin() + std::ptrdiff_t(want_kept), got.begin())) << isa << ", " << count << " notes";
        }
    }
    // Rows 10 to 14 change (some cells nearer, some farther); the tables updated for those rows
    // alone must answer as tables built from scratch.
    for (int cy = 10; cy < 15; ++cy)
        for (int cx = 0; cx < width; ++cx) cells[std::size_t(cy * width + cx)] = depth(rng);
    update_cell_blocks(view, 10, 15);
    std::vector<float> rebuilt(cells.begin(), cells.begin() + width * height);
    rebuilt.resize(cells.size());
    const ReferenceCells rebuilt_view{rebuilt.data(), width, height};
    update_cell_blocks(rebuilt_view, 0, height);
    EXPECT_TRUE(rebuilt == cells);
}

// A clip-space soup drawn with a job system goes in parts of rows (render_parts), as many as
// ParallelFor::threads says, their bounds placed by the last render's load: whatever the parts,
// frame after frame, and with bad input, the same bits and statistics as one thread.
TEST(ReferenceCells, PartsOfRowsGiveTheBitsOfOneThread) {
    std::vector<float> frames[4] = {test::random_clip_triangles(51, 6000, 0.3f), test::random_clip_triangles(52, 6000, 0.3f),
                                    test::random_clip_triangles(53, 9000, 0.2f), test::random_clip_triangles(54, 6000, 0.3f)};
    // The last frame with bad input among the good: vertices behind the eye, not numbers,
    // infinite, and far outside the guard band.
    std::vector<float>& bad = frames[3];
    for (std::size_t v = 0; 4 * v < bad.size(); ++v) {
        float* p = &bad[4 * v];
        if (v % 97 == 0) p[3] = -p[3];
        if (v % 211 == 0) p[v % 2] = std::numeric_limits<float>::quiet_NaN();
        if (v % 223 == 0) p[3] = std::numeric_limits<float>::infinity();
        if (v % 227 == 0) p[2] = std::numeric_limits<float>::infinity();
        if (v % 13 == 0) p[0] *= 1e9f;
    }
    const BufferConfig config = test::buffer_config(333, 201, 2, 0.5f);  // 21 cell rows
    std::vector<OcclusionBuffer> serial_frames;  // render_frame starts from a clear buffer: each frame alone
    for (const std::vector<float>& frame : frames) {
        serial_frames.emplace_back(config);
        serial_frames.back().render_frame(test::clip_space_input(frame));
    }
    std::mt19937_64 order_rng(5);
    for (const std::size_t threads : {std::size_t(0), std::size_t(1), std::size_t(3), std::size_t(8), std::size_t(1000)}) {
        OcclusionBuffer parts(config);
        for (std::size_t f = 0; f < 4; ++f) {
            parts.render_frame(test::clip_space_input(frames[f]), ParallelFor{test::run_shuffled, &order_rng, threads});
            const std::string where = std::to_string(threads) + " threads, frame " + std::to_string(f);
            EXPECT_TRUE(test::same_subtiles(parts, serial_frames[f])) << where;
            EXPECT_TRUE(test::same_pyramid(parts, serial_frames[f])) << where;
            EXPECT_TRUE(parts.stats() == serial_frames[f].stats()) << where;
        }
    }
    const RasterStats& bad_stats = serial_frames[3].stats();
    EXPECT_GT(bad_stats.invalid, 0u);
    EXPECT_GT(bad_stats.near_clipped, 0u);
    EXPECT_GT(bad_stats.too_large + bad_stats.outside, 0u);
}

}  // namespace
}  // namespace homcull::detail
