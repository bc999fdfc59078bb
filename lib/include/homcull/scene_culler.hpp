#pragma once
// Culling a scene's objects frame after frame with hierarchical occlusion maps: select
// occluders, render them into an occlusion buffer, build the maps, and test the objects
// through a hierarchy of boxes, front to back, skipping what lies under a hidden node.
// One SceneCuller is reused frame after frame: the buffer, the maps, the hierarchy and the
// candidate occluders' triangles are set up once, with room (written, so faulted in) for the
// largest frame it can draw, on one thread or through a job system; no frame allocates, the
// first included, whatever the camera's near plane (the caller's answers vector aside).
#include <homcull/object_hierarchy.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occluder_lod.hpp>
#include <homcull/occluder_selection.hpp>
#include <homcull/occlusion_maps.hpp>
#include <homcull/scene.hpp>
#include <homcull/world_triangles.hpp>

#include <cstdint>
#include <vector>

namespace homcull {
namespace detail {
class SceneCullerState;  // lib/scene/scene_culler_state.hpp
}

enum class OccludeeShape : std::uint8_t {
    box,         // the world box alone
    rectangles,  // each triangle's screen rectangle at its nearest depth, through the maps and their depth test
    samples,     // the triangles sample by sample against the buffer's masked depth (OcclusionBuffer::test_triangles)
    automatic,   // samples with the masked depth test, rectangles with the others
};

// How a frame finds its occluders. Every strategy is conservative: only real geometry is drawn.
enum class CullStrategy : std::uint8_t {
    // Select occluders, render them, test everything (Zhang's two-pass framework).
    one_pass,
    // Traverse front to back from an empty buffer; the occluder candidates found visible are
    // rendered in batches as traversal goes, and later nodes are tested against what has been
    // drawn so far (Greene's hierarchical visibility).
    progressive,
    // Last frame's visible set, plus the candidates that have just entered the frustum (Zhang's
    // eq. 7.1 candidate set), are this frame's occluders (Yoon, Salomon and Manocha). The first
    // frame, the first after reset_history(), and a frame whose camera jumped (TemporalCut)
    // work as one_pass. Candidates that come into view (found visible though left out) are then
    // drawn too, and the objects found visible tested again: a second pass, only in frames where
    // that happens.
    temporal,
};

// When temporal treats a frame as a camera cut and works as one_pass: the eye moved more than
// `step_in_near_planes` times the camera's near distance since the last frame, or the view
// direction turned more than `turn_degrees`. Last frame's visible set then predicts this
// frame's occluders badly, and drawing it first, then what came into view, costs more than
// drawing every candidate in the frustum at once (over unrelated views, about twice as much).
// The defaults keep walks temporal: a walk at a few near distances and a few degrees a frame
// culls up to 40 % faster with its history on the shared scenes, the gain holds to about 25
// near distances a frame and turns into a loss on some scenes from about 40
// (docs/scene-culling.md, "Camera cuts"). An engine that knows of a cut calls reset_history()
// as well.
struct TemporalCut {
    double step_in_near_planes = 32.0;  // >= 0; infinity: never a cut for the eye's travel
    double turn_degrees = 30.0;         // in [0, 180]; 180: never a cut for a turn
};

struct SceneCullerConfig {
    Resolution display{1280, 720};
    // Buffer pixels; 0 x 0 means display / samples, whose samples are the display's pixel
    // centres. Conservative mode (maps.hole_pixels = 0) requires exactly that: a coverage
    // sample elsewhere says nothing about the display's pixel centres.
    Resolution buffer{0, 0};
    // S x S coverage samples per buffer pixel: 1, 2 or 4, or 0 for automatic_samples(display,
    // buffer): 1 for a buffer the display's size, 4 x 4 for a low-resolution one (a quarter of
    // the display or less).
    int samples = 0;
    // The buffer's instruction set (BufferConfig::isa); null: select_isa's choice when the
    // culler is made. The culler keeps it for life.
    const char* isa = nullptr;
    OcclusionMapsConfig maps;  // display_width/height are taken from `display`
    // Back faces are surfaces to ground truth and to the eye: none are culled by default.
    Backface backface = Backface::none;
    // With backface none: the occluders that are closed meshes enclosing a positive volume
    // (every edge shared by two triangles of the object, in opposite order) are drawn without
    // the triangles that face away from the eye: left out when the frame's triangles are
    // gathered, or, with occluder_clusters, culled by the rasterizer (Backface::cw on those
    // clusters, ClusteredInput::backfaces). They lie behind the mesh's front faces, and leaving
    // occluder triangles out can never hide what is visible (docs/scene-culling.md, "Closed
    // occluders", has what it costs in culling).
    bool skip_closed_back_faces = true;
    // Draw each occluder with its exactly coplanar regions re-triangulated, when the culler is
    // made: fewer triangles covering the same points at the same depths (gather_world_triangles;
    // docs/scene-culling.md, "Coplanar merge").
    bool merge_coplanar_occluders = true;
    // Occludee shape: the world box alone, or, where the box is found visible, the object's
    // triangles (much tighter for objects whose box reaches past what hides them, at the cost
    // of transforming their vertices). Objects with more than triangle_test_limit triangles
    // keep the box's answer.
    OccludeeShape occludees = OccludeeShape::automatic;
    std::size_t triangle_test_limit = 20000;
    // Each object's triangles split, when the culler is made, into up to this many parts by
    // their centres, each with its box (objects with at most triangle_test_limit triangles):
    // an object whose own box is visible is hidden when every part's box is, and the samples
    // shape then tests only the triangles of the parts whose box is visible. Tighter than the
    // object's box for L-shaped, hollow or sprawling objects, and far cheaper than its
    // triangles. Conservative mode only (approximate mode would tolerate holes once per part).
    // Below 2: the object's box alone.
    int occludee_parts = 16;
    // With the samples shape: give the buffer a per-sample depth (BufferConfig::sample_depth),
    // the occluders' depth without the layers' loss at silhouettes. Off: the layers alone,
    // rendering faster.
    bool sample_depth = true;

