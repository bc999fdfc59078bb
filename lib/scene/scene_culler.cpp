// SceneCuller: set-up, and a frame's occluder selection and rendering. The tests are in
// scene_traversal.cpp.
#include <homcull/detail/memory.hpp>
#include <homcull/error.hpp>
#include <homcull/scene_culler.hpp>

#include "scene/scene_culler_state.hpp"

#include "common/float_mode.hpp"
#include "common/run_tasks.hpp"
#include "scene/closed_occludees.hpp"
#include "scene/scene_culler_frame.hpp"
#include "scene/shared_plans.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace homcull {
namespace {

using Clock = std::chrono::steady_clock;

OcclusionMapsConfig maps_config(const SceneCullerConfig& c) {
    OcclusionMapsConfig m = c.maps;
    m.display_width = c.display.width;
    m.display_height = c.display.height;
    return m;
}

// The most edges from the root to a node (0 for a root alone or no nodes).
std::size_t hierarchy_depth(const ObjectHierarchy& hierarchy) {
    if (hierarchy.nodes.empty()) return 0;
    std::size_t deepest = 0;
    std::vector<std::pair<std::uint32_t, std::size_t>> stack{{0u, 0}};
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, depth);
        const ObjectHierarchy::Node& node = hierarchy.nodes[index];
        if (!node.leaf()) stack.insert(stack.end(), {{node.first_child, depth + 1}, {node.first_child + 1, depth + 1}});
    }
    return deepest;
}

// The display's view frustum in anchored world (positions minus `anchor`, as the objects' boxes),
// for the exact box tests of test_object and append_occluder. Ground truth counts a hit at a
// view depth from near to far (its rays are eye + t d with d's forward component 1, from t = near
// to far) through a pixel centre, half a pixel inside the screen's edges, from the eye rounded
// to float relative to the anchor. The frustum reaches 2^-10 of the depths past both planes, its
// extents are widened by 2^-22 of the eye's coordinates (the rounded eye is within 2^-24), and it
// separates only by 2^-20 of the terms' magnitudes, against the rounding of the boxes, the rays
// and the projections. A far plane too far for doubles leaves the axes it reaches out.
FrustumAxes view_frustum_axes(const Camera& camera, double aspect, const glm::dvec3& anchor) {
    Camera anchored = camera;
    anchored.eye -= anchor;
    anchored.target -= anchor;
    anchored.near_plane = camera.near_plane * (1.0 - 0x1.0p-10);
    anchored.far_plane = camera.far_plane * (1.0 + 0x1.0p-10);
    return frustum_axes(make_frustum(anchored, aspect), 0x1.0p-20, 0x1.0p-22 * glm::abs(anchored.eye));
}

}  // namespace

int automatic_samples(Resolution display, Resolution buffer) {
    if (buffer.width == 0 && buffer.height == 0) return 1;
    for (const int s : {4, 2})
        if (std::int64_t(buffer.width) * s <= display.width && std::int64_t(buffer.height) * s <= display.height) return s;
    return 1;
}

BufferConfig scene_buffer_config(const SceneCullerConfig& c, float near_w) {
    validate_resolution(c.display);
    if (c.samples != 0 && c.samples != 1 && c.samples != 2 && c.samples != 4)
        throw Error("samples per buffer pixel axis must be 1, 2 or 4 (or 0: automatic), got " + std::to_string(c.samples));
    if (!(c.buffer.width == 0 && c.buffer.height == 0)) validate_resolution(c.buffer);
    const int samples = c.samples != 0 ? c.samples : automatic_samples(c.display, c.buffer);
    BufferConfig b;
    b.samples = samples;
    b.near_w = near_w;
    b.isa = c.isa;
    b.sample_depth = c.sample_depth && resolved_occludee_shape(c) == OccludeeShape::samples;
    if (c.buffer.width == 0 && c.buffer.height == 0) {
        if (c.display.width % samples != 0 || c.display.height % samples != 0)
            throw Error("the display resolution " + std::to_string(c.display.width) + "x" + std::to_string(c.display.height) +
                        " is not a multiple of the samples per axis (" + std::to_string(samples) + "): give --buffer");
        b.width = c.display.width / samples;
        b.height = c.display.height / samples;
    } else {
        b.width = c.buffer.width;
        b.height = c.buffer.height;
    }
    const bool same_grid = b.width * samples == c.display.width && b.height * samples == c.display.height;
    if (c.maps.hole_pixels == 0.0 && !same_grid)
        throw Error("conservative culling needs the buffer's samples on the display's pixel centres: buffer x samples (" +
                    std::to_string(b.width * samples) + "x" + std::to_string(b.height * samples) + ") must equal the display (" +
                    std::to_string(c.display.width) + "x" + std::to_string(c.display.height) +
                    "); use a matching buffer or approximate mode");
    return b;
}

OccludeeShape resolved_occludee_shape(const SceneCullerConfig& config) {
    if (config.occludees != OccludeeShape::automatic) return config.occludees;
    return config.maps.depth == DepthTest::masked ? OccludeeShape::samples : OccludeeShape::rectangles;
}

