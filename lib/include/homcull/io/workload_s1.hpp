#pragma once
// Workload S1 (../shared/workloads/s1, see its README): the synthetic occluder stress test
// Intel MOC was measured on. Little-endian float32, no header.
#include <homcull/occlusion_buffer.hpp>

#include <string>
#include <vector>

namespace homcull {

struct WorkloadS1 {
    std::vector<float> occluders;      // 100,000 triangles x 3 vertices x (x, y, z, w) clip space
    std::vector<float> rects;          // 1,000,000 x (xmin, ymin, xmax, ymax) NDC (y up), nearest w
    std::vector<float> occludee_tris;  // like occluders, a second draw
    std::size_t occluder_count() const { return occluders.size() / 12; }
    std::size_t rect_count() const { return rects.size() / 5; }
    // The occluders as MOC was measured on them: clip-space xyzw, identity matrix, clockwise
    // triangles culled (all of S1's are counter-clockwise).
    TriangleInput occluder_input() const;
};

// Reads the three files from `folder`; throws homcull::Error naming a missing or short file.
WorkloadS1 load_workload_s1(const std::string& folder);

}  // namespace homcull
