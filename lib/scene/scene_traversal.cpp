// SceneCuller's tests: the hierarchy traversed front to back, a hidden node answering for
// its objects, and each remaining object's box, then (where the box is visible) its triangles.
#include <homcull/scene_culler.hpp>

#include "scene/scene_culler_state.hpp"

#include "common/float_round.hpp"
#include "common/run_tasks.hpp"
#include "scene/scene_culler_frame.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

namespace homcull {
namespace {

// Squared distance from the eye to a box (0 inside it): the traversal's front-to-back key.
float distance2_to_box(const glm::dvec3& eye, const Aabb& box) {
    const glm::dvec3 d = eye - glm::clamp(eye, glm::dvec3(box.min), glm::dvec3(box.max));
    return float(glm::dot(d, d));
}

// Squared distance from the eye to the farthest corner of a box.
float farthest_distance2(const glm::dvec3& eye, const Aabb& box) {
    const glm::dvec3 d = glm::max(glm::abs(eye - glm::dvec3(box.min)), glm::abs(eye - glm::dvec3(box.max)));
    return float(glm::dot(d, d));
}

}  // namespace

// Nodes come out of a heap nearest first (Greene's front-to-back order, which progressive
// culling needs so that near occluders are drawn before far nodes are tested); a hidden node
// answers for every object under it (node_hidden).
void detail::SceneCullerState::traverse(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    const auto start = std::chrono::steady_clock::now();
    const double flushes_before = timings_.render_ms + timings_.maps_ms;
    answers.assign(scene_->objects.size(), OccludeeAnswer{Visibility::view_culled, 0.0f, 0});
    const bool progressive = config_.strategy == CullStrategy::progressive;
    if (!progressive && parallel.run != nullptr) {  // without progressive's draws the buffer is final
        traverse_in_tasks(frame, answers, parallel);
        timings_.test_ms = ms_since(start);
        return;
    }
    const std::size_t budget = config_.occluder_budget.triangles == 0 ? ~std::size_t(0) : config_.occluder_budget.triangles;
    const auto nearest_first = [](const std::pair<float, std::uint32_t>& a, const std::pair<float, std::uint32_t>& b) {
        return a.first > b.first;
    };
    // progressive: the waiting occluders are drawn when `batch` triangles wait, or earlier (from
    // a sixteenth of that) once traversal reaches a node wholly beyond one of them: only then
    // can they hide what comes next. Each draw costs a rebuild of the maps.
    const std::size_t batch = config_.progressive_batch_triangles, early_batch = std::max<std::size_t>(1, batch / 16);
    float waiting_nearest_far = std::numeric_limits<float>::infinity();  // squared, of the waiting occluders
    node_heap_.clear();
    if (!hierarchy_.nodes.empty()) node_heap_.emplace_back(0.0f, 0u);
    while (!node_heap_.empty()) {
        std::pop_heap(node_heap_.begin(), node_heap_.end(), nearest_first);
        const std::uint32_t node_index = node_heap_.back().second;
        const ObjectHierarchy::Node& node = hierarchy_.nodes[node_index];
        const float node_key = node_heap_.back().first;
        node_heap_.pop_back();
        const std::size_t waiting = triangles_waiting();
        if (progressive && (waiting >= batch || (waiting >= early_batch && node_key > waiting_nearest_far))) {
            render_pending(frame, parallel);
            build_maps(frame);
            waiting_nearest_far = std::numeric_limits<float>::infinity();
        }
        TestTally node_tally;
        const bool hidden = node_hidden(frame, node_index, answers, node_tally);
        add_tally(node_tally);
        if (hidden) continue;
        if (!node.leaf()) {
            for (std::uint32_t c = node.first_child; c < node.first_child + 2; ++c) {
                node_heap_.emplace_back(distance2_to_box(frame.camera->eye, hierarchy_.nodes[c].bounds), c);
                std::push_heap(node_heap_.begin(), node_heap_.end(), nearest_first);
            }
            continue;
        }
        for (std::uint32_t i = node.begin; i < node.end; ++i) {
            const std::uint32_t id = hierarchy_.object_ids[i];
            TestTally tally;
            answers[id] = test_object(frame, id, tally);
            add_tally(tally);
            // progressive: a visible candidate is drawn with the next batch, within the budget.
            if (progressive && answers[id].visibility == Visibility::visible && candidate_of_[id] != kNone &&
                large_enough_to_draw(scene_->objects[id].world_bounds, *frame.camera, config_.occluder_budget) &&
                work_.occluder_triangles + occluder_triangles_drawn(*scene_, id, *frame.camera, config_.lods) <= budget) {
                append_occluder(id, frame, EdgeFlags::drawn_neighbours);
                waiting_nearest_far = std::min(waiting_nearest_far, farthest_distance2(frame.camera->eye, scene_->objects[id].world_bounds));
            }
        }
    }
    timings_.test_ms = ms_since(start) - (timings_.render_ms + timings_.maps_ms - flushes_before);
}

void detail::SceneCullerState::add_tally(const TestTally& tally) {
    work_.nodes_tested += tally.nodes;
    work_.objects_tested += tally.objects;
    work_.occludee_parts_tested += tally.parts;
    work_.solid_parts_tested += tally.solid_parts;
    for (int e = 0; e < 7; ++e) exits_.count[e] += tally.exits[e];
}

// A node is tested when the configuration asks for hierarchy tests and it holds more than one
// object; if its box is outside the frustum or occluded, so is every object under it.
bool detail::SceneCullerState::node_hidden(const Frame& frame, std::uint32_t node_index, std::vector<OccludeeAnswer>& answers,
                                           TestTally& tally) const {
    const ObjectHierarchy::Node& node = hierarchy_.nodes[node_index];
    if (!config_.hierarchy || node.end - node.begin <= 1) return false;
    OccludeeAnswer a = box_answer(frame, node_boxes_[node_index]);
    ++tally.nodes;
    if (a.visibility == Visibility::visible && separated(frame.frustum, node_boxes_[node_index])) {
        a.visibility = Visibility::view_culled;
        a.level_of_visibility = 0.0f;
    }
    if (a.visibility == Visibility::visible) return false;
    for (std::uint32_t i = node.begin; i < node.end; ++i) answers[hierarchy_.object_ids[i]] = a;
    tally.exits[a.overlap_exit] += node.end - node.begin;
    return true;
}

// With the buffer final, no answer depends on the order of the tests, and a node is tested
// exactly when none of its ancestors was found hidden, in any order: so the answers and the
// counts are those of the front-to-back traversal. The top of the hierarchy is split here,
// level by level (testing the inner nodes it opens), until there are several subtrees per
// thread or only leaves are left. Tasks then take the subtrees one at a time from a shared
// counter (their costs differ widely: a hidden subtree costs one test) and traverse each depth
// first, testing its nodes and objects with the task's own tally.
void detail::SceneCullerState::traverse_in_tasks(const Frame& frame, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel) {
    const std::size_t threads = parallel.threads == 0 ? 2 : parallel.threads;
    subtrees_.clear();
    if (!hierarchy_.nodes.empty()) subtrees_.push_back(0);
    TestTally top;
    bool opened = true;
    while (opened && subtrees_.size() < 8 * threads) {
        opened = false;
        next_subtrees_.clear();
        for (const std::uint32_t n : subtrees_) {
            const ObjectHierarchy::Node& node = hierarchy_.nodes[n];
            if (node.leaf()) {  // left for a task, untested
                next_subtrees_.push_back(n);
                continue;
            }
            opened = true;
            if (!node_hidden(frame, n, answers, top)) next_subtrees_.insert(next_subtrees_.end(), {node.first_child, node.first_child + 1});
        }
        subtrees_.swap(next_subtrees_);
    }
    add_tally(top);

    const std::size_t tasks = std::min({task_tallies_.size(), 2 * threads, subtrees_.size()});
    struct Job {
        SceneCullerState* self;
        const Frame* frame;
        std::vector<OccludeeAnswer>* answers;
        std::atomic<std::size_t> next_subtree{0};
    } job{this, &frame, &answers};
    run_tasks(parallel, tasks, [](void* data, std::size_t k) {
        Job& j = *static_cast<Job*>(data);
        SceneCullerState& self = *j.self;
        // Counted here and stored once at the end: the tasks' tallies lie side by side, and a
        // count per test into them would take their shared cache line from the other core each time.
        TestTally tally;
        std::uint32_t* stack = self.task_stacks_.data() + k * self.task_stack_room_;
        for (std::size_t s = j.next_subtree++; s < self.subtrees_.size(); s = j.next_subtree++) {
            std::size_t depth = 0;  // depth first: at most the hierarchy's depth + 1 waiting
            stack[depth++] = self.subtrees_[s];
            while (depth > 0) {
                const std::uint32_t index = stack[--depth];
                if (self.node_hidden(*j.frame, index, *j.answers, tally)) continue;
                const ObjectHierarchy::Node& node = self.hierarchy_.nodes[index];
                if (!node.leaf()) {
                    stack[depth++] = node.first_child + 1;
                    stack[depth++] = node.first_child;
                    continue;
                }
                for (std::uint32_t i = node.begin; i < node.end; ++i) {
                    const std::uint32_t id = self.hierarchy_.object_ids[i];
                    (*j.answers)[id] = self.test_object(*j.frame, id, tally);
                }
            }
        }
        self.task_tallies_[k] = tally;
    }, &job);
    for (std::size_t k = 0; k < tasks; ++k) add_tally(task_tallies_[k]);
}

// A box whose answer only counts as hidden or not (a hierarchy node's, whose visible objects are
// tested one by one, or an object part's): where the maps leave the buffer to decide
// (PyramidBuild::lazy) the buffer answers, without the uncovered share the maps would work out
// for a visible box.
OccludeeAnswer detail::SceneCullerState::box_answer(const Frame& frame, const Aabb& box) const {
    if (maps_.pyramid_built()) return maps_.test_aabb_by_rectangle(box, frame.clip);
    OccludeeAnswer a;
    // Without the buffer's exact view test, which would make the view volume's axes at each
    // call: a node or part whose box lies beside a corner of the view stays visible
    // (conservative), and each object gets the frame's frustum test in test_object.
    a.visibility = buffer_.test_aabb_by_rectangle(&box.min.x, &box.max.x, frame.clip);
    a.level_of_visibility = a.visibility == Visibility::visible ? 1.0f : 0.0f;
    return a;
}

// The object's box, then, where the box is visible and the object small enough, its triangles.
//
// A box (of a node, an object or a part) that the buffer finds visible is then tested against
// the view frustum exactly (Frame::frustum): the buffer tests the screen rectangle of the box's
// projected corners, which reaches past the box's silhouette, so that a box beside a corner or
// an edge of the frustum can overlap the screen without meeting the frustum. On the castle's
// views such boxes were half the objects the occludee triangle tests went on to prove hidden
// (their triangles all off the screen), and most of the triangles those tests went through.
OccludeeAnswer detail::SceneCullerState::test_object(const Frame& frame, std::uint32_t id, TestTally& tally) {
    const Object& object = scene_->objects[id];
    OccludeeAnswer answer = maps_.test_aabb_by_rectangle(object_boxes_[id], frame.clip);  // separated() below is its view test
    ++tally.objects;
    ++tally.exits[answer.overlap_exit];
    if (answer.visibility == Visibility::visible && separated(frame.frustum, object_boxes_[id])) {
        answer.visibility = Visibility::view_culled;
        answer.level_of_visibility = 0.0f;
        return answer;
    }
    if (answer.visibility != Visibility::visible || scene_->triangle_count(object) > config_.triangle_test_limit) return answer;
    const OccludeeShape shape = resolved_occludee_shape(config_);
    if (parts_.count(id) > 0) {
        // The parts answer for the object (their triangles with the samples shape); the
        // rectangles shape still tries the whole object's triangles where a part is visible.
        const bool samples = shape == OccludeeShape::samples && occludee_first_vertex_[id] != kNotGathered;
        if (parts_hidden(frame, id, samples, tally)) {
            answer.visibility = Visibility::occluded;
            answer.level_of_visibility = 0.0f;
            return answer;
        }
        if (shape != OccludeeShape::rectangles) return answer;
    }
    if (shape == OccludeeShape::rectangles && triangle_rectangles_hidden(object, frame.clip_double)) {
        answer.visibility = Visibility::occluded;
        answer.level_of_visibility = 0.0f;  // the holes its triangles tolerated are not estimated
    } else if (shape == OccludeeShape::samples && triangle_samples_hidden(id, frame.clip, answer.level_of_visibility)) {
        answer.visibility = Visibility::occluded;
    }
    return answer;
}

namespace {

// Whether a triangle given by its clip-space corners is hidden at every sample: its screen
// rectangle at its nearest w (w is affine on the triangle, so its nearest point is a corner)
// tested against the maps; when that rectangle is not hidden, the four halves-of-edges
// sub-triangles (clip space is linear on the triangle, so they tile it exactly) are tried, down
// to `depth` more levels. A corner before the near plane makes it visible. The rectangles
// share the object's hole budget (approximate mode).
bool triangle_hidden(const OcclusionMaps& maps, float near_w, const glm::dvec4 c[3], int depth, double& budget) {
    const detail::ClipBounds b = detail::clip_bounds(c, 3, double(near_w));
    if (!b.finite || b.behind > 0) return false;
    // Widened by 2^-20 of the magnitudes: world_bounds and ground truth round the world
    // transform to float, this does not.
    const double slack_x = 0x1.0p-20 * (1.0 + std::abs(b.min_x) + std::abs(b.max_x));
    const double slack_y = 0x1.0p-20 * (1.0 + std::abs(b.min_y) + std::abs(b.max_y));
    const ScreenRect r{detail::float_down(b.min_x - slack_x), detail::float_down(b.min_y - slack_y), detail::float_up(b.max_x + slack_x),
                       detail::float_up(b.max_y + slack_y), detail::float_down(b.min_w * (1.0 - 0x1.0p-20))};
    if (maps.test_rect_within(r, budget).visibility != Visibility::visible) return true;
    if (depth == 0) return false;
    const glm::dvec4 m01 = (c[0] + c[1]) * 0.5, m12 = (c[1] + c[2]) * 0.5, m20 = (c[2] + c[0]) * 0.5;
    const glm::dvec4 parts[4][3] = {{c[0], m01, m20}, {m01, c[1], m12}, {m20, m12, c[2]}, {m01, m12, m20}};
    for (const auto& part : parts)
        if (!triangle_hidden(maps, near_w, part, depth - 1, budget)) return false;
    return true;
}

}  // namespace

// Every triangle hidden (see triangle_hidden), corners transformed in double as ground truth
// transforms them.
bool detail::SceneCullerState::triangle_rectangles_hidden(const Object& object, const glm::dmat4& clip_from_world) const {
    const Mesh& mesh = scene_->meshes[object.mesh];
    const glm::dmat4 m = clip_from_world * object.world;
    double budget = maps_.hole_budget();  // approximate mode: L pixels of holes for the whole object
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        glm::dvec4 c[3];
        for (int k = 0; k < 3; ++k) c[k] = m * glm::dvec4(glm::dvec3(mesh.positions[mesh.indices[3 * t + std::size_t(k)]]), 1.0);
        if (!triangle_hidden(maps_, buffer_.config().near_w, c, 3, budget)) return false;
    }
    return true;
}

