#pragma once
// Culling a scene's objects frame after frame with hierarchical occlusion maps: select
// occluders, render them into an occlusion buffer, build the maps, and test the objects
// through a hierarchy of boxes, front to back, skipping what lies under a hidden node.
// One SceneCuller is reused frame after frame: the buffer, the maps, the hierarchy and the
// candidate occluders' triangles are set up once, and a frame allocates nothing once its
// scratch has grown (the first frames).
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
    // frame, or the first after reset_history(), works as one_pass. Candidates that come into
    // view (found visible though left out) are then drawn too, and the objects found visible
    // tested again: a second pass, only in frames where that happens.
    temporal,
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
    OcclusionMapsConfig maps;  // display_width/height are taken from `display`
    // Back faces are surfaces to ground truth and to the eye: none are culled by default.
    Backface backface = Backface::none;
    // Occludee shape: the world box alone, or, where the box is found visible, the object's
    // triangles (much tighter for objects whose box reaches past what hides them, at the cost
    // of transforming their vertices). Objects with more than triangle_test_limit triangles
    // keep the box's answer.
    OccludeeShape occludees = OccludeeShape::automatic;
    std::size_t triangle_test_limit = 20000;
    // With the samples shape: give the buffer a per-sample depth (BufferConfig::sample_depth),
    // the occluders' depth without the layers' loss at silhouettes. Off: the layers alone,
    // rendering faster.
    bool sample_depth = true;

    CullStrategy strategy = CullStrategy::one_pass;
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
    // drawn with their LOD still go triangle by triangle. Off: every drawn triangle is set up.
    bool occluder_clusters = false;
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
    std::size_t occluder_lods = 0;       // occluders drawn with their LOD
    std::size_t renders = 0;             // render calls (progressive: batches)
    std::size_t nodes_tested = 0;        // inner hierarchy nodes tested
    std::size_t objects_tested = 0;      // objects tested on their own (the rest answered by a node)
};

// How many objects each overlap-test exit decided (indexed by OverlapExit).
struct OverlapExitCounts {
    std::uint64_t count[7] = {};
};

class SceneCuller {
public:
    // `occluders`: the occluder candidates, object ids (occluder_candidates() gives the usual
    // choices); their triangles are gathered once, here. Throws homcull::Error on an invalid
    // configuration.
    SceneCuller(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config);

    // answers[id] for every object of the scene (objects without geometry are view-culled).
    // overlap_exit is the deciding box test's (the object's own, or the hidden node's above
    // it); an object its triangles found hidden reports level of visibility 0.
    void cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel = {});
    // temporal: forget the last frame (after a camera cut), so that the next frame works as
    // one_pass.
    void reset_history() { has_history_ = false; }

    const SceneCullerConfig& config() const { return config_; }
    const Scene& scene() const { return *scene_; }
    const OcclusionBuffer& buffer() const { return buffer_; }
    const OcclusionMaps& maps() const { return maps_; }
    const SceneCullTimings& timings() const { return timings_; }
    const SceneCullWork& work() const { return work_; }
    const OverlapExitCounts& overlap_exits() const { return exits_; }
    // The objects the last cull() drew as occluders (object ids, in drawing order).
    const std::vector<std::uint32_t>& drawn_occluders() const { return frame_occluders_; }
    const ObjectHierarchy& hierarchy() const { return hierarchy_; }
    // The occluder candidates, and their triangles.
    std::size_t occluder_objects() const { return occluder_ids_.size(); }
    std::size_t occluder_triangles() const { return occluders_.triangle_count(); }

