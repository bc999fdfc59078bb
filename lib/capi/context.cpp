// homcull.h: results and messages, version, instruction sets, contexts and their memory.
#include "capi/c_objects.hpp"

#include <homcull/error.hpp>

#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

// The layout the C side compiles against, checked on this side too (homcull.h checks the sizes
// where it is included; these are the offsets an FFI binding must also agree on).
static_assert(offsetof(homcull_view, layout) == 128 && offsetof(homcull_view, flags) == 144, "homcull_view's layout");
static_assert(offsetof(homcull_box, max) == 12, "homcull_box's layout");
static_assert(offsetof(homcull_rect, nearest_w) == 16, "homcull_rect's layout");
static_assert(offsetof(homcull_buffer_desc, near_distance) == 12 && offsetof(homcull_buffer_desc, flags) == 16, "homcull_buffer_desc's layout");
static_assert(offsetof(homcull_frame_stats, allocations) == 40, "homcull_frame_stats' layout");
static_assert(offsetof(homcull_reserve_desc, max_task_list_triangles) == 8 + 3 * sizeof(size_t), "homcull_reserve_desc's layout");
static_assert(offsetof(homcull_reserve_desc, max_job_threads) == 8 + 4 * sizeof(size_t), "homcull_reserve_desc's layout");
static_assert(offsetof(homcull_context_desc, isa) == 5 * sizeof(void*), "homcull_context_desc's layout");
static_assert(sizeof(homcull_visibility) == 1 && sizeof(homcull_result) == 4 && sizeof(homcull_isa) == 4, "enums' sizes");

namespace homcull::capi {
namespace {

thread_local char last_error[512] = "";

void* default_allocate(void*, std::size_t size, std::size_t alignment) {
    // aligned_alloc wants a size that is a multiple of the alignment.
    return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}
void default_deallocate(void*, void* memory, std::size_t) { std::free(memory); }

void* account_allocate(void* user, std::size_t size, std::size_t alignment) {
    Account& a = *static_cast<Account*>(user);
    const homcull_allocator& engine = a.context->allocator;
    void* memory = engine.allocate(engine.user, size, alignment);
    if (!memory) return nullptr;
    a.bytes += size;
    ++a.allocations;
    a.context->bytes += size;
    return memory;
}

void account_deallocate(void* user, void* memory, std::size_t size) {
    Account& a = *static_cast<Account*>(user);
    a.bytes -= size;
    a.context->bytes -= size;
    a.context->allocator.deallocate(a.context->allocator.user, memory, size);
}

// The instruction sets of homcull.h by the names select_isa takes.
const char* const kIsaNames[HOMCULL_ISA_COUNT] = {"best", "scalar", "sse4", "avx2", "avx512", "neon", "sve", "sve2", "emu128"};

}  // namespace

Account::Account(homcull_context* owner) : context(owner) {
    hooks.allocate = account_allocate;
    hooks.deallocate = account_deallocate;
    hooks.user = this;
}

homcull_result report(const homcull_context* context, homcull_result result, const char* format, ...) {
    va_list args;
    va_start(args, format);
    std::vsnprintf(last_error, sizeof last_error, format, args);
    va_end(args);
    if (context && context->on_error) context->on_error(context->error_user, result, last_error);
    return result;
}

namespace {

// homcull_context_create's errors: to the desc's callback, there being no context yet.
homcull_result report_to(const homcull_context_desc* desc, homcull_result result) {
    if (desc && desc->on_error) desc->on_error(desc->error_user, result, last_error);
    return result;
}

}  // namespace

homcull_result exception_result(const homcull_context* context, const char* function) noexcept {
    try {
        throw;
    } catch (const std::bad_alloc&) {
        return report(context, HOMCULL_ERROR_OUT_OF_MEMORY, "%s: out of memory (the engine's allocator returned null)", function);
    } catch (const Error& e) {
        return report(context, HOMCULL_ERROR_INVALID_ARGUMENT, "%s: %s", function, e.what());
    } catch (const std::exception& e) {
        return report(context, HOMCULL_ERROR_INTERNAL, "%s: internal error: %s", function, e.what());
    } catch (...) {
        return report(context, HOMCULL_ERROR_INTERNAL, "%s: internal error (an unknown exception)", function);
    }
}

}  // namespace homcull::capi

using namespace homcull;

