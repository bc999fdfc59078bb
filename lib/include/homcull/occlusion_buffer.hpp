#pragma once
// The occlusion buffer: occluder triangles rasterized into per-sample coverage masks and a
// conservative farthest depth, and occludee tests against it.
//
// Layout. The buffer has W x H pixels of S x S samples each (S = 1, 2 or 4). Samples are
// grouped in subtiles of 8 x 4 samples (one 32-bit mask each); the sample (i, j) has its
// centre at (i + 0.5, j + 0.5) in sample units, which is the centre of display pixel (i, j)
// when W*S x H*S is the display resolution (the same grid as ground truth's sub-samples).
//
// Depth. Depth is stored reversed as d = 1/w (clip w = view depth for a perspective
// projection): larger is nearer, 0 is "nothing". Each subtile keeps the two layers of
// masked occlusion culling (Hasselgren, Andersson, Akenine-Moller, "Masked Software
// Occlusion Culling", HPG 2016): a reference depth d0 that every sample of the subtile is
// known to be at or nearer than, and a working layer (d1, mask) for the samples in mask.
//
// Conservative. A sample is marked covered only when it lies inside the triangle by a margin
// (edge_margin samples) on every silhouette edge, which absorbs the rounding between this
// rasterizer and an exact ray cast (a shared edge whose neighbour lies across it in the view
// needs none: TriangleInput::shared_edges); a triangle's depth enters the buffer as a lower
// bound of 1/w over the samples it covers, lowered by a relative 2^-20. So the buffer never
// claims an occluder where there is none, nor nearer than it is, and occludee tests never hide
// what is visible at the samples.
#include <homcull/aabb.hpp>
#include <homcull/camera.hpp>
#include <homcull/detail/memory.hpp>
#include <homcull/isa.hpp>
#include <homcull/parallel_for.hpp>
#include <homcull/triangle_input.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace homcull {
class OcclusionMaps;
namespace detail {
class BufferState;  // lib/buffer/buffer_state.hpp
}  // namespace detail

enum class Visibility : std::uint8_t { visible, occluded, view_culled };

struct BufferConfig {
    int width = 0, height = 0;  // pixels, >= 1
    int samples = 1;            // S: S x S samples per pixel, 1, 2 or 4 (SceneCuller picks it from its display)
    // Triangles are clipped at clip w >= near_w (the camera's near distance for a standard
    // perspective projection). Occludees reaching w < near_w are visible. At least 2^-126.
    float near_w = 0.1f;
    // An orthographic projection (clip w = 1 everywhere), whose depth comes from clip z instead
    // of 1/w, in OpenGL's range: z = -1 at the near plane, 1 at the far plane. Depth is then
    // kept as g = (3 - z) / 2 (2 at the near plane, 1 at the far one, 0 at twice the far
    // distance), and every clip point is taken as (x, y, z, w) / h with h = (3w - z) / 2 (the
    // same point on the screen, with 1/w' = g: docs/occlusion-buffer.md, "Orthographic
    // projections"), so that the rest of the buffer works as for a perspective one. near_w is
    // then 0.5 (the near plane, z = -1) whatever it was set to. What lies beyond twice the far
    // distance (g < 2^-8) is not drawn and not answered: occluder triangles reaching it are
    // skipped (counted as invalid), occludees reaching it are visible. Inputs must say they are
    // orthographic (TriangleInput, ClusteredInput::orthographic). Occlusion maps refuse such a
    // buffer.
    bool orthographic = false;
    // Inner margin of coverage, in samples: see "Conservative" above.
    double edge_margin = 1.0 / 1024.0;
    // Also keep a conservative depth per sample: at each covered sample, the nearest of the
    // occluders' own lower bounds there (their planes lowered by their float error, as for
    // the subtile layers, but evaluated at the sample). The layers lose depth where a subtile
    // holds occluders at different depths, at silhouettes; per-sample depth does not, which
    // test_triangles uses. Costs 4 bytes a sample and a plane evaluation per covered sample.
    bool sample_depth = false;
    // The instruction set of this buffer's kernels, by a name select_isa takes ("best",
    // "scalar", "avx2", ...: homcull/isa.hpp); null: select_isa's choice when the buffer is made
    // or configured. Every one gives the same bits. config() then names the one in use ("best"
    // becomes the best one's name).
    const char* isa = nullptr;
};

