// homcull.h: buffers, frames, draws and queries.
#include "capi/c_objects.hpp"
#include "capi/view_conventions.hpp"

#include <homcull/aabb.hpp>
#include <homcull/frustum.hpp>

#include "buffer/buffer_state.hpp"
#include "buffer/exact_view_test.hpp"
#include "buffer/rect_queries.hpp"  // box_rectangle

#include <algorithm>
#include <cmath>

using namespace homcull;

namespace {

constexpr const char* kNoFrame = "no frame has begun on this buffer (homcull_buffer_begin_frame)";
constexpr const char* kTaskListOpen = "a task list is open on this buffer (homcull_buffer_finish_tasks ends it)";

// A buffer runs its context's instruction set.
BufferConfig buffer_config(const homcull_context& context, const homcull_buffer_desc& d) {
    BufferConfig c;
    c.isa = context.choice->name;
    c.width = d.width;
    c.height = d.height;
    c.samples = d.samples;
    c.near_w = d.near_distance;
    c.sample_depth = (d.flags & HOMCULL_BUFFER_SAMPLE_DEPTH) != 0;
    return c;
}

// The library's check of a configuration (buffer_config_problem), as a result: its exception
// would allocate its message.
homcull_result check_config(const homcull_context* context, const char* fn, const BufferConfig& c) {
    const char* problem = buffer_config_problem(c);
    if (!problem) return HOMCULL_OK;
    return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: %s (got %dx%d pixels, %d samples per axis, near %g)", fn, problem, c.width,
                        c.height, c.samples, double(c.near_w));
}

OcclusionBuffer make_buffer(capi::Account& account, const BufferConfig& config) {
    const detail::MemoryScope scope(&account.hooks);
    return OcclusionBuffer(config);
}

glm::dmat4 read_model(const homcull_buffer& b, const float* model) {
    return model ? capi::read_matrix(model, b.view.layout) : glm::dmat4(1.0);
}

// The far plane's row against model positions: far_row * (clip_from_world * model).
glm::dvec4 far_row_in_model(const homcull_buffer& b, const glm::dmat4& model) {
    const glm::dmat4 m = b.clip_from_world * model;
    glm::dvec4 row;
    for (int c = 0; c < 4; ++c) row[c] = glm::dot(b.far_row, glm::dvec4(m[c][0], m[c][1], m[c][2], m[c][3]));
    return row;
}

// The view volume of the frame for boxes in the space clip_from_space maps from
// (buffer/exact_view_test.hpp).
FrustumAxes view_volume(const homcull_buffer& b, const glm::dmat4& clip_from_space) {
    return detail::view_volume_of(clip_from_space, b.near_distance, b.buffer.config().orthographic);
}

// Whether a box lies wholly outside the view: before the near plane, or its screen rectangle
// (conservative: it holds every projected point of the box) beyond a side of the screen. Its
// triangles then cover no sample: skipping them changes no bit of the buffer.
bool outside_view(const float box_min[3], const float box_max[3], const std::array<float, 16>& model_to_clip, float near_w, bool orthographic) {
    ScreenRect r;
    Visibility decided;
    if (!detail::box_rectangle(box_min, box_max, model_to_clip, near_w, orthographic, r, decided)) return decided == Visibility::view_culled;
    return r.ndc_max_x < -1.0f || r.ndc_min_x > 1.0f || r.ndc_max_y < -1.0f || r.ndc_min_y > 1.0f;
}

// The checks every draw and query shares.
// recording: the call may come while a task list records (a mesh draw, which it records).
homcull_result check_frame(const homcull_buffer* b, const char* fn, bool recording = false) {
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer is null", fn);
    if (!b->frame_begun) return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: %s", fn, kNoFrame);
    if (b->tasks != homcull_buffer::Tasks::none && !(recording && b->tasks == homcull_buffer::Tasks::recording))
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: %s", fn, kTaskListOpen);
    return HOMCULL_OK;
}