    CullStrategy strategy = CullStrategy::temporal;
    TemporalCut temporal_cut;
    // Per-frame ranking of the occluder candidates under a triangle budget. The default draws
    // every candidate (progressive: every candidate found visible).
    OccluderBudget occluder_budget;
    // progressive: render the occluders found visible every time this many triangles wait.
    std::size_t progressive_batch_triangles = 1024;
    // Test the hierarchy's inner nodes (off: only objects are tested, still front to back).
    bool hierarchy = true;
    int hierarchy_leaf_size = 4;
    // Occluder LODs (not owned; build_occluder_lods in homcull/truth/occluder_lod_build.hpp,
    // for this scene's candidates): an occluder is drawn with its LOD whenever lod_usable()
    // allows it, which keeps every answer conservative (see occluder_lod.hpp). Null: never.
    const OccluderLods* lods = nullptr;
    // Draw the occluders as clusters (occluder_clusters.hpp), built per candidate when the
    // culler is made: each frame the drawn candidates' clusters go nearest first, and those
    // outside the view or hidden are skipped before their triangles are set up. Occluders
    // drawn with their LOD still go triangle by triangle. Off: every drawn triangle is set up,
    // and the culler is made faster: building every candidate's clusters adds up to a few
    // tenths of a second on the shared scenes, which frames culled faster win back over a few
    // hundred frames.
    bool occluder_clusters = true;
    // Whether cull() may be given a job system (ParallelFor::run). The culler then reserves,
    // when it is made, the room the draws a job system runs take (with clusters, the task
    // list's set-up pool: up to 65,536 triangles' worth, about 12 MB), so that no frame
    // allocates, the first included. A caller that culls on its own thread only can leave it
    // out: a cull given a job system anyway answers the same, but grows that room in its first
    // frames.
    bool job_system = true;
};

// The shape `automatic` stands for with this configuration.
OccludeeShape resolved_occludee_shape(const SceneCullerConfig& config);

struct SceneCullTimings {
    double select_ms = 0.0;  // choosing the frame's occluders and gathering their triangles
    double render_ms = 0.0;  // occluder triangles into the buffer
    double maps_ms = 0.0;    // opacity pyramid, depth maps, depth estimation buffer
    double test_ms = 0.0;    // the hierarchy's nodes and the objects' boxes (and triangles)
};

// What the last cull() did.
struct SceneCullWork {
    std::size_t occluder_objects = 0;    // objects rendered into the buffer
    std::size_t occluder_triangles = 0;  // their triangles (as drawn: LODs' where used)
    // Of those, the closed meshes' triangles facing away from the eye, left out
    // (skip_closed_back_faces; clusters' are culled by the rasterizer instead, and counted in
    // the buffer's RasterStats::backface_culled).
    std::size_t back_faces_skipped = 0;
    std::size_t occluder_lods = 0;       // occluders drawn with their LOD
    std::size_t renders = 0;             // render calls (progressive: batches)
    std::size_t nodes_tested = 0;        // inner hierarchy nodes tested
    std::size_t objects_tested = 0;      // objects tested on their own (the rest answered by a node)
    std::size_t occludee_parts_tested = 0;  // part boxes tested (SceneCullerConfig::occludee_parts)
    // Of the parts whose triangles were tested, those of closed occludees seen from outside
    // (wholly beyond the near plane), tested without the triangles the eye sees from behind.
    std::size_t solid_parts_tested = 0;
    // temporal: the frame started from the last frame's visible set (false on the first frame,
    // after reset_history() and at a camera cut, TemporalCut).
    bool used_history = false;
};

// How many objects each overlap-test exit decided (indexed by OverlapExit).
struct OverlapExitCounts {
    std::uint64_t count[7] = {};
};

class SceneCuller {
public:
    // `occluders`: the occluder candidates, object ids (occluder_candidates() gives the usual
    // choices); their triangles are gathered once, here. Throws homcull::Error on an invalid
    // configuration. With a job system (`parallel`), the preparation's work per object and per
    // mesh (world positions, coplanar merges, shared edges, clusters, occludee parts, closed
    // meshes' orientations) runs in its tasks; the culler is the same, bit for bit.
    SceneCuller(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                const ParallelFor& parallel = {});