// The largest work a buffer will be given (OcclusionBuffer::reserve). Zeros reserve nothing.
struct BufferReserve {
    int max_width = 0, max_height = 0;  // pixels (the samples per pixel stay the buffer's)
    std::size_t max_triangles = 0;      // per render call
    std::size_t max_vertices = 0;       // per render(TriangleInput) call
    std::size_t max_clusters = 0;       // per render(ClusteredInput) or record() call
    std::size_t max_cluster_vertices = 0;  // the largest OccluderCluster::vertex_count drawn
    // Clustered draws with a job system, and record()ed task lists: the most clusters and the
    // most triangles in them of one task list (a render with a job system is a list of one draw).
    std::size_t max_task_list_draws = 0, max_task_list_clusters = 0, max_task_list_triangles = 0;
    // Triangle renders (render(TriangleInput)) with a job system: the most ParallelFor::threads
    // they are given (a job system that says 0 counts as 2). 0: such renders are not reserved for.
    std::size_t max_threads = 0;
};

struct OccluderClusters;
struct OccluderCluster;
// An occluder mesh split into clusters at load time (occluder_clusters.hpp), under a
// model-to-clip matrix (column-major), for OcclusionBuffer::render. Its positions have 3
// components; its shared-edge flags are the mesh's.
struct ClusteredInput {
    const OccluderClusters* clusters = nullptr;
    std::array<float, 16> model_to_clip{};
    Backface backface = Backface::cw;
    // Optional: only these clusters (numbers into clusters->clusters, cluster_count of them);
    // null: all of them.
    const std::uint32_t* cluster_ids = nullptr;
    std::size_t cluster_count = 0;
    // Optional: shared-edge flags and their apexes to use instead of clusters->shared_edges and
    // clusters->edge_apexes, one (three) per clustered triangle in the same order (for example
    // flags computed within each object only); the apexes number vertices within each
    // triangle's cluster, as OccluderClusters::edge_apexes do.
    const std::uint8_t* shared_edges = nullptr;
    const std::uint32_t* edge_apexes = nullptr;
    bool orthographic = false;  // as TriangleInput::orthographic
    // Optional: each drawn cluster's own backface mode instead of `backface`, one per cluster
    // drawn (in cluster_ids' order, or per cluster of `clusters` when cluster_ids is null). For
    // example, the back faces of closed meshes culled and the other meshes' kept
    // (SceneCullerConfig::skip_closed_back_faces).
    const Backface* backfaces = nullptr;
};

// A screen rectangle to test: NDC (y up) bounds and the occludee's nearest clip w. The layout
// of S1's rectangle file (5 floats).
struct ScreenRect {
    float ndc_min_x, ndc_min_y, ndc_max_x, ndc_max_y, w_min;
};

// What is wrong with a configuration (a constant text naming the rule it breaks), or null when
// it is valid. The buffer's constructor and configure() throw homcull::Error with it. Allocates
// nothing (the C interface reports it without a C++ string).
const char* buffer_config_problem(const BufferConfig& config) noexcept;

class OcclusionBuffer {
public:
    struct Subtile {
        float d0 = 0.0f;           // reference layer: all samples at or nearer than this
        float d1 = 0.0f;           // working layer depth, for the samples in `mask`
        std::uint32_t mask = 0;    // working layer samples
        std::uint32_t covered = 0; // union of all occluder coverage (for opacity)
    };
    static constexpr int kSubtileWidth = 8, kSubtileHeight = 4;

    // Throws homcull::Error on an invalid configuration. The buffer's planes and pyramid are
    // allocated here; the first render sizes its scratch (draw order, clusters, bins) to its
    // input, and from then on renders of inputs no larger, and every query, allocate nothing.
    explicit OcclusionBuffer(const BufferConfig& config);

    // A new configuration (resolution, samples, near plane, ...): the buffer is then empty. Its
    // arrays keep their memory and grow only where the new configuration needs more than they
    // hold. Throws homcull::Error on an invalid configuration, std::bad_alloc when memory runs
    // out; either way the buffer is left as it was.
    void configure(const BufferConfig& config);
    // A new near plane (BufferConfig::near_w), emptying the buffer; allocates nothing.
    void set_near_w(float near_w);
    // Sizes every array for the largest buffer and input the caller will give, so that renders
    // within these sizes (with a job system: of at most max_threads threads), and configure()
    // up to that resolution, never allocate, not even the first frame. Throws like configure;
    // whatever it reserved stays reserved.
    void reserve(const BufferReserve& reserve);