// Whether every part of the object is hidden: its box, and where the box is visible and
// `test_triangles`, its triangles sample by sample (conservative mode: no holes tolerated). The
// part found visible last time goes first, so that a visible object ends at once.
bool detail::SceneCullerState::parts_hidden(const Frame& frame, std::uint32_t id, bool test_triangles, TestTally& tally) {
    const std::uint32_t first = parts_.first(id), count = parts_.count(id);
    const std::uint32_t start = first_visible_part_[id] < count ? first_visible_part_[id] : 0;
    std::optional<OcclusionBuffer::ClosedSolid> solid;  // decided once per object, when a part first needs its triangles
    bool solid_decided = false;
    for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t p = (start + k) % count;
        ++tally.parts;
        if (box_answer(frame, parts_.box(first + p)).visibility != Visibility::visible || separated(frame.frustum, parts_.box(first + p)))
            continue;
        if (test_triangles) {
            if (!solid_decided) solid = seen_solid(frame, id), solid_decided = true;
            tally.solid_parts += solid.has_value();
            if (part_triangles_hidden(frame, id, first + p, solid ? &*solid : nullptr)) continue;
        }
        first_visible_part_[id] = std::uint8_t(p);
        return false;
    }
    return true;
}

// The object as a closed solid seen from outside (closed_occludees.hpp), when it is one this
// frame: closed, and its box wholly beyond the near plane; the eye as ground truth's rays start
// from it (relative to the anchor, rounded to float).
std::optional<OcclusionBuffer::ClosedSolid> detail::SceneCullerState::seen_solid(const Frame& frame, std::uint32_t id) const {
    if (occludee_orientation_[id] == 0 || !beyond_near_plane(frame, object_boxes_[id])) return std::nullopt;
    const glm::vec3 eye(frame.camera->eye - anchor_);
    return OcclusionBuffer::ClosedSolid{{eye.x, eye.y, eye.z}, occludee_orientation_[id]};
}

