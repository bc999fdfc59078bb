#pragma once
// homcull bench --workload frame: whole frames of the scene culler on a real scene, as an
// engine pays for them (occluders in, every object answered), per view: the frame's time and
// each stage's, and the culling efficiency and false culls against Embree ground truth at the
// display's pixel centres.
#include "cull_options.hpp"

#include <cstdint>
#include <string>

namespace homcull::cli {

struct FrameBenchOptions {
    std::string scene;        // a scene file or gen:...
    std::string views;        // a camera path file (data/views/castle.json); or:
    int walk = 0;             // a walk of this many frames through the scene (walk_path), or
    int random = 0;           // this many random viewpoints in its free space (random_views)
    std::uint64_t seed = 1;   // of the walk or the random views
    int rounds = 15;          // timed culls per view, interleaved over the views; the median is reported
    int threads = 1;
    std::string isa = "best";
    CullOptions cull;         // the culler's configuration (display: cull.resolution)
    bool json = false;
    bool scaling = false;     // also measure what the threads gain over one (bench_scaling.hpp)
};

// Prints, per view and over all, the median whole-frame time (the cull() call, timed around
// it), each stage's median (SceneCullTimings), and against Embree: the efficiency over the
// objects hidden outright (DESIGN.md, "coincident surfaces"), the plain efficiency beside it,
// and the false culls. With `scaling`, then also what `threads` threads gain over one, beside
// the machine's ceiling (measure_thread_scaling). Throws homcull::Error on bad options.
void run_frame_bench(const FrameBenchOptions& options);

}  // namespace homcull::cli