homcull_context::homcull_context(const homcull_context_desc& desc)
    : allocator(desc.allocator), on_error(desc.on_error), error_user(desc.error_user), isa(desc.isa), own(this) {
    if (!allocator.allocate) {
        allocator.allocate = capi::default_allocate;
        allocator.deallocate = capi::default_deallocate;
    }
}

extern "C" {

const char* homcull_result_name(homcull_result result) {
    switch (result) {
        case HOMCULL_OK: return "HOMCULL_OK";
        case HOMCULL_ERROR_INVALID_ARGUMENT: return "HOMCULL_ERROR_INVALID_ARGUMENT";
        case HOMCULL_ERROR_OUT_OF_MEMORY: return "HOMCULL_ERROR_OUT_OF_MEMORY";
        case HOMCULL_ERROR_UNSUPPORTED: return "HOMCULL_ERROR_UNSUPPORTED";
        case HOMCULL_ERROR_INVALID_OPERATION: return "HOMCULL_ERROR_INVALID_OPERATION";
        case HOMCULL_ERROR_INTERNAL: return "HOMCULL_ERROR_INTERNAL";
        default: return "HOMCULL_ERROR_UNKNOWN";
    }
}

const char* homcull_last_error(void) { return capi::last_error; }

uint32_t homcull_version(void) { return HOMCULL_VERSION; }

uint32_t homcull_supported_isas(void) {
    uint32_t bits = 0;
    for (homcull_isa isa = 0; isa < HOMCULL_ISA_COUNT; ++isa)
        if (detail::find_isa_choice(capi::kIsaNames[isa])) bits |= 1u << isa;
    return bits;
}

const char* homcull_isa_name(homcull_isa isa) { return isa >= 0 && isa < HOMCULL_ISA_COUNT ? capi::kIsaNames[isa] : "unknown"; }

homcull_result homcull_context_create(const homcull_context_desc* desc, homcull_context** out) {
    const auto fail = [desc](homcull_result r) { return capi::report_to(desc, r); };
    if (!out) return fail(capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_context_create: out is null"));
    *out = nullptr;
    if (!desc) return fail(capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_context_create: desc is null"));
    if (!desc->allocator.allocate != !desc->allocator.deallocate)
        return fail(capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT,
                                 "homcull_context_create: give both allocate and deallocate, or neither (the C library's then)"));
    if (desc->isa < 0 || desc->isa >= HOMCULL_ISA_COUNT)
        return fail(capi::report(nullptr, HOMCULL_ERROR_INVALID_ARGUMENT, "homcull_context_create: instruction set %d is not a homcull_isa",
                                 int(desc->isa)));
    if (!(homcull_supported_isas() & (1u << desc->isa)))
        return fail(capi::report(nullptr, HOMCULL_ERROR_UNSUPPORTED,
                                 "homcull_context_create: instruction set '%s' is not available on this CPU or in this build",
                                 capi::kIsaNames[desc->isa]));
    homcull_allocator engine = desc->allocator;
    if (!engine.allocate) engine = {capi::default_allocate, capi::default_deallocate, nullptr};
    void* memory = engine.allocate(engine.user, sizeof(homcull_context), alignof(homcull_context));
    if (!memory)
        return fail(capi::report(nullptr, HOMCULL_ERROR_OUT_OF_MEMORY, "homcull_context_create: out of memory (the engine's allocator returned null)"));
    homcull_context* context = new (memory) homcull_context(*desc);
    try {
        context->choice = &detail::isa_choice(capi::kIsaNames[desc->isa]);
    } catch (...) {  // checked above: only a bug gets here
        const homcull_result r = capi::exception_result(nullptr, "homcull_context_create");
        context->~homcull_context();
        engine.deallocate(engine.user, memory, sizeof(homcull_context));
        return fail(r);
    }
    context->bytes += sizeof(homcull_context);
    *out = context;
    return HOMCULL_OK;
}

void homcull_context_destroy(homcull_context* context) {
    if (!context) return;
    const homcull_allocator engine = context->allocator;
    context->~homcull_context();
    engine.deallocate(engine.user, context, sizeof(homcull_context));
}

homcull_isa homcull_context_isa(const homcull_context* context) {
    if (!context) return HOMCULL_ISA_BEST;
    for (homcull_isa isa = 1; isa < HOMCULL_ISA_COUNT; ++isa)
        if (std::strcmp(context->choice->name, capi::kIsaNames[isa]) == 0) return isa;
    return HOMCULL_ISA_BEST;
}

uint64_t homcull_context_allocated_bytes(const homcull_context* context) { return context ? context->bytes.load() : 0; }

}  // extern "C"