    void clear();
    // Rasterizes occluders in draw order (TriangleInput::order, nearest first by default).
    // Without a job system each triangle is set up and drawn in turn; with one, a clip-space
    // soup drawn nearest first (the identity matrix, 4 packed floats per vertex, no shared-edge
    // flags, as S1 and MOC's API give triangles) is drawn in ParallelFor::threads parts of rows,
    // one task each; other input in waves of chunks of triangles (4, 8, 16, then 32 chunks at
    // a time), each set up and binned into bands of subtile rows in parallel, then each band
    // rasterized in draw order. Every subtile sees the same sequence of triangles whatever the
    // threads. Triangles already hidden in the buffer are dropped before their edges are set
    // up (most of a noted soup's before they are read), which changes no bit. The room for the
    // waves has a fixed size (about 14 MB at 1080p for inputs of 65,536 triangles or more),
    // allocated on the calling thread before any task runs, or by reserve(): the tasks never
    // allocate. Should the job system fail after drawing began, the buffer keeps what was
    // drawn, with a pyramid to match; a render_frame leaves no row of the frame before.
    // Indexed input with at most two vertices per
    // triangle has every one of its vertex_count positions read and transformed once (so
    // vertex_count must not overstate the positions), into scratch of 33 bytes a vertex (up to
    // 4M vertices) that also only grows and stays allocated with the buffer. Statistics
    // accumulate until clear() or render_frame(). Not thread-safe with itself or with tests.
    void render(const TriangleInput& input, const ParallelFor& parallel = {});
    // clear() then render(), for the frame's first (or only) occluders: the same bits, but with
    // a job system each band's rows are cleared by the task that then rasterizes them, so that
    // they are written on one core instead of first on the caller's (castle view C0, two
    // threads: about 10 % faster than clear() and render()). Throws, as render() does, before
    // anything is cleared.
    void render_frame(const TriangleInput& input, const ParallelFor& parallel = {});
    // Rasterizes a clustered mesh, deciding clusters by their boxes before any of their
    // triangles is set up: clusters outside the view are dropped; the others are taken nearest
    // first (by their boxes' nearest w, then their number), and each band of subtile rows
    // (128 sample rows, whatever the threads) skips a cluster whose box lies behind the band's
    // reference layer d0 over every subtile the box covers there (test_rect's first rule, on
    // d0 alone, on the layer as it is when the cluster's turn comes). A skipped cluster only
    // leaves out occlusion, so the buffer stays conservative; but a triangle of it could have
    // entered a subtile (its conservative depth is a bound, evaluated where the box is not), so
    // the bits are those of this order and these skips, not of render(TriangleInput) over the
    // same triangles. They are the same on every instruction set and with any threads: with a
    // job system (two parallel runs a frame) the clusters' boxes are placed in tasks of 64,
    // then the bands run in parallel, and a cluster is set up once, by the first band that
    // draws it, its triangles kept for the other bands (no bins). Scratch (each cluster's place
    // and the clusters' order, each band's transformed vertices, the kept triangles) is reused
    // and only grows.
    // Throws homcull::Error, before anything is drawn, when input.clusters is null, a cluster
    // number is out of range or a cluster reaches past its arrays.
    void render(const ClusteredInput& input, const ParallelFor& parallel = {});
    void render_frame(const ClusteredInput& input, const ParallelFor& parallel = {});

    // Clustered draws as tasks the caller's job system schedules itself (the pull model, as
    // masked occlusion culling's BinTriangles and RenderTrilist allow), beside ParallelFor:
    //     begin_tasks();                      // clear_first: as render_frame
    //     record(draw) for each draw;         // on the calling thread: nothing drawn yet
    //     n = close_tasks();                  // one task per band of subtile rows
    //     run_task(i) for every i < n, once each, on any threads, at once, in any order
    //                                         // (best in turn: the longest bands come first);
    //     finish_tasks();                     // after every run_task returned
    // The buffer then holds the same bits as render(draw) called for each draw in turn, on one
    // thread or with a job system: each band takes the draws in their order, and a draw's
    // clusters nearest first, as those renders do. record() places the draw's clusters (in
    // tasks of `parallel`, when given) and throws homcull::Error, like render(), before
    // recording anything. A task allocates nothing, throws nothing and never waits for another:
    // a cluster is set up by the first band that comes to it, into room for its own triangle
    // count, which the bands coming to it later draw; a band coming to it while it is being set
    // up sets up the next clusters meanwhile, or with none left sets it up for itself, as every
    // band does with a cluster that clipping makes larger than its room.
    // Between begin_tasks and finish_tasks the buffer must not be rendered into, cleared or
    // queried. finish_tasks throws homcull::Error when close_tasks' tasks did not all run (the
    // buffer then holds the bands that ran, which is conservative, with a pyramid to match).
    void begin_tasks(bool clear_first = false);
    void record(const ClusteredInput& draw, const ParallelFor& parallel = {});
    std::size_t close_tasks();
    void run_task(std::size_t index) noexcept;
    void finish_tasks();
    // The same without throwing, whatever state the list is in (for a caller abandoning it):
    // returns how many tasks did not run (every one when the list was not closed; nothing was
    // drawn then, and nothing changes).
    std::size_t finish_tasks(std::nothrow_t) noexcept;