    // answers[id] for every object of the scene (objects without geometry are view-culled).
    // overlap_exit is the deciding box test's (the object's own, or the hidden node's above
    // it); an object its triangles found hidden reports level of visibility 0. Throws
    // homcull::Error on an invalid or orthographic camera (validate_camera; the occlusion maps
    // compare perspective depths). With a job system (`parallel`) the render runs in bands of
    // rows and, for one_pass and temporal, the hierarchy is traversed and its nodes and objects
    // tested in tasks; the answers are those of one thread.
    void cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel = {});
    // temporal: forget the last frame (after a camera cut the engine knows of), so that the
    // next frame works as one_pass.
    void reset_history();

    const SceneCullerConfig& config() const;
    const Scene& scene() const;
    const OcclusionBuffer& buffer() const;
    // The maps of the last cull() with their pyramids: with lazy maps (the default, see
    // PyramidBuild) the first call after a cull makes them, for dumps. Not thread-safe with
    // cull() or with itself.
    const OcclusionMaps& maps() const;
    const SceneCullTimings& timings() const;
    const SceneCullWork& work() const;
    const OverlapExitCounts& overlap_exits() const;
    // The objects the last cull() drew as occluders (object ids, in drawing order).
    const std::vector<std::uint32_t>& drawn_occluders() const;
    const ObjectHierarchy& hierarchy() const;
    // The occluder candidates, and their triangles.
    std::size_t occluder_objects() const;
    std::size_t occluder_triangles() const;

    // The implementation (lib/scene/scene_culler_state.hpp): not part of the interface.
    const detail::SceneCullerState& state() const { return *state_; }

    // Moves leave the source with no state: it may then only be assigned to or destroyed.
    ~SceneCuller();
    SceneCuller(SceneCuller&&) noexcept;
    SceneCuller& operator=(SceneCuller&&) noexcept;

private:
    detail::HookPtr<detail::SceneCullerState> state_;  // the scene's occluders, buffer, maps and per-frame scratch
};

// The samples per buffer pixel axis that SceneCullerConfig::samples = 0 stands for: the largest
// S in {4, 2, 1} whose buffer x S samples fit within the display on both axes. A low-resolution
// buffer (a quarter of the display or less on each axis) gets 4 x 4, as Intel's Masked
// Occlusion Culling uses; a buffer of display / S gets S, its samples on the display's pixel
// centres; buffer 0 x 0 (the display itself) and any buffer more than half the display on an
// axis get 1, so that a buffer never holds more samples than the display has pixels.
int automatic_samples(Resolution display, Resolution buffer);

// The buffer configuration a SceneCullerConfig asks for (resolved buffer size), for callers
// that want to check it before building a culler. Throws homcull::Error when invalid.
BufferConfig scene_buffer_config(const SceneCullerConfig& config, float near_w);

}  // namespace homcull