detail::SceneCullerState::SceneCullerState(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                                           const ParallelFor& parallel)
    : scene_(&scene),
      config_(config),
      occluder_ids_(occluders),
      anchor_(scene_anchor(scene)),
      occluders_(gather_world_triangles(scene, occluders, anchor_, config.merge_coplanar_occluders, parallel)),
      hierarchy_(ObjectHierarchy::build(scene, config.hierarchy_leaf_size)),
      buffer_(scene_buffer_config(config, 0.1f)),
      maps_(buffer_, maps_config(config)) {
    config_.isa = buffer_.config().isa;  // the choice made now, for the buffers made when the near plane changes
    const detail::StandardFloatMode mode;  // float_mode.hpp
    if (config.strategy == CullStrategy::progressive && config.progressive_batch_triangles == 0)
        throw Error("progressive culling needs a batch of at least one triangle");
    if (config.occluder_budget.ranking == OccluderRanking::baked && !config.occluder_budget.grid)
        throw Error("baked occluder ranking needs a visibility grid");
    if (!(config.occluder_budget.min_projected_size >= 0.0))  // infinity allowed: no occluder drawn
        throw Error("an occluder's minimum projected size must be at least 0 square radians, got " +
                    std::to_string(config.occluder_budget.min_projected_size));
    if (config.occludee_parts < 0 || config.occludee_parts > 64)
        throw Error("occludee parts must be 0 to 64 per object, got " + std::to_string(config.occludee_parts));
    if (!(config.temporal_cut.step_in_near_planes >= 0.0))
        throw Error("a temporal camera cut's step must be at least 0 near distances, got " + std::to_string(config.temporal_cut.step_in_near_planes));
    if (!(config.temporal_cut.turn_degrees >= 0.0 && config.temporal_cut.turn_degrees <= 180.0))
        throw Error("a temporal camera cut's turn must be 0 to 180 degrees, got " + std::to_string(config.temporal_cut.turn_degrees));
    detail::reserve_written(temporal_pool_, occluders.size());
    detail::reserve_written(ranked_, occluders.size());
    detail::reserve_written(rank_scratch_, occluders.size());
    // Where each candidate's triangles are, and their shared edges within the object alone.
    candidate_of_.assign(scene.objects.size(), kNone);
    for (std::size_t k = 0; k < occluders.size(); ++k) candidate_of_[occluders[k]] = std::uint32_t(k);
    first_triangle_ = occluders_.object_first_triangle;
    own_shared_edges_.resize(occluders_.triangle_count());
    own_edge_apexes_.resize(3 * occluders_.triangle_count());
    for_each_index(parallel, occluders.size(), 8, [&](std::size_t k) {
        const std::size_t first = first_triangle_[k], count = first_triangle_[k + 1] - first;
        if (count == 0) return;
        compute_shared_edges(occluders_.positions.data(), 3 * sizeof(float), occluders_.positions.size() / 3,
                             occluders_.indices.data() + 3 * first, count, own_shared_edges_.data() + first,
                             own_edge_apexes_.data() + 3 * first);
    });
    // The boxes the buffer and the maps test, relative to the anchor as the triangles are.
    object_boxes_.reserve(scene.objects.size());
    for (const Object& object : scene.objects) object_boxes_.push_back(anchored_box(object.world_bounds, anchor_));
    node_boxes_.reserve(hierarchy_.nodes.size());
    for (const ObjectHierarchy::Node& node : hierarchy_.nodes) node_boxes_.push_back(anchored_box(node.bounds, anchor_));
    find_closed_candidates();
    gather_lods();
    build_clusters(parallel);
    find_triangle_neighbours();
    reserve_frame_room();
    drawn_.assign(occluders.size(), 0);
    detail::reserve_written(frame_occluders_, occluders.size());
    last_visibility_.assign(scene.objects.size(), Visibility::visible);
    task_tallies_.resize(64);
    detail::reserve_written(subtrees_, hierarchy_.nodes.size());
    detail::reserve_written(next_subtrees_, hierarchy_.nodes.size());
    detail::reserve_written(node_heap_, hierarchy_.nodes.size());  // front-to-back traversal (one thread or progressive)
    // Rounded up to whole cache lines and one line more, so that two tasks' stacks, pushed and
    // popped at every node, share no line (the vector's start need not be a line's).
    constexpr std::size_t kLineWords = 64 / sizeof(std::uint32_t);
    task_stack_room_ = (hierarchy_depth(hierarchy_) + 1 + kLineWords - 1) / kLineWords * kLineWords + kLineWords;
    task_stacks_.resize(task_tallies_.size() * task_stack_room_);

    // Approximate mode: each part would tolerate the holes again, so no parts.
    parts_.build(scene, config.maps.hole_pixels == 0.0 ? config.occludee_parts : 0, config.triangle_test_limit, anchor_, parallel);
    first_visible_part_.assign(scene.objects.size(), 0);
    if (resolved_occludee_shape(config) != OccludeeShape::samples) return;
    occludee_first_vertex_.assign(scene.objects.size(), kNotGathered);
    first_visible_triangle_.assign(scene.objects.size(), 0);
    std::size_t vertices = 0;
    for (std::size_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        if (scene.triangle_count(object) > config.triangle_test_limit) continue;
        occludee_first_vertex_[id] = vertices;
        vertices += scene.meshes[object.mesh].positions.size();
    }
    occludee_positions_.resize(3 * vertices);
    for_each_index(parallel, scene.objects.size(), 16, [&](std::size_t id) {
        const Object& object = scene.objects[id];
        if (occludee_first_vertex_[id] != kNotGathered)
            write_world_positions(object, scene.meshes[object.mesh], occludee_positions_.data() + 3 * occludee_first_vertex_[id], anchor_);
    });
    occludee_orientation_ = closed_occludee_orientations(scene, occludee_positions_, occludee_first_vertex_, kNotGathered, parallel);
}