    // Occludee tests. Thread-safe with each other (no render in flight): they only read the
    // buffer.
    // Screen rectangle in NDC (y up) with the nearest clip w of the occludee. Occluded when
    // every sample whose centre lies in it has an occluder nearer than w_min, by the subtile
    // bounds: d0, or max(d0, d1) where the rectangle's samples are all in the working layer.
    // So a rectangle (inside the view) that holds no sample centre is occluded, even in an
    // empty buffer: it covers nothing the buffer's samples (the display's pixel centres, when
    // they are its samples) could show.
    // Answered with a pyramid of the farthest depth (Greene, Kass, Miller, "Hierarchical
    // Z-buffer visibility", SIGGRAPH 1993): a coarse check, then a pruned search.
    Visibility test_rect(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const;
    // The same answers, by visiting every subtile: the definition test_rect is checked against.
    Visibility test_rect_exhaustive(float ndc_min_x, float ndc_min_y, float ndc_max_x, float ndc_max_y, float w_min) const;
    // World (or model) AABB under a model-to-clip matrix (column-major). view_culled when the
    // box lies before the near plane or outside the view volume the matrix gives (x and y
    // within w, no far plane), by an exact separating-axis test with a margin of 2^-20 of the
    // terms (homcull/frustum.hpp, view_volume_axes), so that a box beside a corner of the view
    // is culled too; else the box's screen rectangle at its nearest w, as test_rect.
    Visibility test_aabb(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const;
    // test_aabb without the exact view test: the screen rectangle and the clip planes alone, so a
    // box beside a corner of the view may be visible. For callers that test boxes against a view
    // of their own first (the scene culler, against its frustum), to whom the volume made at
    // each call would be a cost for nothing.
    Visibility test_aabb_by_rectangle(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip) const;
    // Batches: results[k] is what test_rect / test_aabb answer for item k, bit for bit.
    // rects/boxes and results must hold `count` elements (they may be null when count is 0). The
    // rectangles' first stage (validity, frustum, sample span, nearest depth and the coarse
    // pyramid check, which decides most hidden rectangles) runs with one rectangle per SIMD
    // lane; the rest one at a time. No allocation; thread-safe like the single tests.
    void test_rects(const ScreenRect* rects, std::size_t count, Visibility* results) const;
    void test_aabbs(const Aabb* boxes, std::size_t count, const std::array<float, 16>& model_to_clip, Visibility* results) const;
    // Occludee triangles, sample by sample (the occludee's own shape instead of a box around
    // it, as masked occlusion culling's TestTriangles). Every triangle counts, whatever its
    // orientation (backface and shared_edges are ignored), by its outer coverage: the samples
    // within a margin outside it that absorbs the rounding of this test, of its float input and
    // of an exact ray cast (edge_margin plus the input's own rounding bound). At each such sample
    // the triangle's nearest depth over the subtile (its plane, bounded by its nearest vertex,
    // raised by the rounding bounds) is compared with the subtile's layer bound.
    // Triangles are clipped at the near plane (near_w, moved towards the eye by the input's
    // rounding bound): what lies before it is not seen, as in ground truth.
    // Occluded when at most `tolerated_samples` samples (counted per triangle, so overlaps
    // count twice) are not certainly behind an occluder; view-culled when every triangle lies
    // outside the view frustum; visible otherwise, and as soon as a triangle has a non-finite
    // vertex or an index out of range, is too large to clip, or lies so far from the origin that
    // the rounding bound of its w reaches the near plane. Degenerate triangles (zero
    // area in clip space) cover nothing. The counts stop with the
    // answer, so they are partial for visible occludees. With no tolerance (0), a triangle that
    // needs no clipping is first tested by its bounding rectangle of samples at a depth no
    // farther than any of its own (its nearest vertex, raised by the transform's rounding
    // bound), against the layers as test_rect's rectangles are: where the layers hide that, the
    // triangle shows nothing and its samples are not counted (the same answer, for a fraction
    // of the work: most triangles of a hidden occludee end there), and so are its subtile rows
    // whose subtiles' far bounds all lie nearer than that depth; so with no tolerance the counts
    // are partial for occluded occludees too. No allocation; thread-safe like the other tests.
    struct TriangleTest {
        Visibility visibility = Visibility::view_culled;
        std::uint64_t samples = 0;          // samples the triangles counted may cover (see above)
        std::uint64_t visible_samples = 0;  // of those, samples with no occluder certainly nearer
        std::size_t deciding_triangle = 0;  // visible: the triangle that made it so
    };
    // The triangles are scanned from `first_triangle` on, wrapping around: the answer is the
    // same from any start, but starting at last frame's deciding triangle finds a visible
    // occludee's visible triangle at once (frame-to-frame coherence).
    TriangleTest test_triangles(const TriangleInput& occludee, std::uint64_t tolerated_samples = 0, std::size_t first_triangle = 0) const;
    // An occludee that is a closed solid seen from outside: every edge of its triangles shared
    // with another of them in opposite order, each connected piece enclosing a volume with the
    // triangles' counter-clockwise fronts facing out of it (orientation +1) or into it (-1), and
    // the whole occludee beyond the near plane, so that no ray starts inside it. Along any ray
    // its first surface is then a triangle seen from the front, and the test passes over the
    // triangles that `eye` (in the input's model space, as the rays start from it) certainly sees
    // from behind: about half of them. The caller vouches for the conditions: an occludee that
    // meets them only in part may be found hidden where a back face shows. (The scene culler
    // finds its closed occludees at load time and checks the near plane per frame.) Throws
    // homcull::Error for an orthographic or clip-space input, 4-component positions, an
    // orientation other than +1 and -1, or an eye that is not finite.
    struct ClosedSolid {
        double eye[3];
        int orientation;  // +1 or -1
    };
    TriangleTest test_triangles(const TriangleInput& occludee, std::uint64_t tolerated_samples, std::size_t first_triangle,
                                const ClosedSolid& solid) const;

    const BufferConfig& config() const;
    int sample_width() const;
    int sample_height() const;
    const RasterStats& stats() const;
    // One subtile's state, and a row-major copy of all of them (for tests and dumps).
    Subtile subtile(int tx, int ty) const;
    std::vector<Subtile> subtiles() const;
    int subtiles_x() const;
    int subtiles_y() const;

    // Read-back per sample (row-major, top row first): whether an occluder covers it, and
    // the conservative occluder depth as clip w (infinity where nothing is known): the layers'
    // bound, or the per-sample depth where that is nearer (BufferConfig::sample_depth).
    void read_coverage(std::vector<std::uint8_t>& covered) const;
    void read_depth(std::vector<float>& w) const;
    // The per-sample depth as kept (BufferConfig::sample_depth): 1/w per sample, row-major,
    // 0 where no occluder covers it; empty when the buffer does not keep it.
    void read_sample_depth(std::vector<float>& d) const;
    // The farthest-depth pyramid the rectangle tests use, every level one after the other:
    // level 0 the subtiles' d0, level l the minimum over cells of 2^l x 2^l subtiles, each
    // ceil(subtiles_x / 2^l) x ceil(subtiles_y / 2^l) cells, row-major, down to 1 x 1.
    void read_pyramid(std::vector<float>& cells) const;

    // The implementation (lib/buffer/buffer_state.hpp), for the library's own layers that read a
    // buffer (the occlusion maps): not part of the interface.
    const detail::BufferState& state() const { return *state_; }

    // Moves leave the source with no state: it may then only be assigned to or destroyed.
    ~OcclusionBuffer();
    OcclusionBuffer(OcclusionBuffer&&) noexcept;
    OcclusionBuffer& operator=(OcclusionBuffer&&) noexcept;

private:
    // Every array, scratch and setting lives there, so that this header, which engines and
    // tools include, says what the buffer does and not how.
    detail::HookPtr<detail::BufferState> state_;
};

// A camera's view-projection matrix as a column-major float array for TriangleInput and
// test_aabb (projection_matrix * view_matrix).
std::array<float, 16> clip_from_world(const Camera& camera, double aspect);
// A double matrix as the column-major float array TriangleInput and test_aabb take (each entry
// rounded to nearest).
std::array<float, 16> float_matrix(const glm::dmat4& m);

}  // namespace homcull