// Calls that change the buffer's settings or frame, refused while a task list is open.
homcull_result check_no_task_list(const homcull_buffer& b, const char* fn) {
    if (b.tasks == homcull_buffer::Tasks::none) return HOMCULL_OK;
    return capi::report(b.account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: %s", fn, kTaskListOpen);
}

// A homcull_triangles as the library's input, or an error result.
homcull_result triangle_input(const homcull_buffer& b, const homcull_triangles* t, const float* model, const char* fn, TriangleInput& in) {
    const homcull_context* context = b.account.context;
    if (!t) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: triangles is null", fn);
    if (t->triangle_count > 0 && !t->positions) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: positions is null", fn);
    if (t->position_stride < 3 * sizeof(float))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: position_stride %zu is below one position (12 bytes)", fn,
                            t->position_stride);
    if (t->indices && t->index_size != 2 && t->index_size != 4)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: index_size must be 2 or 4, got %u", fn, unsigned(t->index_size));
    if (!t->indices && t->triangle_count > t->vertex_count / 3)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: %zu triangles without indices need %zu vertices, vertex_count is %zu", fn,
                            t->triangle_count, 3 * t->triangle_count, t->vertex_count);
    if (t->triangle_count >= (std::size_t(1) << 32))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: at most 2^32 - 1 triangles a call", fn);
    if (!capi::finite_matrix(model)) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: model_matrix has a number that is not finite", fn);
    in = TriangleInput{};
    in.positions = t->positions;
    in.position_components = 3;
    in.position_stride = t->position_stride;
    in.vertex_count = t->vertex_count;
    in.indices = t->indices;
    in.indices_16bit = t->indices && t->index_size == 2;
    in.triangle_count = t->triangle_count;
    in.model_to_clip = capi::float_clip_from_model(b.clip_from_world, read_model(b, model));
    in.backface = b.backface;
    in.orthographic = b.buffer.config().orthographic;  // the frame's projection: begin_frame configures it
    return HOMCULL_OK;
}

// An orthographic view's nearest clip z (in its depth range) as the w' the buffer compares
// (BufferConfig::orthographic): 2 / (3 - z_gl), rounded towards the eye. Beyond twice the far
// distance, or not a number: 0, before the near plane, which the rectangle test answers visible.
float orthographic_nearest_w(const homcull_buffer& b, float z) {
    const double z_gl = b.ortho_z_scale * double(z) + b.ortho_z_offset, h = (3.0 - z_gl) * 0.5;
    if (!(h >= 0x1.0p-8)) return 0.0f;
    const float w = float(1.0 / h);
    return double(w) > 1.0 / h ? std::nextafter(w, 0.0f) : w;
}

homcull_visibility as_c(Visibility v) {
    return v == Visibility::occluded ? HOMCULL_OCCLUDED : v == Visibility::view_culled ? HOMCULL_VIEW_CULLED : HOMCULL_VISIBLE;
}

// Both triangle tests: the answer (visible unless the test says otherwise) into `result`.
homcull_result test_triangles(const homcull_buffer* b, const homcull_triangles* triangles, const float* model_matrix,
                              const homcull_triangle_test_desc& options, homcull_triangle_test_result& result, const char* fn) {
    result = homcull_triangle_test_result{};
    result.visibility = HOMCULL_VISIBLE;
    if (homcull_result r = check_frame(b, fn); r != HOMCULL_OK) return r;
    const homcull_context* context = b->account.context;
    if (options.flags & ~std::uint32_t(HOMCULL_TRIANGLES_CLOSED_SOLID))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: unknown flags 0x%x", fn, unsigned(options.flags));
    const bool closed = (options.flags & HOMCULL_TRIANGLES_CLOSED_SOLID) != 0;
    if (closed) {
        if (options.orientation != 1 && options.orientation != -1)
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: a closed solid's orientation must be +1 or -1, got %d", fn,
                                int(options.orientation));
        if (!std::isfinite(options.eye[0]) || !std::isfinite(options.eye[1]) || !std::isfinite(options.eye[2]))
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: a closed solid's eye must be finite", fn);
        if (b->buffer.config().orthographic)
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: closed solids need a perspective view (this frame's is orthographic)",
                                fn);
    }
    TriangleInput in;
    if (homcull_result r = triangle_input(*b, triangles, model_matrix, fn, in); r != HOMCULL_OK) return r;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        const OcclusionBuffer::TriangleTest test =
            closed ? b->buffer.test_triangles(in, options.tolerated_samples, options.first_triangle,
                                              OcclusionBuffer::ClosedSolid{{options.eye[0], options.eye[1], options.eye[2]}, int(options.orientation)})
                   : b->buffer.test_triangles(in, options.tolerated_samples, options.first_triangle);
        result.visibility = as_c(test.visibility);
        result.deciding_triangle = test.visibility == Visibility::visible ? test.deciding_triangle : 0;
        result.samples = test.samples;
        result.visible_samples = test.visible_samples;
        return HOMCULL_OK;
    });
}