void detail::SceneCullerState::cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    const detail::StandardFloatMode mode;  // float_mode.hpp
    validate_camera(camera);
    if (camera.ortho_height > 0.0)
        throw Error("scene culler: orthographic cameras are not supported (its occlusion maps compare perspective depths); the "
                    "occlusion buffer and the C interface take orthographic projections");
    // The near plane is the camera's: the buffer and the maps take a new one without
    // allocating (rebuilt, they took 48 ms and 3,930 page faults at 720p).
    if (buffer_.config().near_w != float(camera.near_plane)) {
        buffer_.set_near_w(float(camera.near_plane));
        maps_.set_near_w(float(camera.near_plane));
        maps_built_ = false;
    }
    const double aspect = config_.display.aspect();
    // The buffer's matrix takes positions relative to the anchor: composed in double, so that the
    // float matrix holds the eye's offset from the scene, not from the world's origin.
    const glm::dmat4 clip_double = projection_matrix(camera, aspect) * view_matrix(camera);
    const Frame frame{&camera, float_matrix(clip_double * glm::translate(glm::dmat4(1.0), anchor_)), clip_double,
                      view_frustum_axes(camera, aspect, anchor_)};
    timings_ = {};
    work_ = {};
    exits_ = {};
    for (std::uint32_t id : frame_occluders_) drawn_[candidate_of_[id]] = 0;
    frame_occluders_.clear();
    frame_indices_.clear();
    frame_shared_.clear();
    frame_apexes_.clear();
    frame_rendered_ = 0;  // the buffer is cleared by the frame's first render (render_frame), or by build_maps
    frame_neighbours_.clear();
    frame_clusters_.clear();
    frame_cluster_backfaces_.clear();
    frame_clusters_rendered_ = 0;
    frame_cluster_flags_ = EdgeFlags::own_object;
    frame_cluster_triangles_waiting_ = 0;
    frame_back_faces_waiting_ = 0;
    frame_started_ = false;

    // one_pass (and temporal's first frame, or its first after a cut): the candidates in the
    // frustum. temporal: those not found occluded last frame. progressive draws as it traverses.
    if (config_.strategy == CullStrategy::temporal && has_history_ && camera_cut(camera)) has_history_ = false;
    work_.used_history = config_.strategy == CullStrategy::temporal && has_history_;
    if (config_.strategy != CullStrategy::progressive) {
        select_occluders(frame);
        render_pending(frame, parallel);
    }
    build_maps(frame);
    traverse(frame, answers, parallel);
    if (config_.strategy == CullStrategy::temporal && has_history_) draw_newly_visible(frame, answers, parallel);

    if (config_.strategy == CullStrategy::temporal) {
        for (std::size_t id = 0; id < answers.size(); ++id) last_visibility_[id] = answers[id].visibility;
        has_history_ = true;
        last_eye_ = camera.eye;
        last_direction_ = glm::normalize(camera.target - camera.eye);
    }
}

bool detail::SceneCullerState::camera_cut(const Camera& camera) const {
    const TemporalCut& cut = config_.temporal_cut;
    const double step = glm::length(camera.eye - last_eye_);
    const double cos_turn = glm::dot(glm::normalize(camera.target - camera.eye), last_direction_);
    // A turn of exactly the limit is no cut; 180 degrees is never one (cos_turn >= -1 up to rounding).
    const bool turned = cut.turn_degrees < 180.0 && cos_turn < std::cos(glm::radians(cut.turn_degrees));
    return step > cut.step_in_near_planes * camera.near_plane || turned;
}

// one_pass and temporal: the frame's occluders into frame_indices_. temporal keeps the
// candidates that were not found occluded last frame: those seen, and those that were outside
// the frustum (rank_occluders then keeps the ones inside it now).
//
// Shared-edge flags: an edge may go without its coverage margin only where the neighbour
// across it is drawn too. Within an object that always holds. Between objects it holds when
// every candidate whose box may meet the frustum is drawn: a neighbour left out lies wholly
// outside a frustum plane, and so does the edge it shares, at least half a sample from every
// sample centre, far beyond the margin's 2^-10 sample (near plane: the part of a triangle
// before it is clipped away, and the edge with it). With a budget or temporal's choice,
// neighbours may be missing: the flags across objects then, each kept only where the neighbour
// is drawn too (EdgeFlags::drawn_neighbours), or, with an LOD drawn, each object's own.
void detail::SceneCullerState::select_occluders(const Frame& frame) {
    const auto start = Clock::now();
    const std::vector<std::uint32_t>* pool = &occluder_ids_;
    if (config_.strategy == CullStrategy::temporal && has_history_) {
        temporal_pool_.clear();
        for (std::uint32_t id : occluder_ids_)
            if (last_visibility_[id] != Visibility::occluded) temporal_pool_.push_back(id);
        pool = &temporal_pool_;
    }
    rank_occluders(*scene_, *pool, *frame.camera, config_.display.aspect(), config_.occluder_budget, ranked_, rank_scratch_,
                   config_.lods);
    // Cross-object flags also need every neighbour drawn as itself, not as an LOD; where some
    // candidates are left out, the clusters and triangles keep the flags of the edges whose
    // neighbour is drawn.
    bool any_lod = false;
    for (std::size_t i = 0; i < ranked_.size() && !any_lod; ++i) any_lod = draws_lod(ranked_[i], *frame.camera);
    const bool every_candidate_in_frustum =
        pool == &occluder_ids_ && config_.occluder_budget.triangles == 0 && !(config_.occluder_budget.min_projected_size > 0.0) && !any_lod;
    const EdgeFlags flags = every_candidate_in_frustum ? EdgeFlags::across_objects : any_lod ? EdgeFlags::own_object : EdgeFlags::drawn_neighbours;
    for (std::uint32_t id : ranked_) append_occluder(id, frame, flags);
    timings_.select_ms += ms_since(start);
}

// The LODs' triangles in world space, after the candidates' own vertices, placed exactly as the
// originals are (transform_point), with shared-edge flags within each LOD.
void detail::SceneCullerState::gather_lods() {
    lod_first_.assign(occluder_ids_.size() + 1, 0);
    if (!config_.lods) return;
    if (config_.lods->lod_of_mesh.size() != scene_->meshes.size())
        throw Error("the occluder LODs were built for another scene (" + std::to_string(config_.lods->lod_of_mesh.size()) +
                    " meshes, " + scene_->source + " has " + std::to_string(scene_->meshes.size()) + ")");
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k) {
        const Object& object = scene_->objects[occluder_ids_[k]];
        lod_first_[k + 1] = lod_first_[k];
        const OccluderLod* lod = config_.lods->lod_for(occluder_ids_[k], object.mesh);
        if (!lod || lod->mesh.triangle_count() == 0) continue;
        const auto base = std::uint32_t(occluders_.positions.size() / 3);
        for (const glm::vec3& p : lod->mesh.positions) {
            const glm::vec3 w = transform_point_from(object.world, p, anchor_);
            occluders_.positions.insert(occluders_.positions.end(), {w.x, w.y, w.z});
        }
        for (std::uint32_t index : lod->mesh.indices) lod_indices_.push_back(base + index);
        lod_first_[k + 1] += std::uint32_t(lod->mesh.triangle_count());
    }
    lod_shared_edges_.resize(lod_indices_.size() / 3);
    lod_edge_apexes_.resize(lod_indices_.size());
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k) {
        const std::size_t first = lod_first_[k], count = lod_first_[k + 1] - first;
        if (count == 0) continue;
        compute_shared_edges(occluders_.positions.data(), 3 * sizeof(float), occluders_.positions.size() / 3,
                             lod_indices_.data() + 3 * first, count, lod_shared_edges_.data() + first, lod_edge_apexes_.data() + 3 * first);
    }
}