// The triangles of one part of an object, sample by sample; the triangle that found the object
// visible last time goes first when it is in this part. With `solid` (seen_solid), the test
// passes over the triangles the eye certainly sees from behind.
bool detail::SceneCullerState::part_triangles_hidden(const Frame& frame, std::uint32_t id, std::uint32_t part,
                                                     const OcclusionBuffer::ClosedSolid* solid) {
    const Mesh& mesh = scene_->meshes[scene_->objects[id].mesh];
    const std::uint32_t begin = parts_.first_triangle(part), count = parts_.triangle_count(part);
    TriangleInput in;
    in.positions = occludee_positions_.data() + 3 * occludee_first_vertex_[id];
    in.vertex_count = mesh.positions.size();
    in.indices = parts_.indices(scene_->objects[id].mesh) + 3 * std::size_t(begin);
    in.triangle_count = count;
    in.model_to_clip = frame.clip;
    in.backface = Backface::none;
    const std::uint32_t last = first_visible_triangle_[id];
    const std::uint32_t start = last >= begin && last < begin + count ? last - begin : 0;
    const OcclusionBuffer::TriangleTest r = solid ? buffer_.test_triangles(in, 0, start, *solid) : buffer_.test_triangles(in, 0, start);
    if (r.visibility != Visibility::visible) return true;
    first_visible_triangle_[id] = begin + std::uint32_t(r.deciding_triangle);
    return false;
}

