#include <homcull/tbb_parallel_for.hpp>

#include <tbb/parallel_for.h>

namespace homcull {
namespace {

void run(void*, std::size_t count, void (*task)(void*, std::size_t), void* task_data) {
    // One TBB task per index: the library's tasks are already coarse (chunks, bands).
    tbb::parallel_for(std::size_t(0), count, [&](std::size_t i) { task(task_data, i); });
}

}  // namespace

ParallelFor tbb_parallel_for() { return ParallelFor{run, nullptr}; }

}  // namespace homcull