// The room for the largest frame this culler can draw, made now (its pages written) so that no
// cull() allocates (homcull/scene_culler.hpp): the buffer's for every candidate's clusters in
// one render, on one thread or as a task list with a job system, and for the triangles that go
// triangle by triangle (every candidate's without clusters, else the LODs'), with a job system
// too (either only when config_.job_system says one may come); and the frame's lists of those
// triangles. Grown during a frame, that room would bring its page faults into the frame: tens of
// milliseconds for a two-thread first frame drawing every candidate of a large scene.
void detail::SceneCullerState::reserve_frame_room() {
    const std::size_t triangles = (config_.occluder_clusters ? 0 : occluders_.triangle_count()) + lod_indices_.size() / 3;
    BufferReserve r;
    if (config_.occluder_clusters) {
        r.max_clusters = clusters_.clusters.size();
        r.max_cluster_vertices = clusters_.max_cluster_vertices;
        if (config_.job_system) {
            r.max_task_list_clusters = clusters_.clusters.size();
            r.max_task_list_draws = 1;  // each render is a list of one draw
            r.max_task_list_triangles = clusters_.shared_edges.size();
        }
    }
    if (triangles > 0) {
        r.max_triangles = triangles;
        r.max_vertices = occluders_.positions.size() / 3;
        // Any job system: the waves' room does not depend on its threads (world positions: no row parts).
        r.max_threads = config_.job_system ? 2 : 0;
    }
    buffer_.reserve(r);
    detail::reserve_written(frame_indices_, 3 * triangles);
    detail::reserve_written(frame_shared_, triangles);
    detail::reserve_written(frame_apexes_, 3 * triangles);
}

// config_.occluder_clusters: each candidate's triangles split into clusters of their own (so
// that a frame draws the clusters of the candidates it picks), one after the other in clusters_,
// with the flags within each object (own_shared_edges_), right whichever candidates a frame
// draws, and beside them the flags across objects, for frames that draw every candidate in the
// frustum (candidate_clusters).
void detail::SceneCullerState::build_clusters(const ParallelFor& parallel) {
    if (!config_.occluder_clusters) return;
    cluster_first_.assign(1, 0);
    cluster_neighbour_first_.assign(1, 0);
    const std::vector<std::uint32_t> vertex_candidate = vertex_candidates();
    // Each candidate's triangles relative to its first vertex: each object's vertices are
    // together in occluders_.positions, and a build sees only those (meshoptimizer's work grows
    // with the vertices it is given).
    const std::size_t candidates = occluder_ids_.size();
    std::vector<LocalTriangles> local(candidates);
    std::vector<std::uint32_t> mesh_of(candidates);
    for_each_index(parallel, candidates, 8, [&](std::size_t k) {
        const std::size_t first = first_triangle_[k], count = first_triangle_[k + 1] - first;
        const auto begin = occluders_.indices.begin() + std::ptrdiff_t(3 * first), end = begin + std::ptrdiff_t(3 * count);
        mesh_of[k] = scene_->objects[occluder_ids_[k]].mesh;
        LocalTriangles& m = local[k];
        m.base = count ? *std::min_element(begin, end) : 0;
        m.vertices = count ? std::size_t(*std::max_element(begin, end) - m.base) + 1 : 0;
        m.indices.assign(begin, end);
        for (std::uint32_t& v : m.indices) v -= m.base;
    });
    // Candidates that place the same mesh with the same triangles share one plan (which
    // triangles and vertices each cluster takes: meshoptimizer's meshlets, most of the build),
    // made from the first of them; each then gets its clusters from its own positions and flags.
    // The castle's 115 role occluders place 16 meshes. (A merge of coplanar triangles can give
    // two placements different triangles: then each has its own plan.)
    const std::vector<std::uint32_t> plan_of = first_with_same_triangles(mesh_of, local);
    const auto positions_of = [&](std::size_t k) { return occluders_.positions.data() + 3 * std::size_t(local[k].base); };
    std::vector<OccluderClusterPlan> plans(candidates);
    for_each_index(parallel, candidates, 2, [&](std::size_t k) {
        if (plan_of[k] == k)
            plans[k] = plan_occluder_clusters(positions_of(k), 3 * sizeof(float), local[k].vertices, local[k].indices.data(),
                                              local[k].indices.size() / 3);
    });
    // Each candidate's clusters, with the flags across objects, in a task of its own; then
    // appended in the candidates' order.
    std::vector<CandidateClusters> parts(candidates);
    for_each_index(parallel, candidates, 4, [&](std::size_t k) {
        const std::size_t first = first_triangle_[k], count = first_triangle_[k + 1] - first;
        std::vector<std::uint32_t> local_apexes(own_edge_apexes_.begin() + std::ptrdiff_t(3 * first),
                                                own_edge_apexes_.begin() + std::ptrdiff_t(3 * (first + count)));
        for (std::uint32_t& v : local_apexes) v = v == kNoApex ? kNoApex : v - local[k].base;
        parts[k] = candidate_clusters(k,
                                      build_occluder_clusters(plans[plan_of[k]], positions_of(k), 3 * sizeof(float),
                                                              own_shared_edges_.data() + first, local_apexes.data()),
                                      vertex_candidate);
    });
    local = {}, plans = {};
    // Room for every candidate's clusters at once (appended in growing vectors, the castle's
    // copied their contents again at every doubling and wrote twice the pages).
    std::size_t clusters = 0, triangles = 0, positions = 0, neighbours = 0;
    for (const CandidateClusters& part : parts) {
        clusters += part.clusters.clusters.size();
        triangles += part.clusters.triangle_count();
        positions += part.clusters.positions.size();
        neighbours += part.neighbours.size();
    }
    clusters_.clusters.reserve(clusters);
    clusters_.positions.reserve(positions);
    clusters_.indices.reserve(3 * triangles);
    clusters_.shared_edges.reserve(triangles);
    clusters_.edge_apexes.reserve(3 * triangles);
    clusters_.source_triangles.reserve(triangles);
    cluster_cross_shared_edges_.reserve(triangles);
    cluster_cross_edge_apexes_.reserve(3 * triangles);
    cluster_neighbours_.reserve(neighbours);
    cluster_neighbour_first_.reserve(clusters + 1);
    cluster_first_.reserve(candidates + 1);
    for (std::size_t k = 0; k < candidates; ++k) {
        append_candidate_clusters(k, parts[k]);
        parts[k] = {};  // freed once added: the parts together are a second copy of every candidate's clusters
        cluster_first_.push_back(std::uint32_t(clusters_.clusters.size()));
    }
    cluster_neighbour_edges_ = cluster_cross_shared_edges_;
    detail::reserve_written(frame_clusters_, clusters_.clusters.size());
    detail::reserve_written(frame_cluster_backfaces_, clusters_.clusters.size());
}

