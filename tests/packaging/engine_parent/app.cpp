// The engine's own code, linking homcull::core from the subproject.
#include <homcull/isa.hpp>
#include <homcull/occlusion_buffer.hpp>

#include <cstdio>

int main() {
    homcull::BufferConfig config;
    config.width = 32;
    config.height = 16;
    const homcull::OcclusionBuffer buffer(config);
    std::printf("engine app: a %dx%d buffer on %s\n", buffer.config().width, buffer.config().height, buffer.config().isa);
    return buffer.test_rect(-0.5f, -0.5f, 0.5f, 0.5f, 1.0f) == homcull::Visibility::visible ? 0 : 1;
}
