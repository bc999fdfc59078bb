#pragma once
// The C interface's objects (homcull.h) and the one place where C++ errors become results.
//
// Every object is placed in memory from the engine's allocator, and everything it holds is made
// inside a MemoryScope of its own account (homcull/detail/memory.hpp): its containers keep that
// account's hooks for life. A context's buffers run its instruction set (BufferConfig::isa,
// common/isa_choice.hpp). Errors found here are reported without throwing (report()); those
// thrown by the C++ library are caught at the entry point (guarded()), so none reaches the caller.
#include <homcull/homcull.h>

#include <homcull/detail/memory.hpp>
#include <homcull/frustum.hpp>
#include <homcull/occluder_clusters.hpp>
#include <homcull/occlusion_buffer.hpp>

#include "common/isa_choice.hpp"

#include <glm/mat4x4.hpp>

#include <atomic>
#include <cstdint>
#include <new>

namespace homcull::capi {

// Counts what an object holds from the engine's allocator; its hooks route every allocation to
// the context's allocator through it.
struct Account {
    homcull_context* context = nullptr;
    detail::MemoryHooks hooks;
    std::atomic<std::uint64_t> bytes{0}, allocations{0};
    explicit Account(homcull_context* owner);
};

}  // namespace homcull::capi

struct homcull_context {
    homcull_allocator allocator;  // with the defaults filled in
    homcull_error_callback on_error;
    void* error_user;
    homcull_isa isa;
    const homcull::detail::IsaChoice* choice = nullptr;
    std::atomic<std::uint64_t> bytes{0};
    homcull::capi::Account own;  // the context's own memory
    explicit homcull_context(const homcull_context_desc& desc);
};

struct homcull_mesh {
    homcull::capi::Account account;
    homcull::OccluderClusters clusters;  // made in the account's scope
    std::size_t triangle_count = 0;
    // The box of the vertices its triangles use (bounded: all finite): an instance wholly outside
    // the view is skipped before its clusters are placed.
    float bounds_min[3] = {0, 0, 0}, bounds_max[3] = {0, 0, 0};
    bool bounded = false;
    explicit homcull_mesh(homcull_context* context) : account(context) {}
};

struct homcull_buffer {
    homcull::capi::Account account;
    homcull::OcclusionBuffer buffer;  // made in the account's scope
    // The frame's camera, in the library's convention (column-major, clip y up).
    bool frame_begun = false;
    homcull_view view{};
    glm::dmat4 clip_from_world{1.0};
    homcull::Backface backface = homcull::Backface::cw;
    bool far_plane = false;
    glm::dvec4 far_row{0.0};  // in front of (or on) the far plane: dot(far_row, world clip) >= 0
    // The view volume as separating axes for world boxes (view_volume_axes): test_boxes' exact
    // frustum test, made once per frame.
    homcull::FrustumAxes world_view_axes;
    // An orthographic frame (begin_frame configures the buffer so: BufferConfig::orthographic)
    // has the engine's clip z = (z_gl - ortho_z_offset) / ortho_z_scale; perspective frames clip
    // at near_distance (an orthographic buffer's own near_w is its near plane's).
    double ortho_z_scale = 1.0, ortho_z_offset = 0.0;
    float near_distance = 0.1f;
    std::uint64_t draw_calls = 0, allocations_at_frame = 0;
    homcull::ParallelFor jobs;  // the engine's job system for draws (empty: the calling thread)
    // A task list (homcull_buffer_begin_tasks): draws recorded, then tasks run by the engine.
    enum class Tasks : std::uint8_t { none, recording, closed } tasks = Tasks::none;
    std::size_t task_count = 0;
    homcull_buffer(homcull_context* context, const homcull::BufferConfig& config);
};

namespace homcull::capi {

// Writes the message (printf-style) to this thread's last-error buffer, calls the context's
// callback (when there is a context) and returns `result`. Allocates nothing.
homcull_result report(const homcull_context* context, homcull_result result, const char* format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

// Runs `body` (which returns a homcull_result), turning
// every exception into a result: std::bad_alloc into HOMCULL_ERROR_OUT_OF_MEMORY, homcull::Error
// (the library's checks) into HOMCULL_ERROR_INVALID_ARGUMENT, anything else into
// HOMCULL_ERROR_INTERNAL.
homcull_result exception_result(const homcull_context* context, const char* function) noexcept;
template <typename Body>
homcull_result guarded(const homcull_context* context, const char* function, Body&& body) noexcept {
    try {
        return body();
    } catch (...) {
        return exception_result(context, function);
    }
}
// The same, with an object's account current (homcull/detail/memory.hpp): what the call makes
// (scratch a render creates on first use, say) is the object's.
template <typename Body>
homcull_result guarded(const Account& account, const char* function, Body&& body) noexcept {
    const detail::MemoryScope scope(&account.hooks);
    return guarded(account.context, function, std::forward<Body>(body));
}

// Places a T in memory from the context's allocator (its own account), or null when that fails.
template <typename T, typename... Args>
T* place(homcull_context* context, Args&&... args) {
    void* memory = detail::hooked_allocate(&context->own.hooks, sizeof(T), alignof(T));
    try {
        return new (memory) T(context, std::forward<Args>(args)...);
    } catch (...) {
        detail::hooked_deallocate(&context->own.hooks, memory, sizeof(T), alignof(T));
        throw;
    }
}
template <typename T>
void unplace(T* object) noexcept {
    homcull_context* context = object->account.context;
    object->~T();
    detail::hooked_deallocate(&context->own.hooks, object, sizeof(T), alignof(T));
}

}  // namespace homcull::capi