std::vector<std::uint32_t> detail::SceneCullerState::vertex_candidates() const {
    std::vector<std::uint32_t> vertex_candidate(occluders_.positions.size() / 3, kNone);
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k)
        for (std::size_t i = 3 * std::size_t(first_triangle_[k]); i < 3 * std::size_t(first_triangle_[k + 1]); ++i)
            vertex_candidate[occluders_.indices[i]] = std::uint32_t(k);
    return vertex_candidate;
}

// Occluders drawn as triangles: each candidate's edges whose cross-object flag names an apex in
// another candidate (for EdgeFlags::drawn_neighbours, as candidate_clusters lists them for
// clusters, an apex in no candidate listed with kNone, never drawn).
void detail::SceneCullerState::find_triangle_neighbours() {
    triangle_neighbour_first_.assign(1, 0);
    if (config_.occluder_clusters) return;
    const std::vector<std::uint32_t> vertex_candidate = vertex_candidates();
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k) {
        for (std::uint32_t t = first_triangle_[k]; t < first_triangle_[k + 1]; ++t)
            for (std::size_t e = 0; e < 3; ++e) {
                if (!((occluders_.shared_edges[t] >> e) & 1u)) continue;
                const std::uint32_t apex = occluders_.edge_apexes[3 * std::size_t(t) + e];
                if (apex < vertex_candidate.size() && vertex_candidate[apex] != k)  // kNone: in no candidate, never drawn
                    triangle_neighbours_.push_back({t, vertex_candidate[apex], std::uint8_t(1u << e)});
            }
        triangle_neighbour_first_.push_back(std::uint32_t(triangle_neighbours_.size()));
    }
    detail::reserve_written(frame_neighbours_, triangle_neighbours_.size());
}

// Candidate k's clusters (built with its own flags), each with the cross-object flags of its
// triangles beside them. An apex the own flags already name keeps its cluster vertex; an apex in
// another object becomes a vertex of the cluster (found among its vertices by position, or a
// copy appended), so that either set of flags names apexes among the cluster's own vertices, as
// the render requires. Reads the culler's arrays only: candidates are made in tasks.
detail::SceneCullerState::CandidateClusters detail::SceneCullerState::candidate_clusters(std::size_t k, OccluderClusters&& part,
                                                                                        const std::vector<std::uint32_t>& vertex_candidate) const {
    const std::size_t first = first_triangle_[k];
    const std::size_t occluder_vertices = occluders_.positions.size() / 3;
    CandidateClusters out;
    OccluderClusters& made = out.clusters;
    made.clusters.reserve(part.clusters.size());
    made.positions.reserve(part.positions.size());
    out.cross_shared_edges.reserve(part.triangle_count());
    out.cross_edge_apexes.reserve(3 * part.triangle_count());
    out.neighbour_end.reserve(part.clusters.size());
    for (OccluderCluster c : part.clusters) {
        const std::uint32_t part_first_vertex = c.first_vertex;
        c.first_vertex = std::uint32_t(made.positions.size() / 3);
        const auto own_positions = part.positions.begin() + 3 * std::ptrdiff_t(part_first_vertex);
        made.positions.insert(made.positions.end(), own_positions, own_positions + 3 * std::ptrdiff_t(c.vertex_count));
        for (std::uint32_t i = 0; i < c.triangle_count; ++i) {
            const std::size_t local = std::size_t(c.first_triangle) + i;  // within part
            const std::size_t source = first + part.source_triangles[local];
            const std::uint8_t flags = occluders_.shared_edges[source];
            out.cross_shared_edges.push_back(flags);
            for (std::size_t e = 0; e < 3; ++e) {
                const std::uint32_t apex = (flags >> e) & 1u ? occluders_.edge_apexes[3 * source + e] : kNoApex;
                if (apex < occluder_vertices && vertex_candidate[apex] != k)
                    out.neighbours.push_back({std::uint32_t(local), vertex_candidate[apex], std::uint8_t(1u << e)});
                if (apex >= occluder_vertices) {  // none (the render drops a flag without an apex)
                    out.cross_edge_apexes.push_back(kNoApex);
                } else if ((own_shared_edges_[source] >> e) & 1u && own_edge_apexes_[3 * source + e] == apex &&
                           part.edge_apexes[3 * local + e] != kNoApex) {
                    out.cross_edge_apexes.push_back(part.edge_apexes[3 * local + e]);
                } else {
                    const float* p = occluders_.positions.data() + 3 * std::size_t(apex);
                    const std::size_t begin = 3 * std::size_t(c.first_vertex), end = made.positions.size();
                    std::size_t at = begin;
                    while (at < end && !(made.positions[at] == p[0] && made.positions[at + 1] == p[1] && made.positions[at + 2] == p[2]))
                        at += 3;
                    if (at == end) made.positions.insert(made.positions.end(), p, p + 3);
                    out.cross_edge_apexes.push_back(std::uint32_t((at - begin) / 3));
                }
            }
        }
        c.vertex_count = std::uint32_t(made.positions.size() / 3 - c.first_vertex);
        made.max_cluster_vertices = std::max(made.max_cluster_vertices, c.vertex_count);
        made.clusters.push_back(c);
        out.neighbour_end.push_back(std::uint32_t(out.neighbours.size()));
    }
    made.indices = std::move(part.indices);
    made.shared_edges = std::move(part.shared_edges);
    made.edge_apexes = std::move(part.edge_apexes);
    made.source_triangles = std::move(part.source_triangles);
    return out;
}

