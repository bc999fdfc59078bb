#include <homcull/tbb_parallel_for.hpp>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

namespace homcull {
namespace {

void run(void*, std::size_t count, void (*task)(void*, std::size_t), void* task_data) {
    // One TBB task per index: the library's tasks are already coarse (chunks, bands).
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) { task(task_data, i); });
}

}  // namespace

ParallelFor tbb_parallel_for() {
    // The threads TBB would use now: the arena's, within a global_control limit if one is set.
    const std::size_t threads = std::min(std::size_t(tbb::this_task_arena::max_concurrency()),
                                         tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    return ParallelFor{run, nullptr, threads};
}

}  // namespace homcull
