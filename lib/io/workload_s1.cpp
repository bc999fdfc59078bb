#include <homcull/error.hpp>
#include <homcull/io/workload_s1.hpp>

#include <cstring>
#include <fstream>

namespace homcull {
namespace {

std::vector<float> read_floats(const std::string& path, std::size_t count) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw Error(path + ": cannot open the workload file");
    const std::streamoff size = in.tellg();
    if (size != std::streamoff(count * sizeof(float)))
        throw Error(path + ": expected " + std::to_string(count * sizeof(float)) + " bytes, found " + std::to_string(size));
    std::vector<float> data(count);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(data.data()), std::streamsize(count * sizeof(float)));
    if (!in) throw Error(path + ": read error");
    return data;  // little-endian float32, as on every platform homcull builds for
}

}  // namespace

TriangleInput WorkloadS1::occluder_input() const {
    TriangleInput in;
    in.positions = occluders.data();
    in.position_components = 4;
    in.position_stride = 4 * sizeof(float);
    in.vertex_count = occluder_count() * 3;
    in.triangle_count = occluder_count();
    in.model_to_clip = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    in.backface = Backface::cw;
    in.clip_space = true;  // clip-space points already: drawn through cell notes
    return in;
}

WorkloadS1 load_workload_s1(const std::string& folder) {
    WorkloadS1 w;
    w.occluders = read_floats(folder + "/occluders_clip_xyzw_f32.bin", 100000 * 12);
    w.rects = read_floats(folder + "/rects_ndc_xmin_ymin_xmax_ymax_wmin_f32.bin", 1000000 * 5);
    w.occludee_tris = read_floats(folder + "/occludee_tris_clip_xyzw_f32.bin", 100000 * 12);
    return w;
}

}  // namespace homcull