// Candidate k's clusters appended to clusters_ and the cross-object arrays, renumbered.
void detail::SceneCullerState::append_candidate_clusters(std::size_t k, const CandidateClusters& candidate) {
    const std::size_t first = first_triangle_[k];
    const OccluderClusters& made = candidate.clusters;
    const auto vertex_base = std::uint32_t(clusters_.positions.size() / 3), triangle_base = std::uint32_t(clusters_.shared_edges.size());
    const auto neighbour_base = std::uint32_t(cluster_neighbours_.size());
    for (OccluderCluster c : made.clusters) {
        c.first_vertex += vertex_base;
        c.first_triangle += triangle_base;
        clusters_.clusters.push_back(c);
    }
    clusters_.max_cluster_vertices = std::max(clusters_.max_cluster_vertices, made.max_cluster_vertices);
    clusters_.positions.insert(clusters_.positions.end(), made.positions.begin(), made.positions.end());
    clusters_.indices.insert(clusters_.indices.end(), made.indices.begin(), made.indices.end());
    clusters_.shared_edges.insert(clusters_.shared_edges.end(), made.shared_edges.begin(), made.shared_edges.end());
    clusters_.edge_apexes.insert(clusters_.edge_apexes.end(), made.edge_apexes.begin(), made.edge_apexes.end());
    for (const std::uint32_t t : made.source_triangles) clusters_.source_triangles.push_back(std::uint32_t(first) + t);
    cluster_cross_shared_edges_.insert(cluster_cross_shared_edges_.end(), candidate.cross_shared_edges.begin(),
                                       candidate.cross_shared_edges.end());
    cluster_cross_edge_apexes_.insert(cluster_cross_edge_apexes_.end(), candidate.cross_edge_apexes.begin(),
                                      candidate.cross_edge_apexes.end());
    for (const NeighbourEdge& n : candidate.neighbours) cluster_neighbours_.push_back({n.triangle + triangle_base, n.candidate, n.edge_bit});
    for (const std::uint32_t end : candidate.neighbour_end) cluster_neighbour_first_.push_back(neighbour_base + end);
}

// A candidate is closed when every edge of its triangles is shared within the object, in
// opposite order (own_shared_edges_: all three bits), and it encloses a positive volume (the
// divergence theorem over its triangles: the counter-clockwise normals point out of the solid,
// so an eye in free space sees their front sides). Drawn as triangles, its triangles' front
// planes are kept for the per-frame test; drawn as clusters, the rasterizer culls its back
// faces (append_occluder).
void detail::SceneCullerState::find_closed_candidates() {
    closed_.assign(occluder_ids_.size(), 0);
    if (!config_.skip_closed_back_faces || config_.backface != Backface::none) return;
    if (!config_.occluder_clusters) front_planes_.assign(4 * occluders_.triangle_count(), 0.0f);
    const auto vertex = [&](std::uint32_t v) {
        return glm::dvec3(occluders_.positions[3 * std::size_t(v)], occluders_.positions[3 * std::size_t(v) + 1],
                          occluders_.positions[3 * std::size_t(v) + 2]);
    };
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k) {
        const std::size_t first = first_triangle_[k], last = first_triangle_[k + 1];
        bool closed = last > first;
        double volume = 0.0;
        for (std::size_t t = first; t < last && closed; ++t) {
            closed = own_shared_edges_[t] == 7;
            const glm::dvec3 a = vertex(occluders_.indices[3 * t]), b = vertex(occluders_.indices[3 * t + 1]),
                             c = vertex(occluders_.indices[3 * t + 2]);
            volume += glm::dot(a, glm::cross(b, c));  // 6 times the signed volume of (origin, a, b, c)
        }
        if (!closed || !(volume > 0.0)) continue;
        closed_[k] = 1;
        for (std::size_t t = first; t < last && !config_.occluder_clusters; ++t) {
            const glm::dvec3 a = vertex(occluders_.indices[3 * t]), b = vertex(occluders_.indices[3 * t + 1]),
                             c = vertex(occluders_.indices[3 * t + 2]);
            const glm::dvec3 n = glm::cross(b - a, c - a);
            float* plane = front_planes_.data() + 4 * t;
            plane[0] = float(n.x), plane[1] = float(n.y), plane[2] = float(n.z), plane[3] = float(glm::dot(n, a));
        }
    }
}

bool detail::SceneCullerState::draws_lod(std::uint32_t id, const Camera& camera) const {
    const std::uint32_t k = candidate_of_[id];
    return lod_first_[k] < lod_first_[k + 1] && lod_usable(scene_->objects[id].world_bounds, camera);
}

