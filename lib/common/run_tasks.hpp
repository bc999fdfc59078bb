#pragma once
// Runs tasks 0..count-1 through the caller's job system (ParallelFor) when it has one and there
// is more than one task, else one after another on the calling thread. Each task runs as the
// calling thread would: in the library's floating-point environment (float_mode.hpp), with the
// caller's memory hooks (homcull/detail/memory.hpp), whichever thread runs it. (The instruction
// set is the buffer's: its kernel table travels with the task's data.) No exception leaves a task into the job system (a C job system
// cannot pass one on, and an exception reaching it would end the process): the first one a
// task throws is kept and thrown again on the calling thread once every task has returned.
#include "common/float_mode.hpp"

#include <homcull/detail/memory.hpp>
#include <homcull/parallel_for.hpp>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <type_traits>

namespace homcull::detail {

inline void run_tasks(const ParallelFor& parallel, std::size_t count, void (*task)(void* data, std::size_t index), void* data) {
    if (!parallel.run || count <= 1) {  // on the calling thread, whose entry point set the environment
        for (std::size_t i = 0; i < count; ++i) task(data, i);
        return;
    }
    struct Wrapped {
        void (*task)(void*, std::size_t);
        void* data;
        const MemoryHooks* hooks;
        std::atomic<bool> failed{false};
        std::exception_ptr error;  // the first task's to throw, written once (failed guards it)
    } wrapped{task, data, current_memory_hooks(), {false}, nullptr};
    parallel.run(parallel.user, count, [](void* w, std::size_t i) {
        Wrapped& t = *static_cast<Wrapped*>(w);
        const StandardFloatMode mode;
        const MemoryScope memory(t.hooks);
        try {
            t.task(t.data, i);
        } catch (...) {
            if (!t.failed.exchange(true)) t.error = std::current_exception();
        }
    }, &wrapped);
    if (wrapped.failed.load()) std::rethrow_exception(wrapped.error);
}

// Calls body(i) once for every i in [0, count): `per_task` consecutive indices a task, through
// run_tasks (so on the calling thread, in order, without a job system). For load-time loops
// whose every index writes only its own results: the bits are then those of one thread.
template <typename Body>
void for_each_index(const ParallelFor& parallel, std::size_t count, std::size_t per_task, Body&& body) {
    if (per_task == 0) per_task = 1;
    struct Job {
        std::remove_reference_t<Body>* body;
        std::size_t count, per_task;
    } job{&body, count, per_task};
    run_tasks(parallel, (count + per_task - 1) / per_task, [](void* data, std::size_t k) {
        const Job& j = *static_cast<const Job*>(data);
        for (std::size_t i = k * j.per_task, end = std::min(j.count, i + j.per_task); i < end; ++i) (*j.body)(i);
    }, &job);
}

}  // namespace homcull::detail