// Whether a box (anchored world: it holds the rounded vertices ground truth has, anchored_box)
// lies wholly beyond the near plane, where ground truth's rays start: every corner's w (the
// view depth) above near (1 + 2^-10), plus how far the rays' origin, the eye rounded to float
// relative to the anchor, may lie from the eye (2^-24 of each coordinate; 2^-22 of their sum).
bool detail::SceneCullerState::beyond_near_plane(const Frame& frame, const Aabb& box) const {
    const glm::dmat4& m = frame.clip_double;
    const glm::dvec3 eye = frame.camera->eye - anchor_;
    const double near = double(buffer_.config().near_w) * (1.0 + 0x1.0p-10) + 0x1.0p-22 * (std::abs(eye.x) + std::abs(eye.y) + std::abs(eye.z));
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 p = glm::dvec3((k & 1) ? box.max.x : box.min.x, (k & 2) ? box.max.y : box.min.y, (k & 4) ? box.max.z : box.min.z) + anchor_;
        const double w = m[0][3] * p.x + m[1][3] * p.y + m[2][3] * p.z + m[3][3];
        if (!(w > near)) return false;
    }
    return true;
}

// The object's triangles sample by sample (OcclusionBuffer::test_triangles), tolerating the
// maps' hole budget in approximate mode; its level of visibility is then the share of its
// samples left visible.
bool detail::SceneCullerState::triangle_samples_hidden(std::size_t id, const std::array<float, 16>& clip_from_world, float& level_of_visibility) {
    const std::size_t first = occludee_first_vertex_[id];
    if (first == kNotGathered) return false;
    const Mesh& mesh = scene_->meshes[scene_->objects[id].mesh];
    TriangleInput in;
    in.positions = occludee_positions_.data() + 3 * first;
    in.vertex_count = mesh.positions.size();
    in.indices = mesh.indices.data();
    in.triangle_count = mesh.triangle_count();
    in.model_to_clip = clip_from_world;
    in.backface = Backface::none;
    const OcclusionBuffer::TriangleTest r = buffer_.test_triangles(in, std::uint64_t(maps_.hole_budget()), first_visible_triangle_[id]);
    if (r.visibility == Visibility::visible) {
        first_visible_triangle_[id] = std::uint32_t(r.deciding_triangle);
        return false;
    }
    level_of_visibility = r.samples > 0 ? float(double(r.visible_samples) / double(r.samples)) : 0.0f;
    return true;
}

}  // namespace homcull