void all_visible(homcull_visibility* visibility, std::size_t count) {
    if (visibility) std::fill(visibility, visibility + count, homcull_visibility(HOMCULL_VISIBLE));
}

}  // namespace

homcull_buffer::homcull_buffer(homcull_context* context, const BufferConfig& config)
    : account(context), buffer(make_buffer(account, config)), near_distance(config.near_w) {}

extern "C" {

homcull_result homcull_buffer_create(homcull_context* context, const homcull_buffer_desc* desc, homcull_buffer** out) {
    const char* const fn = "homcull_buffer_create";
    if (!out) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: out is null", fn);
    *out = nullptr;
    if (!context || !desc) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: context or desc is null", fn);
    if (desc->flags & ~uint32_t(HOMCULL_BUFFER_SAMPLE_DEPTH))
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: unknown flags 0x%x", fn, unsigned(desc->flags));
    const homcull_result valid = check_config(context, fn, buffer_config(*context, *desc));
    if (valid != HOMCULL_OK) return valid;
    homcull_buffer* buffer = nullptr;
    const homcull_result result = capi::guarded(context, fn, [&]() -> homcull_result {
        buffer = capi::place<homcull_buffer>(context, buffer_config(*context, *desc));
        return HOMCULL_OK;
    });
    if (result == HOMCULL_OK) *out = buffer;
    return result;
}

void homcull_buffer_destroy(homcull_buffer* buffer) {
    if (buffer) capi::unplace(buffer);
}

homcull_result homcull_buffer_set_resolution(homcull_buffer* b, int32_t width, int32_t height) {
    const char* const fn = "homcull_buffer_set_resolution";
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer is null", fn);
    if (homcull_result r = check_no_task_list(*b, fn); r != HOMCULL_OK) return r;
    BufferConfig config = b->buffer.config();
    config.width = width;
    config.height = height;
    const homcull_result valid = check_config(b->account.context, fn, config);
    if (valid != HOMCULL_OK) return valid;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->buffer.configure(config);  // leaves the buffer as it was when it throws
        b->frame_begun = false;
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_set_near(homcull_buffer* b, float near_distance) {
    const char* const fn = "homcull_buffer_set_near";
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer is null", fn);
    if (homcull_result r = check_no_task_list(*b, fn); r != HOMCULL_OK) return r;
    BufferConfig config = b->buffer.config();
    config.near_w = near_distance;
    const homcull_result valid = check_config(b->account.context, fn, config);
    if (valid != HOMCULL_OK) return valid;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->buffer.set_near_w(near_distance);  // an orthographic buffer keeps its own
        b->near_distance = near_distance;
        b->frame_begun = false;
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_reserve(homcull_buffer* b, const homcull_reserve_desc* desc) {
    const char* const fn = "homcull_buffer_reserve";
    if (!b || !desc) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer or desc is null", fn);
    if (homcull_result r = check_no_task_list(*b, fn); r != HOMCULL_OK) return r;
    BufferConfig largest = b->buffer.config();
    const int width = std::max(largest.width, desc->max_width), height = std::max(largest.height, desc->max_height);
    largest.width = width, largest.height = height;
    const homcull_result valid = check_config(b->account.context, fn, largest);
    if (valid != HOMCULL_OK) return valid;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        BufferReserve r;
        r.max_width = width;
        r.max_height = height;
        r.max_triangles = desc->max_draw_triangles;
        r.max_vertices = desc->max_draw_vertices;
        // A mesh's clusters hold at least one triangle each, and at most the limits' vertices
        // plus a copy of each triangle's three apexes (OccluderClusters::edge_apexes).
        r.max_clusters = desc->max_draw_triangles;
        const ClusterLimits limits;
        r.max_cluster_vertices = desc->max_draw_triangles + desc->max_task_list_triangles > 0 ? limits.max_vertices + 3 * limits.max_triangles : 0;
        // A draw through the job system is a task list of one draw.
        r.max_task_list_draws = std::max<std::size_t>(desc->max_task_list_draws, 1);
        r.max_task_list_clusters = r.max_task_list_triangles = std::max(desc->max_draw_triangles, desc->max_task_list_triangles);
        r.max_threads = desc->max_job_threads;
        b->buffer.reserve(r);
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_set_job_system(homcull_buffer* b, const homcull_job_system* jobs) {
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_buffer_set_job_system: buffer is null");
    if (homcull_result r = check_no_task_list(*b, "homcull_buffer_set_job_system"); r != HOMCULL_OK) return r;
    b->jobs = ParallelFor{};
    if (jobs && jobs->run) b->jobs = ParallelFor{jobs->run, jobs->user, jobs->threads};
    return HOMCULL_OK;
}

homcull_result homcull_buffer_begin_tasks(homcull_buffer* b) {
    const char* const fn = "homcull_buffer_begin_tasks";
    if (homcull_result r = check_frame(b, fn); r != HOMCULL_OK) return r;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->buffer.begin_tasks();
        b->tasks = homcull_buffer::Tasks::recording;
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_close_tasks(homcull_buffer* b, size_t* task_count) {
    const char* const fn = "homcull_buffer_close_tasks";
    if (task_count) *task_count = 0;
    if (!b || !task_count) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer or task_count is null", fn);
    if (b->tasks != homcull_buffer::Tasks::recording)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: no task list is recording (homcull_buffer_begin_tasks)", fn);
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->task_count = b->buffer.close_tasks();  // out of memory: the list stays recording, finish_tasks ends it
        b->tasks = homcull_buffer::Tasks::closed;
        *task_count = b->task_count;
        return HOMCULL_OK;
    });
}

// From the engine's threads, at once: reads the buffer's state, which no other call changes
// while the list is closed.
homcull_result homcull_buffer_run_task(homcull_buffer* b, size_t index) {
    const char* const fn = "homcull_buffer_run_task";
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer is null", fn);
    if (b->tasks != homcull_buffer::Tasks::closed)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: the task list is not closed (homcull_buffer_close_tasks)", fn);
    if (index >= b->task_count)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: task %zu is not below the task count %zu", fn, index,
                            b->task_count);
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->buffer.run_task(index);  // noexcept, allocates nothing
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_finish_tasks(homcull_buffer* b) {
    const char* const fn = "homcull_buffer_finish_tasks";
    if (!b) return capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer is null", fn);
    if (b->tasks == homcull_buffer::Tasks::none)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: no task list is open (homcull_buffer_begin_tasks)", fn);
    const bool closed = b->tasks == homcull_buffer::Tasks::closed;
    const std::size_t tasks = b->task_count;
    std::size_t missing = 0;
    const homcull_result r = capi::guarded(b->account, fn, [&]() -> homcull_result {
        missing = b->buffer.finish_tasks(std::nothrow);
        return HOMCULL_OK;
    });
    b->tasks = homcull_buffer::Tasks::none;
    b->task_count = 0;
    if (r != HOMCULL_OK) return r;
    if (!closed)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION, "%s: the list was not closed (homcull_buffer_close_tasks): nothing was drawn", fn);
    if (missing != 0)
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_OPERATION,
                            "%s: %zu of the %zu tasks did not run; the buffer holds those that did", fn, missing, tasks);
    return HOMCULL_OK;
}

uint64_t homcull_buffer_allocated_bytes(const homcull_buffer* b) { return b ? b->account.bytes.load() : 0; }

homcull_result homcull_buffer_begin_frame(homcull_buffer* b, const homcull_view* view) {
    const char* const fn = "homcull_buffer_begin_frame";
    if (!b || !view) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer or view is null", fn);
    if (homcull_result open = check_no_task_list(*b, fn); open != HOMCULL_OK) return open;
    capi::ViewConventions conventions;
    const homcull_result r = capi::read_view(b->account.context, *view, conventions);
    if (r != HOMCULL_OK) {
        b->frame_begun = false;  // answers nothing until a frame begins
        return r;
    }
    if (conventions.orthographic != b->buffer.config().orthographic) {
        // The same sizes in the other projection: configure allocates nothing (arrays only grow).
        BufferConfig config = b->buffer.config();
        config.orthographic = conventions.orthographic;
        config.near_w = b->near_distance;
        const homcull_result switched = capi::guarded(b->account, fn, [&]() -> homcull_result {
            b->buffer.configure(config);
            return HOMCULL_OK;
        });
        if (switched != HOMCULL_OK) {
            b->frame_begun = false;
            return switched;
        }
    }
    b->buffer.clear();  // allocates nothing
    b->ortho_z_scale = conventions.ortho_z_scale, b->ortho_z_offset = conventions.ortho_z_offset;
    b->view = *view;
    b->clip_from_world = conventions.clip_from_world;
    b->backface = conventions.backface;
    b->far_plane = conventions.far_plane;
    b->far_row = conventions.far_row;
    b->world_view_axes = view_volume(*b, conventions.clip_from_world);
    b->frame_begun = true;
    b->draw_calls = 0;
    b->allocations_at_frame = b->account.allocations.load();
    return HOMCULL_OK;
}

homcull_result homcull_buffer_draw_mesh(homcull_buffer* b, const homcull_mesh* mesh, const float* model_matrices, size_t instance_count) {
    const char* const fn = "homcull_buffer_draw_mesh";
    if (homcull_result r = check_frame(b, fn, true); r != HOMCULL_OK) return r;
    const homcull_context* context = b->account.context;
    if (!mesh) return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: mesh is null", fn);
    if (!model_matrices && instance_count > 1)
        return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: %zu instances need their model matrices", fn, instance_count);
    for (std::size_t i = 0; model_matrices && i < instance_count; ++i)
        if (!capi::finite_matrix(model_matrices + 16 * i))
            return capi::report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: model matrix %zu has a number that is not finite", fn, i);
    ++b->draw_calls;
    if (mesh->triangle_count == 0) return HOMCULL_OK;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        ClusteredInput in;
        in.clusters = &mesh->clusters;
        in.backface = b->backface;
        in.orthographic = b->buffer.config().orthographic;
        for (std::size_t i = 0; i < instance_count; ++i) {
            in.model_to_clip = capi::float_clip_from_model(b->clip_from_world, read_model(*b, model_matrices ? model_matrices + 16 * i : nullptr));
            if (mesh->bounded && outside_view(mesh->bounds_min, mesh->bounds_max, in.model_to_clip, b->buffer.config().near_w, in.orthographic)) continue;
            if (b->tasks == homcull_buffer::Tasks::recording) b->buffer.record(in);  // a record that fails records nothing
            else b->buffer.render(in, b->jobs);  // a render that fails leaves what it drew: occluders all, so still conservative
        }
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_draw_triangles(homcull_buffer* b, const homcull_triangles* triangles, const float* model_matrix) {
    const char* const fn = "homcull_buffer_draw_triangles";
    if (homcull_result r = check_frame(b, fn); r != HOMCULL_OK) return r;
    TriangleInput in;
    if (homcull_result r = triangle_input(*b, triangles, model_matrix, fn, in); r != HOMCULL_OK) return r;
    ++b->draw_calls;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        b->buffer.render(in, b->jobs);
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_test_boxes(const homcull_buffer* b, const homcull_box* boxes, size_t count, const float* model_matrix,
                                         homcull_visibility* visibility) {
    const char* const fn = "homcull_buffer_test_boxes";
    if (count > 0 && !visibility)
        return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: visibility is null", fn);
    all_visible(visibility, count);
    if (homcull_result r = check_frame(b, fn); r != HOMCULL_OK) return r;
    if (count > 0 && !boxes) return capi::report(b->account.context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: boxes is null", fn);
    if (!capi::finite_matrix(model_matrix))
        return capi::report(b->account.context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: model_matrix has a number that is not finite", fn);
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        const glm::dmat4 model = read_model(*b, model_matrix);
        const std::array<float, 16> clip_from_model = capi::float_clip_from_model(b->clip_from_world, model);
        const glm::dvec4 far_row = far_row_in_model(*b, model);
        // The exact view test of the boxes the buffer's rectangles find visible
        // (buffer/exact_view_test.hpp), here with the volume of the frame's double matrices
        // rather than the float one: world boxes use the axes made at begin_frame, model boxes
        // make them in model space once per call, when a box first needs them.
        const FrustumAxes* volume = model_matrix ? nullptr : &b->world_view_axes;
        FrustumAxes model_volume;
        // The library's boxes (glm) filled from the C ones a block at a time, on the stack.
        constexpr std::size_t kBlock = 64;
        Aabb block[kBlock];
        Visibility answers[kBlock];
        for (std::size_t base = 0; base < count; base += kBlock) {
            const std::size_t n = std::min(kBlock, count - base);
            for (std::size_t k = 0; k < n; ++k) {
                const homcull_box& c = boxes[base + k];
                block[k].min = {c.min[0], c.min[1], c.min[2]};
                block[k].max = {c.max[0], c.max[1], c.max[2]};
            }
            b->buffer.state().test_aabbs_by_rectangle(block, n, clip_from_model, answers);
            for (std::size_t k = 0; k < n; ++k) {
                homcull_visibility v = as_c(answers[k]);
                if (v != HOMCULL_VIEW_CULLED && b->far_plane && capi::box_beyond_far(far_row, boxes[base + k].min, boxes[base + k].max))
                    v = HOMCULL_VIEW_CULLED;
                if (v == HOMCULL_VISIBLE &&
                    !detail::point_of_box_in_view(clip_from_model, &block[k].min.x, &block[k].max.x, b->near_distance, b->buffer.config().orthographic)) {
                    if (!volume) {
                        model_volume = view_volume(*b, b->clip_from_world * model);
                        volume = &model_volume;
                    }
                    if (separated(*volume, block[k])) v = HOMCULL_VIEW_CULLED;
                }
                visibility[base + k] = v;
            }
        }
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_test_rects(const homcull_buffer* b, const homcull_rect* rects, size_t count, homcull_visibility* visibility) {
    const char* const fn = "homcull_buffer_test_rects";
    if (count > 0 && !visibility)
        return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: visibility is null", fn);
    all_visible(visibility, count);
    if (homcull_result r = check_frame(b, fn); r != HOMCULL_OK) return r;
    if (count > 0 && !rects) return capi::report(b->account.context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: rects is null", fn);
    const bool y_down = (b->view.flags & HOMCULL_VIEW_Y_DOWN) != 0;
    return capi::guarded(b->account, fn, [&]() -> homcull_result {
        constexpr std::size_t kBlock = 64;
        ScreenRect block[kBlock];
        Visibility answers[kBlock];
        for (std::size_t base = 0; base < count; base += kBlock) {
            const std::size_t n = std::min(kBlock, count - base);
            for (std::size_t k = 0; k < n; ++k) {
                const homcull_rect& r = rects[base + k];
                const float nearest = b->buffer.config().orthographic ? orthographic_nearest_w(*b, r.nearest_w) : r.nearest_w;
                block[k] = y_down ? ScreenRect{r.min_x, -r.max_y, r.max_x, -r.min_y, nearest}
                                  : ScreenRect{r.min_x, r.min_y, r.max_x, r.max_y, nearest};
            }
            b->buffer.test_rects(block, n, answers);
            for (std::size_t k = 0; k < n; ++k) visibility[base + k] = as_c(answers[k]);
        }
        return HOMCULL_OK;
    });
}

homcull_result homcull_buffer_test_triangles(const homcull_buffer* b, const homcull_triangles* triangles, const float* model_matrix,
                                             homcull_visibility* visibility) {
    const char* const fn = "homcull_buffer_test_triangles";
    if (!visibility) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: visibility is null", fn);
    homcull_triangle_test_result result;
    const homcull_result r = test_triangles(b, triangles, model_matrix, homcull_triangle_test_desc{}, result, fn);
    *visibility = result.visibility;
    return r;
}

homcull_result homcull_buffer_test_triangles_ex(const homcull_buffer* b, const homcull_triangles* triangles, const float* model_matrix,
                                                const homcull_triangle_test_desc* desc, homcull_triangle_test_result* result) {
    const char* const fn = "homcull_buffer_test_triangles_ex";
    if (!result) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: result is null", fn);
    return test_triangles(b, triangles, model_matrix, desc ? *desc : homcull_triangle_test_desc{}, *result, fn);
}

homcull_result homcull_buffer_frame_stats(const homcull_buffer* b, homcull_frame_stats* stats) {
    const char* const fn = "homcull_buffer_frame_stats";
    if (!b || !stats) return capi::report(b ? b->account.context : nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: buffer or stats is null", fn);
    const RasterStats& s = b->buffer.stats();
    stats->triangles_in = s.triangles_in;
    stats->triangles_drawn = s.rasterized;
    stats->triangles_skipped = s.invalid + s.outside + s.too_large + s.backface_culled + s.degenerate;
    stats->clusters_hidden = s.cluster_bands_hidden;
    stats->draw_calls = b->draw_calls;
    stats->allocations = b->account.allocations.load() - b->allocations_at_frame;
    return HOMCULL_OK;
}

}  // extern "C"