void detail::SceneCullerState::append_occluder(std::uint32_t id, const Frame& frame, EdgeFlags edge_flags) {
    const Camera& camera = *frame.camera;
    const std::uint32_t k = candidate_of_[id];
    const bool lod = draws_lod(id, camera);
    // drawn_neighbours starts from the cross-object flags, cleared where the neighbour is not
    // drawn when the clusters or triangles are rendered.
    const bool own = edge_flags == EdgeFlags::own_object;
    const std::vector<std::uint32_t>& indices = lod ? lod_indices_ : occluders_.indices;
    const std::vector<std::uint8_t>& flags = lod ? lod_shared_edges_ : own ? own_shared_edges_ : occluders_.shared_edges;
    const std::vector<std::uint32_t>& apexes = lod ? lod_edge_apexes_ : own ? own_edge_apexes_ : occluders_.edge_apexes;
    const std::uint32_t first = lod ? lod_first_[k] : first_triangle_[k], last = lod ? lod_first_[k + 1] : first_triangle_[k + 1];
    frame_occluders_.push_back(id);
    drawn_[k] = lod ? 2 : 1;
    ++work_.occluder_objects;
    work_.occluder_triangles += last - first;
    work_.occluder_lods += lod;
    if (config_.occluder_clusters && !lod) {
        // A closed candidate's clusters without their back faces (find_closed_candidates): its
        // triangles face out counter-clockwise in world space, so its front faces are
        // counter-clockwise in the GL clip space (y up) the culler projects to.
        const Backface backface = closed_[k] ? Backface::cw : config_.backface;
        // A batch not rendered yet takes the flags all its clusters may take (EdgeFlags' order).
        frame_cluster_flags_ = frame_clusters_.size() == frame_clusters_rendered_ ? edge_flags : std::min(frame_cluster_flags_, edge_flags);
        // A cluster whose box (OccluderCluster::bounds, of its own vertices, in anchored world)
        // misses the frustum (Frame::frustum) is left out. The buffer places
        // a cluster by the screen rectangle of its box's corners, which covers part of the screen
        // for a cluster beside the view that reaches behind the eye or past a corner of the
        // frustum, then sets up every triangle to find each outside (on castle views C1-C3, most
        // of the triangles set up). Such a cluster claims no sample in front of the far plane,
        // and leaves no hole where it is left out: an edge a neighbour shares with it lies in its
        // box, outside the frustum, half a sample from every sample centre.
        for (std::uint32_t c = cluster_first_[k]; c < cluster_first_[k + 1]; ++c) {
            const OccluderCluster& cluster = clusters_.clusters[c];
            if (cluster.bounded && separated(frame.frustum, cluster.bounds)) continue;
            frame_clusters_.push_back(c);
            frame_cluster_backfaces_.push_back(backface);
        }
        frame_cluster_triangles_waiting_ += last - first;
        return;
    }
    // drawn_neighbours: this candidate's edges shared with others, in triangle order, each noted
    // at its place in frame_shared_ as its triangle is appended.
    const bool note_neighbours = !lod && edge_flags == EdgeFlags::drawn_neighbours;
    std::uint32_t n = note_neighbours ? triangle_neighbour_first_[k] : 0;
    const std::uint32_t n_end = note_neighbours ? triangle_neighbour_first_[k + 1] : 0;
    const auto note_neighbours_of = [&](std::uint32_t t) {
        for (; n < n_end && triangle_neighbours_[n].triangle <= t; ++n)
            if (triangle_neighbours_[n].triangle == t)
                frame_neighbours_.push_back({std::uint32_t(frame_shared_.size()), triangle_neighbours_[n].candidate, triangle_neighbours_[n].edge_bit});
    };
    if (!lod && closed_[k]) {
        // The triangles facing the eye (find_closed_candidates); a triangle seen edge-on, or one
        // whose sign rounds the wrong way, may go either way: leaving it out only loses occlusion.
        const glm::dvec3 eye = camera.eye - anchor_;
        const float ex = float(eye.x), ey = float(eye.y), ez = float(eye.z);
        for (std::uint32_t t = first; t < last; ++t) {
            const float* p = front_planes_.data() + 4 * std::size_t(t);
            if (!(p[0] * ex + p[1] * ey + p[2] * ez > p[3])) {
                ++work_.back_faces_skipped;
                ++frame_back_faces_waiting_;
                continue;
            }
            note_neighbours_of(t);
            frame_indices_.insert(frame_indices_.end(), indices.begin() + 3 * std::ptrdiff_t(t), indices.begin() + 3 * std::ptrdiff_t(t + 1));
            frame_shared_.push_back(flags[t]);
            frame_apexes_.insert(frame_apexes_.end(), apexes.begin() + 3 * std::ptrdiff_t(t), apexes.begin() + 3 * std::ptrdiff_t(t + 1));
        }
        return;
    }
    for (; n < n_end; ++n) {
        const NeighbourEdge& edge = triangle_neighbours_[n];
        frame_neighbours_.push_back({std::uint32_t(frame_shared_.size() + (edge.triangle - first)), edge.candidate, edge.edge_bit});
    }
    frame_indices_.insert(frame_indices_.end(), indices.begin() + 3 * std::size_t(first), indices.begin() + 3 * std::size_t(last));
    frame_shared_.insert(frame_shared_.end(), flags.begin() + first, flags.begin() + last);
    frame_apexes_.insert(frame_apexes_.end(), apexes.begin() + 3 * std::ptrdiff_t(first), apexes.begin() + 3 * std::ptrdiff_t(last));
}

