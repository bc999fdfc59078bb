#pragma once
// homcull bench --workload frame --scaling: what N threads gain over one on whole frames, beside
// what this machine lets N threads gain at that very moment.
//
// The machines this runs on are virtual, and how much a second core gives moves with the host's
// load (from 1.3 to 1.9 times for the same process, minutes apart). A speed-up measured alone
// cannot tell the culler's losses from the machine's, so every measurement is paired with a
// ceiling taken in the same round: N copies of the single-threaded cull, each on its own thread
// with its own culler and nothing shared, started together. Their frame takes T_par where one
// copy alone takes t_1; N t_1 / T_par is the most any division of that frame's work among N
// threads could gain then (N if the cores do not slow each other down).
#include <homcull/io/camera_path.hpp>
#include <homcull/parallel_for.hpp>
#include <homcull/scene.hpp>
#include <homcull/scene_culler.hpp>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <vector>

namespace homcull::cli {

// Throws homcull::Error unless 2 <= threads <= the machine's hardware threads.
void check_scaling_threads(int threads);

// For `rounds` rounds over the views, per view in this order: one thread (SceneCuller::cull with
// no job system), `threads` threads (through `parallel`), and the ceiling (threads copies at
// once). Each is timed on its second cull of the view in a row, as consecutive frames of a walk
// are alike: the job system's workers are awake and the bands' order (clustered_render.cpp)
// comes from the same view. Before each round, the time a cache line takes between two cores
// and back. Returns the mean of the views' median frame times of each kind and their ratios
// (speed-up and ceiling), the per-round ratios' spreads and the round trips', and every
// round's figures in order.
nlohmann::json measure_thread_scaling(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config,
                                      const CameraPath& views, int rounds, int threads, const ParallelFor& parallel);

}  // namespace homcull::cli
