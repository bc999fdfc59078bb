#pragma once
// The caller's job system, as every layer that splits work into tasks takes it.
#include <cstddef>

namespace homcull {

// The caller's job system (renders, the scene culler's tests and its preparation):
// run(user, count, task, task_data) must call
// task(task_data, i) once for every i in [0, count), in any order, on any threads, and return
// when all calls have returned. The library creates no threads. Left empty, tasks run in
// order on the calling thread. Results are the same bits whatever the threads.
struct ParallelFor {
    void (*run)(void* user, std::size_t count, void (*task)(void* task_data, std::size_t index), void* task_data) = nullptr;
    void* user = nullptr;
    // How many threads run the tasks (0: not said, taken as 2). Only a speed hint: a render of a
    // clip-space soup splits the buffer's rows into this many parts, one task each.
    std::size_t threads = 0;
};

}  // namespace homcull
