// Draws a wall in front of the camera and asks about a rectangle behind it and one beside it:
// the C++ core library alone.
#include <homcull/occlusion_buffer.hpp>

#include <cstdio>
#include <vector>

int main() {
    homcull::BufferConfig config;
    config.width = 64;
    config.height = 32;
    homcull::OcclusionBuffer buffer(config);
    // One clip-space triangle at w = 2 over the left half of the view: its right edge at
    // x = 0.1 in NDC, its apex far to the left (one triangle: no edge between two to leave open).
    const std::vector<float> wall = {0.2f, -18, 0, 2, 0.2f, 18, 0, 2, -40, 0, 0, 2};
    homcull::TriangleInput in;
    in.positions = wall.data();
    in.position_components = 4;
    in.position_stride = 16;
    in.vertex_count = 3;
    in.triangle_count = 1;
    in.backface = homcull::Backface::none;
    in.clip_space = true;
    buffer.render_frame(in);
    const bool behind = buffer.test_rect(-0.8f, -0.5f, -0.2f, 0.5f, 5.0f) == homcull::Visibility::occluded;
    const bool beside = buffer.test_rect(0.2f, -0.5f, 0.8f, 0.5f, 5.0f) == homcull::Visibility::visible;
    std::printf("core consumer: behind the wall %s, beside it %s (%s)\n", behind ? "occluded" : "NOT occluded",
                beside ? "visible" : "NOT visible", buffer.config().isa);
    return behind && beside ? 0 : 1;
}
