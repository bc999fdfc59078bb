#pragma once
// A ParallelFor backed by oneTBB, for the tools and for engines without a job system of
// their own (target homcull::tbb). Thread count: TBB's when it is called, within any
// tbb::global_control limit then in force (ParallelFor::threads).
#include <homcull/parallel_for.hpp>

namespace homcull {

ParallelFor tbb_parallel_for();

}  // namespace homcull
