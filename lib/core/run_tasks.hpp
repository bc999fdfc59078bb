#pragma once
// Runs tasks 0..count-1 through the caller's job system (ParallelFor) when it has one and there
// is more than one task, else one after another on the calling thread; each task in the
// library's floating-point environment (float_mode.hpp), whichever thread runs it.
#include "core/float_mode.hpp"

#include <homcull/occlusion_buffer.hpp>

#include <cstddef>

namespace homcull::detail {

inline void run_tasks(const ParallelFor& parallel, std::size_t count, void (*task)(void* data, std::size_t index), void* data) {
    if (!parallel.run || count <= 1) {  // on the calling thread, whose entry point set the environment
        for (std::size_t i = 0; i < count; ++i) task(data, i);
        return;
    }
    struct Wrapped {
        void (*task)(void*, std::size_t);
        void* data;
    } wrapped{task, data};
    parallel.run(parallel.user, count, [](void* w, std::size_t i) {
        const Wrapped& t = *static_cast<const Wrapped*>(w);
        const StandardFloatMode mode;
        t.task(t.data, i);
    }, &wrapped);
}

}  // namespace homcull::detail
