#pragma once
// The instruction set the SIMD kernels of every layer run.
#include <string>
#include <vector>

namespace homcull {

// Instruction sets. Rendering runs SIMD kernels compiled for several instruction sets and
// chosen at run time (Google Highway); every one gives the same bits as the plain scalar
// reference path. Each buffer runs the instruction set it was made with
// (BufferConfig::isa); for tests, benchmarks and users who want to pin one:
//   available_isas(): "scalar" and the SIMD ones this CPU and build support (avx512, avx2,
//                     sse4 on x86; sve2, sve, neon on Arm; emu128), "scalar" first, then best
//                     first.
//   select_isa(name): the process-wide default, for buffers made or configured without naming
//                     one from then on: "best" (the default), "scalar", or one of those.
//                     Buffers that exist keep theirs. Throws homcull::Error for another name.
//   selected_isa():   the default's name ("best" gives the name of the best one).
std::vector<std::string> available_isas();
void select_isa(const std::string& name);
std::string selected_isa();

}  // namespace homcull
