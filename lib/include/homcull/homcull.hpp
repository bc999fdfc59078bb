#pragma once
// A thin header-only C++ layer over the C interface (homcull.h), in the way meshoptimizer and
// Embree offer theirs: handles that destroy themselves, containers in place of pointer and
// count. Nothing here throws or allocates: every call that can fail returns the C result
// (homcull_last_error() has the message). It needs only homcull.h, so an engine links
// libhomcull.so (or the core library) and nothing of the C++ library's headers.
#include <homcull/homcull.h>

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace homcull::api {

using Result = homcull_result;

// A view of contiguous elements (std::vector, std::array, a C array): what std::span is in
// C++20.
template <typename T>
struct Span {
    T* data = nullptr;
    std::size_t size = 0;
    Span() = default;
    Span(T* d, std::size_t n) : data(d), size(n) {}
    template <typename Container,
              typename = std::enable_if_t<std::is_convertible_v<decltype(std::declval<Container&>().data()), T*>>>
    Span(Container& c) : data(c.data()), size(c.size()) {}  // NOLINT: implicit, as std::span
    template <std::size_t N>
    Span(T (&a)[N]) : data(a), size(N) {}  // NOLINT
};

// An owning handle: moves, never copies, destroys its object.
template <typename Handle, void (*Destroy)(Handle*)>
class Owned {
public:
    Owned() = default;
    explicit Owned(Handle* h) : handle_(h) {}
    Owned(Owned&& o) noexcept : handle_(std::exchange(o.handle_, nullptr)) {}
    Owned& operator=(Owned&& o) noexcept {
        if (this != &o) reset(std::exchange(o.handle_, nullptr));
        return *this;
    }
    Owned(const Owned&) = delete;
    Owned& operator=(const Owned&) = delete;
    ~Owned() { reset(); }
    void reset(Handle* h = nullptr) {
        if (handle_) Destroy(handle_);
        handle_ = h;
    }
    Handle* get() const { return handle_; }
    explicit operator bool() const { return handle_ != nullptr; }

protected:
    Handle* handle_ = nullptr;
};

class Context : public Owned<homcull_context, homcull_context_destroy> {
public:
    Context() = default;
    [[nodiscard]] static Result create(const homcull_context_desc& desc, Context& out) {
        homcull_context* c = nullptr;
        const Result r = homcull_context_create(&desc, &c);
        out.reset(c);
        return r;
    }
    homcull_isa isa() const { return homcull_context_isa(handle_); }
    std::uint64_t allocated_bytes() const { return homcull_context_allocated_bytes(handle_); }
};

class Mesh : public Owned<homcull_mesh, homcull_mesh_destroy> {
public:
    Mesh() = default;
    [[nodiscard]] static Result create(const Context& context, const homcull_mesh_desc& desc, Mesh& out) {
        homcull_mesh* m = nullptr;
        const Result r = homcull_mesh_create(context.get(), &desc, &m);
        out.reset(m);
        return r;
    }
    std::size_t triangle_count() const { return homcull_mesh_triangle_count(handle_); }
};

class Buffer : public Owned<homcull_buffer, homcull_buffer_destroy> {
public:
    Buffer() = default;
    [[nodiscard]] static Result create(const Context& context, const homcull_buffer_desc& desc, Buffer& out) {
        homcull_buffer* b = nullptr;
        const Result r = homcull_buffer_create(context.get(), &desc, &b);
        out.reset(b);
        return r;
    }
    [[nodiscard]] Result set_resolution(int width, int height) { return homcull_buffer_set_resolution(handle_, width, height); }
    [[nodiscard]] Result set_near(float near_distance) { return homcull_buffer_set_near(handle_, near_distance); }
    [[nodiscard]] Result reserve(const homcull_reserve_desc& desc) { return homcull_buffer_reserve(handle_, &desc); }
    [[nodiscard]] Result begin_frame(const homcull_view& view) { return homcull_buffer_begin_frame(handle_, &view); }
    // One instance per 16 floats of model_matrices (the view's layout); none: the identity.
    [[nodiscard]] Result draw(const Mesh& mesh, Span<const float> model_matrices = {}) {
        return homcull_buffer_draw_mesh(handle_, mesh.get(), model_matrices.data, model_matrices.data ? model_matrices.size / 16 : 1);
    }
    [[nodiscard]] Result draw(const homcull_triangles& triangles, const float* model_matrix = nullptr) {
        return homcull_buffer_draw_triangles(handle_, &triangles, model_matrix);
    }
    // Task lists, the pull model (homcull.h): begin_tasks, draws of meshes, close_tasks, then
    // run_task(i) for every i < task_count on the engine's threads, then finish_tasks.
    [[nodiscard]] Result begin_tasks() { return homcull_buffer_begin_tasks(handle_); }
    [[nodiscard]] Result close_tasks(std::size_t& task_count) { return homcull_buffer_close_tasks(handle_, &task_count); }
    [[nodiscard]] Result run_task(std::size_t index) { return homcull_buffer_run_task(handle_, index); }
    [[nodiscard]] Result finish_tasks() { return homcull_buffer_finish_tasks(handle_); }
    // Answers into `visibility`, which must be as long as `boxes` (else an error).
    [[nodiscard]] Result test(Span<const homcull_box> boxes, Span<homcull_visibility> visibility, const float* model_matrix = nullptr) const {
        if (visibility.size < boxes.size) return homcull_buffer_test_boxes(handle_, boxes.data, boxes.size, model_matrix, nullptr);
        return homcull_buffer_test_boxes(handle_, boxes.data, boxes.size, model_matrix, visibility.data);
    }
    [[nodiscard]] Result test(Span<const homcull_rect> rects, Span<homcull_visibility> visibility) const {
        if (visibility.size < rects.size) return homcull_buffer_test_rects(handle_, rects.data, rects.size, nullptr);
        return homcull_buffer_test_rects(handle_, rects.data, rects.size, visibility.data);
    }
    [[nodiscard]] Result test(const homcull_triangles& triangles, homcull_visibility& visibility, const float* model_matrix = nullptr) const {
        return homcull_buffer_test_triangles(handle_, &triangles, model_matrix, &visibility);
    }
    homcull_frame_stats frame_stats() const {
        homcull_frame_stats s{};
        (void)homcull_buffer_frame_stats(handle_, &s);
        return s;
    }
    std::uint64_t allocated_bytes() const { return homcull_buffer_allocated_bytes(handle_); }
};

}  // namespace homcull::api