private:
    const Scene* scene_;
    SceneCullerConfig config_;
    std::vector<std::uint32_t> occluder_ids_;
    // Every float position and box the buffer and maps see is relative to this point
    // (scene_anchor, as ground truth's), so that scenes far from the origin keep their precision.
    glm::dvec3 anchor_;
    std::vector<Aabb> object_boxes_, node_boxes_;  // world_bounds and the hierarchy's node bounds, anchored
    WorldTriangles occluders_;  // shared-edge flags across the whole candidate set
    // Per candidate k (occluder_ids_[k]): its triangles are [first_triangle_[k], first_triangle_[k + 1]).
    std::vector<std::uint32_t> first_triangle_;
    std::vector<std::uint32_t> candidate_of_;  // object id -> k, or kNone
    // Shared-edge flags within each object only: right for any subset of the candidates (an edge
    // shared with an object that is not drawn is a silhouette and needs its margin).
    std::vector<std::uint8_t> own_shared_edges_;
    std::vector<std::uint32_t> own_edge_apexes_;  // their apexes (3 per triangle, into occluders_.positions)
    // Per candidate k: its LOD's triangles (indices into occluders_.positions, which hold the
    // LODs' vertices after the originals') are lod_indices_[3 * lod_first_[k] .. 3 * lod_first_[k + 1]),
    // with shared-edge flags within the LOD; an empty range when it has none.
    std::vector<std::uint32_t> lod_first_, lod_indices_;
    std::vector<std::uint8_t> lod_shared_edges_;
    std::vector<std::uint32_t> lod_edge_apexes_;
    // config_.occluder_clusters: candidate k's clusters are [cluster_first_[k], cluster_first_[k + 1])
    // of clusters_, whose flags are own_shared_edges_' (a cluster's apexes are in its own vertices).
    OccluderClusters clusters_;
    std::vector<std::uint32_t> cluster_first_;
    ObjectHierarchy hierarchy_;
    OcclusionBuffer buffer_;
    OcclusionMaps maps_;
    SceneCullTimings timings_;
    SceneCullWork work_;
    OverlapExitCounts exits_;

    // Per-frame state and scratch (reused, grown only).
    std::vector<std::uint32_t> frame_occluders_;  // object ids drawn this frame
    std::vector<std::uint32_t> frame_indices_;    // their triangles' indices into occluders_
    std::vector<std::uint8_t> frame_shared_;      // and their shared-edge flags
    std::vector<std::uint32_t> frame_apexes_;     // and the flags' apexes
    std::size_t frame_rendered_ = 0;              // triangles of frame_indices_ already rendered
    std::vector<std::uint32_t> frame_clusters_;   // with clusters: the drawn candidates' clusters
    std::size_t frame_clusters_rendered_ = 0;     // of those, already rendered
    std::size_t frame_cluster_triangles_waiting_ = 0;
    bool frame_started_ = false;                  // something was rendered this frame (the buffer is cleared)
    std::vector<std::uint32_t> temporal_pool_;    // temporal: the candidates not occluded last frame
    std::vector<std::uint32_t> ranked_;           // rank_occluders' choice
    std::vector<std::pair<float, std::uint32_t>> rank_scratch_, node_heap_;
    std::vector<Visibility> last_visibility_;
    std::vector<std::uint8_t> drawn_;  // per candidate k: drawn this frame
    bool has_history_ = false;

    static constexpr std::uint32_t kNone = ~std::uint32_t(0);
    struct Frame;
    void select_occluders(const Frame& frame);
    // Which shared-edge flags an occluder is drawn with (docs/scene-culling.md, "Shared edges").
    enum class EdgeFlags : std::uint8_t { own_object, across_objects };
    // Appends an occluder's triangles (or clusters), its LOD's when it has one usable from this
    // camera, with those flags (an LOD always has its own).
    void append_occluder(std::uint32_t id, const Camera& camera, EdgeFlags edge_flags);
    bool draws_lod(std::uint32_t id, const Camera& camera) const;
    void gather_lods();
    void build_clusters();
    // Triangles appended and not rendered yet (progressive draws every batch of them).
    std::size_t triangles_waiting() const { return frame_shared_.size() - frame_rendered_ + frame_cluster_triangles_waiting_; }
    void render_pending(const Frame& frame, const ParallelFor& parallel);
    void build_maps(const Frame& frame);
    void draw_newly_visible(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel);
    void traverse(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel);
    OccludeeAnswer test_object(const Frame& frame, std::uint32_t id);
    // Occludee triangles in world space (transformed as ground truth transforms them) for the
    // samples test: object id -> its first vertex in occludee_positions_, or kNotGathered.
    static constexpr std::size_t kNotGathered = ~std::size_t(0);
    std::vector<float> occludee_positions_;
    std::vector<std::size_t> occludee_first_vertex_;
    bool triangle_rectangles_hidden(const Object& object, const glm::dmat4& clip_from_world) const;
    // Per object, the triangle that found it visible last time: the next test starts there.
    std::vector<std::uint32_t> first_visible_triangle_;
    bool triangle_samples_hidden(std::size_t id, const std::array<float, 16>& clip_from_world, float& level_of_visibility);
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