// temporal's second pass. Last frame's answers leave out the candidates that were hidden; one
// that has come into view this frame is found visible without having been drawn, and what it
// hides is missed (a frame late, as Zhang's eq. 7.1 set alone would have it). Such candidates
// are drawn now (nearest first, within what the budget leaves), the maps rebuilt, and the objects found
// visible tested again. Hidden answers stay: drawing more only hides more. This is the second
// phase of two-phase temporal occlusion culling (Haar and Aaltonen, "GPU-driven rendering
// pipelines", SIGGRAPH 2015 course), here run only in frames where some candidate came into view.
void detail::SceneCullerState::draw_newly_visible(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    auto start = Clock::now();
    const std::size_t budget = config_.occluder_budget.triangles;
    std::size_t left = budget == 0 ? ~std::size_t(0) : budget - std::min(budget, work_.occluder_triangles);
    const std::size_t drawn_before = frame_occluders_.size();
    // Nearest first, so that a budget goes to the occluders most likely to hide much.
    rank_scratch_.clear();
    for (std::size_t k = 0; k < occluder_ids_.size(); ++k) {
        const std::uint32_t id = occluder_ids_[k];
        if (drawn_[k] || answers[id].visibility != Visibility::visible) continue;
        const Aabb& box = scene_->objects[id].world_bounds;
        if (!large_enough_to_draw(box, *frame.camera, config_.occluder_budget)) continue;
        const glm::dvec3 eye = frame.camera->eye;
        rank_scratch_.emplace_back(float(glm::length(eye - glm::clamp(eye, glm::dvec3(box.min), glm::dvec3(box.max)))), id);
    }
    std::sort(rank_scratch_.begin(), rank_scratch_.end());
    for (const auto& [distance, id] : rank_scratch_) {
        (void)distance;
        const std::size_t n = occluder_triangles_drawn(*scene_, id, *frame.camera, config_.lods);
        if (n > left) continue;
        append_occluder(id, frame, EdgeFlags::drawn_neighbours);
        left -= n;
    }
    timings_.select_ms += ms_since(start);
    if (frame_occluders_.size() == drawn_before) return;
    render_pending(frame, parallel);
    build_maps(frame);
    start = Clock::now();
    for (std::size_t id = 0; id < answers.size(); ++id)
        if (answers[id].visibility == Visibility::visible) {
            TestTally tally;
            answers[id] = test_object(frame, std::uint32_t(id), tally);
            add_tally(tally);
        }
    timings_.test_ms += ms_since(start);
}

// The flags of the pending clusters frame_clusters_[first_cluster, end_cluster) for
// EdgeFlags::drawn_neighbours: an edge shared with another candidate keeps its flag only when
// that candidate is drawn as itself this frame (so far: those drawn later leave it a margin,
// which only loses occlusion). An edge within the object keeps its flag, as in
// cluster_cross_shared_edges_, which cluster_neighbour_edges_ starts as.
void detail::SceneCullerState::keep_drawn_neighbours(std::size_t first_cluster, std::size_t end_cluster) {
    for (std::size_t i = first_cluster; i < end_cluster; ++i) {
        const std::uint32_t c = frame_clusters_[i];
        for (std::uint32_t n = cluster_neighbour_first_[c]; n < cluster_neighbour_first_[c + 1]; ++n) {
            const NeighbourEdge& edge = cluster_neighbours_[n];
            std::uint8_t& flags = cluster_neighbour_edges_[edge.triangle];
            flags = edge.candidate != kNone && drawn_[edge.candidate] == 1 ? std::uint8_t(flags | edge.edge_bit) : std::uint8_t(flags & ~edge.edge_bit);
        }
    }
}

// The flags of the pending triangles noted in frame_neighbours_ (drawn_neighbours): an edge
// shared with another candidate loses its flag unless that candidate is drawn as itself this
// frame (so far), as keep_drawn_neighbours does for clusters.
void detail::SceneCullerState::clear_undrawn_neighbours() {
    for (const NeighbourEdge& edge : frame_neighbours_)
        if (edge.candidate == kNone || drawn_[edge.candidate] != 1)
            frame_shared_[edge.triangle] = std::uint8_t(frame_shared_[edge.triangle] & ~edge.edge_bit);
    frame_neighbours_.clear();
}

// The clusters of frame_clusters_ and the triangles of frame_indices_ not rendered yet; the
// frame's first render clears the buffer (render_frame clears each band where it rasterizes).
void detail::SceneCullerState::render_pending(const Frame& frame, const ParallelFor& parallel) {
    const std::size_t clusters = frame_clusters_.size() - frame_clusters_rendered_, count = frame_shared_.size() - frame_rendered_;
    frame_back_faces_waiting_ = 0;
    if (clusters == 0 && count == 0) return;
    const auto start = Clock::now();
    if (clusters > 0) {
        ClusteredInput in{&clusters_, frame.clip, config_.backface};
        in.cluster_ids = frame_clusters_.data() + frame_clusters_rendered_;
        in.backfaces = frame_cluster_backfaces_.data() + frame_clusters_rendered_;
        in.cluster_count = clusters;
        if (frame_cluster_flags_ == EdgeFlags::across_objects) {  // every candidate in the frustum is drawn (select_occluders)
            in.shared_edges = cluster_cross_shared_edges_.data();
            in.edge_apexes = cluster_cross_edge_apexes_.data();
        } else if (frame_cluster_flags_ == EdgeFlags::drawn_neighbours) {
            keep_drawn_neighbours(frame_clusters_rendered_, frame_clusters_.size());
            in.shared_edges = cluster_neighbour_edges_.data();
            in.edge_apexes = cluster_cross_edge_apexes_.data();
        }
        if (!frame_started_) buffer_.render_frame(in, parallel);
        else buffer_.render(in, parallel);
        frame_started_ = true;
        frame_clusters_rendered_ += clusters;
        frame_cluster_triangles_waiting_ = 0;
        ++work_.renders;
    }
    if (count > 0) {
        clear_undrawn_neighbours();
        TriangleInput in = occluders_.input(frame.clip, config_.backface);
        in.indices = frame_indices_.data() + 3 * frame_rendered_;
        in.triangle_count = count;
        in.shared_edges = frame_shared_.data() + frame_rendered_;
        in.edge_apexes = frame_apexes_.data() + 3 * frame_rendered_;
        if (!frame_started_) buffer_.render_frame(in, parallel);
        else buffer_.render(in, parallel);
        frame_started_ = true;
        frame_rendered_ += count;
        ++work_.renders;
    }
    timings_.render_ms += ms_since(start);
}

// The maps of what the buffer holds; the depth estimation buffer takes the rendered
// occluders' boxes.
void detail::SceneCullerState::build_maps(const Frame& frame) {
    const auto start = Clock::now();
    if (!frame_started_) buffer_.clear();  // nothing drawn yet this frame: it still holds the last one
    maps_.clear();
    if (config_.maps.depth == DepthTest::deb)
        for (std::uint32_t id : frame_occluders_) maps_.add_occluder_box(object_boxes_[id], frame.clip);
    maps_.build(buffer_);
    maps_built_ = true;
    timings_.maps_ms += ms_since(start);
}

}  // namespace homcull
