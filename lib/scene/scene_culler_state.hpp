#pragma once
// The scene culler's state and the implementation of its calls. homcull/scene_culler.hpp
// states the contracts and SceneCuller forwards each call here (scene_culler_calls.cpp).
// Private to the library.
#include <homcull/scene_culler.hpp>

#include "scene/occludee_parts.hpp"

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace homcull::detail {

class SceneCullerState {
public:
    // The calls of SceneCuller, with its contracts.
    SceneCullerState(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                     const ParallelFor& parallel);
    void cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel = {});
    void reset_history() { has_history_ = false; }
    const SceneCullerConfig& config() const { return config_; }
    const Scene& scene() const { return *scene_; }
    const OcclusionBuffer& buffer() const { return buffer_; }
    // The maps with their pyramids (made now when the frame's build left them out,
    // PyramidBuild::lazy), for dumps.
    const OcclusionMaps& maps() {
        if (maps_built_) maps_.build_pyramid();
        return maps_;
    }
    const SceneCullTimings& timings() const { return timings_; }
    const SceneCullWork& work() const { return work_; }
    const OverlapExitCounts& overlap_exits() const { return exits_; }
    const std::vector<std::uint32_t>& drawn_occluders() const { return frame_occluders_; }
    const ObjectHierarchy& hierarchy() const { return hierarchy_; }
    std::size_t occluder_objects() const { return occluder_ids_.size(); }
    std::size_t occluder_triangles() const { return occluders_.triangle_count(); }

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
    // config_.skip_closed_back_faces (triangles, not clusters): per candidate k, whether it is a closed mesh enclosing a
    // positive volume (find_closed_candidates), and per triangle of occluders_ the plane of its
    // front side, (n, d) with n the counter-clockwise normal: facing the eye when n.eye > d
    // (positions and eye relative to the anchor). Zero planes for the other candidates.
    std::vector<std::uint8_t> closed_;
    std::vector<float> front_planes_;
    void find_closed_candidates();
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
    // The same clustered triangles' flags across the whole candidate set (occluders_'), for the
    // frames that may use them (EdgeFlags::across_objects); an apex from another object is a
    // copy among the cluster's vertices, after those of its own triangles and own apexes.
    std::vector<std::uint8_t> cluster_cross_shared_edges_;
    std::vector<std::uint32_t> cluster_cross_edge_apexes_;
    // An edge of the cross-object flags whose neighbour is in another candidate.
    struct NeighbourEdge {
        std::uint32_t triangle;   // see each list
        std::uint32_t candidate;  // the neighbour's k
        std::uint8_t edge_bit;
    };
    // Clusters: cluster c's such edges are [cluster_neighbour_first_[c],
    // cluster_neighbour_first_[c + 1]) of cluster_neighbours_ (triangle: into the clustered
    // triangles). A frame that draws some candidates (EdgeFlags::drawn_neighbours) keeps such an
    // edge's flag in cluster_neighbour_edges_ (otherwise cluster_cross_shared_edges_) only when
    // the neighbour is drawn too.
    std::vector<NeighbourEdge> cluster_neighbours_;
    std::vector<std::uint32_t> cluster_neighbour_first_;
    std::vector<std::uint8_t> cluster_neighbour_edges_;
    // Triangles (no clusters): candidate k's such edges are [triangle_neighbour_first_[k],
    // triangle_neighbour_first_[k + 1]) of triangle_neighbours_ (triangle: into occluders_), in
    // triangle order. A frame's triangles drawn with EdgeFlags::drawn_neighbours take the
    // cross-object flags, and frame_neighbours_ lists their such edges (triangle: into
    // frame_shared_) until they are rendered, when each flag whose neighbour is not drawn is
    // cleared.
    std::vector<NeighbourEdge> triangle_neighbours_;
    std::vector<std::uint32_t> triangle_neighbour_first_;
    std::vector<NeighbourEdge> frame_neighbours_;
    // Which candidate each vertex of occluders_ belongs to (each object's vertices are its own).
    std::vector<std::uint32_t> vertex_candidates() const;
    void find_triangle_neighbours();
    // One candidate's clusters with the flags across objects beside them, numbered from its own
    // first vertex, triangle and neighbour edge: made in a task (candidate_clusters), then
    // appended in the candidates' order (append_candidate_clusters).
    struct CandidateClusters {
        OccluderClusters clusters;  // each cluster's positions, then its copies of apexes in other objects
        std::vector<std::uint8_t> cross_shared_edges;
        std::vector<std::uint32_t> cross_edge_apexes;
        std::vector<NeighbourEdge> neighbours;     // triangle: into clusters' triangles
        std::vector<std::uint32_t> neighbour_end;  // per cluster: where its neighbour edges end
    };
    CandidateClusters candidate_clusters(std::size_t k, OccluderClusters&& part, const std::vector<std::uint32_t>& vertex_candidate) const;
    void append_candidate_clusters(std::size_t k, const CandidateClusters& candidate);
    void keep_drawn_neighbours(std::size_t first_cluster, std::size_t end_cluster);
    void clear_undrawn_neighbours();
    ObjectHierarchy hierarchy_;
    OcclusionBuffer buffer_;
    OcclusionMaps maps_;
    bool maps_built_ = false;  // since the buffer was made (maps() may then make their pyramids)
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
    std::vector<Backface> frame_cluster_backfaces_;  // each one's backface mode (closed candidates': cw)
    std::size_t frame_clusters_rendered_ = 0;     // of those, already rendered
    // Which shared-edge flags occluders take (docs/scene-culling.md, "Shared edges"), from the
    // fewest flags kept to the most: own_object, each object's own (right for any subset);
    // drawn_neighbours, across objects where the neighbour is drawn too, decided when the
    // clusters or triangles are rendered; across_objects,
    // across the whole candidate set (every candidate that may meet the frustum is drawn). A
    // batch of clusters appended with several takes the first of them in this order.
    enum class EdgeFlags : std::uint8_t { own_object, drawn_neighbours, across_objects };
    EdgeFlags frame_cluster_flags_ = EdgeFlags::own_object;  // the flags the clusters not rendered yet all take
    std::size_t frame_cluster_triangles_waiting_ = 0;
    // Closed candidates' back faces left out and not rendered yet: they count towards
    // progressive's batches as if drawn, so that skipping them does not delay a batch.
    std::size_t frame_back_faces_waiting_ = 0;
    bool frame_started_ = false;                  // something was rendered this frame (the buffer is cleared)
    std::vector<std::uint32_t> temporal_pool_;    // temporal: the candidates not occluded last frame
    std::vector<std::uint32_t> ranked_;           // rank_occluders' choice
    std::vector<std::pair<float, std::uint32_t>> rank_scratch_, node_heap_;
    std::vector<Visibility> last_visibility_;
    glm::dvec3 last_eye_{0.0}, last_direction_{0.0};  // the camera of last_visibility_'s frame
    // temporal: whether this camera jumped from last frame's (SceneCullerConfig::temporal_cut).
    bool camera_cut(const Camera& camera) const;
    std::vector<std::uint8_t> drawn_;  // per candidate k: drawn this frame (1), as its LOD (2), or not (0)
    bool has_history_ = false;

    static constexpr std::uint32_t kNone = ~std::uint32_t(0);
    struct Frame;
    void select_occluders(const Frame& frame);
    // Appends an occluder's triangles (or clusters), its LOD's when it has one usable from this
    // camera, with those flags (an LOD always has its own).
    void append_occluder(std::uint32_t id, const Frame& frame, EdgeFlags edge_flags);
    bool draws_lod(std::uint32_t id, const Camera& camera) const;
    void gather_lods();
    void build_clusters(const ParallelFor& parallel);
    void reserve_frame_room();
    // Triangles appended and not rendered yet (progressive draws every batch of them).
    std::size_t triangles_waiting() const {
        return frame_shared_.size() - frame_rendered_ + frame_cluster_triangles_waiting_ + frame_back_faces_waiting_;
    }
    void render_pending(const Frame& frame, const ParallelFor& parallel);
    void build_maps(const Frame& frame);
    void draw_newly_visible(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel);
    void traverse(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel);
    OccludeeAnswer box_answer(const Frame& frame, const Aabb& box) const;
    // What object tests count, per task when they run in parallel (then added to work_ and exits_).
    // Each task counts into its own tally, written at every test: a cache line of its own, or
    // the two threads' tallies would share one and bounce it between the cores.
    struct alignas(64) TestTally {
        std::size_t nodes = 0, objects = 0, parts = 0, solid_parts = 0;
        std::uint64_t exits[7] = {};
    };
    void add_tally(const TestTally& tally);
    // Thread-safe for distinct objects: it writes only their answers and caches.
    OccludeeAnswer test_object(const Frame& frame, std::uint32_t id, TestTally& tally);
    // Whether a hierarchy node is tested and found hidden; its answer then goes to every object
    // under it. Thread-safe for disjoint subtrees.
    bool node_hidden(const Frame& frame, std::uint32_t node_index, std::vector<OccludeeAnswer>& answers, TestTally& tally) const;
    // one_pass and temporal with a job system: the buffer does not change during the tests, so
    // the hierarchy's subtrees are traversed in tasks (scene_traversal.cpp).
    void traverse_in_tasks(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel);
    std::vector<TestTally> task_tallies_;
    std::vector<std::uint32_t> subtrees_, next_subtrees_;  // traverse_in_tasks' frontier
    // Per task, room for a depth-first traversal's stack of nodes: the hierarchy's depth + 1.
    std::size_t task_stack_room_ = 0;
    std::vector<std::uint32_t> task_stacks_;
    // Occludee triangles in world space (transformed as ground truth transforms them) for the
    // samples test: object id -> its first vertex in occludee_positions_, or kNotGathered.
    static constexpr std::size_t kNotGathered = ~std::size_t(0);
    std::vector<float> occludee_positions_;
    std::vector<std::size_t> occludee_first_vertex_;
    bool triangle_rectangles_hidden(const Object& object, const glm::dmat4& clip_from_world) const;
    // Per object, the triangle that found it visible last time: the next test starts there
    // (with parts: numbered in the parts' order, OccludeeParts::indices).
    std::vector<std::uint32_t> first_visible_triangle_;
    OccludeeParts parts_;  // config_.occludee_parts
    std::vector<std::uint8_t> first_visible_part_;  // per object, the part found visible last time: tested first
    bool parts_hidden(const Frame& frame, std::uint32_t id, bool test_triangles, TestTally& tally);
    bool part_triangles_hidden(const Frame& frame, std::uint32_t id, std::uint32_t part, const OcclusionBuffer::ClosedSolid* solid);
    // Per object gathered for the samples test: +1 or -1 when closed (closed_occludees.hpp),
    // else 0; its part tests then leave out the triangles seen from behind.
    std::vector<std::int8_t> occludee_orientation_;
    bool beyond_near_plane(const Frame& frame, const Aabb& box) const;
    std::optional<OcclusionBuffer::ClosedSolid> seen_solid(const Frame& frame, std::uint32_t id) const;
    bool triangle_samples_hidden(std::size_t id, const std::array<float, 16>& clip_from_world, float& level_of_visibility);
};

}  // namespace homcull::detail
