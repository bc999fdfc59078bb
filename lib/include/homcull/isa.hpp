#pragma once
// The instruction set the SIMD kernels of every layer run.
#include <string>
#include <vector>

namespace homcull {

// Instruction sets. Rendering runs SIMD kernels compiled for several instruction sets and
// chosen at run time (Google Highway); every one gives the same bits as the plain scalar
// reference path. For tests, benchmarks and users who want to pin one:
//   available_isas(): "scalar" and the SIMD ones this CPU and build support (avx512, avx2,
//                     sse4 on x86; sve2, sve, neon on Arm; emu128), best first after "scalar".
//   select_isa(name): "best" (the default), "scalar", or one of those; process-wide, not to
//                     be called while a render is in flight. Throws homcull::Error otherwise.
std::vector<std::string> available_isas();
void select_isa(const std::string& name);
std::string selected_isa();

}  // namespace homcull
