#pragma once
// One culled frame's debug dump, shared by `homcull dump` and `homcull cull --dump DIR`:
// DIR/maps.exr (every buffer and pyramid level), DIR/<part>.png with colormaps.json, and
// DIR/overlay.png (the scene coloured by the answers, false culls in magenta).
#include <homcull/scene_culler.hpp>
#include <homcull/truth/ray_scene.hpp>

#include <string>
#include <vector>

namespace homcull::cli {

// Creates `dir` when missing (throws homcull::Error naming it when it cannot). Call before
// the expensive work, so that a bad folder fails first.
void prepare_dump_folder(const std::string& dir);

// Writes the dump of the culler's last frame (creating `dir` when missing) and prints what it wrote (on stdout, or on
// stderr when stdout carries JSON). Returns the objects the overlay found culled yet seen.
std::vector<std::uint32_t> write_frame_dump(const SceneCuller& culler, const RayScene& rays, const Camera& camera,
                                            const std::vector<OccludeeAnswer>& answers, const std::string& dir,
                                            bool print_to_stderr);

}  // namespace homcull::cli
