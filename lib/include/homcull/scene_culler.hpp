#pragma once
// Culling a scene's objects from one camera with hierarchical occlusion maps: render the
// chosen occluders into an occlusion buffer, build the maps, test every object's world box.
// One SceneCuller is reused frame after frame: the buffer, the maps and the occluder triangles
// are allocated once.
#include <homcull/occlusion_maps.hpp>
#include <homcull/scene.hpp>
#include <homcull/world_triangles.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

enum class OccludeeShape : std::uint8_t {
    box,         // the world box alone
    rectangles,  // each triangle's screen rectangle at its nearest depth, through the maps and their depth test
    samples,     // the triangles sample by sample against the buffer's masked depth (OcclusionBuffer::test_triangles)
    automatic,   // samples with the masked depth test, rectangles with the others
};

struct SceneCullerConfig {
    Resolution display{1280, 720};
    // Buffer pixels; 0 x 0 means display / samples, whose samples are the display's pixel
    // centres. Conservative mode (maps.hole_pixels = 0) requires exactly that: a coverage
    // sample elsewhere says nothing about the display's pixel centres.
    Resolution buffer{0, 0};
    int samples = 1;
    OcclusionMapsConfig maps;  // display_width/height are taken from `display`
    // Back faces are surfaces to ground truth and to the eye: none are culled by default.
    Backface backface = Backface::none;
    // Occludee shape: the world box alone, or, where the box is found visible, the object's
    // triangles (much tighter for objects whose box reaches past what hides them, at the cost
    // of transforming their vertices). Objects with more than triangle_test_limit triangles
    // keep the box's answer.
    OccludeeShape occludees = OccludeeShape::automatic;
    std::size_t triangle_test_limit = 20000;
    // With the samples shape: give the buffer a per-sample depth (BufferConfig::sample_depth),
    // the occluders' depth without the layers' loss at silhouettes. Off: the layers alone,
    // rendering faster.
    bool sample_depth = true;
};

// The shape `automatic` stands for with this configuration.
OccludeeShape resolved_occludee_shape(const SceneCullerConfig& config);

struct SceneCullTimings {
    double render_ms = 0.0;  // occluder triangles into the buffer
    double maps_ms = 0.0;    // opacity pyramid, depth maps, depth estimation buffer
    double test_ms = 0.0;    // every object's box (and triangles)
};

// How many objects each overlap-test exit decided (indexed by OverlapExit).
struct OverlapExitCounts {
    std::uint64_t count[7] = {};
};

class SceneCuller {
public:
    // `occluders`: object ids whose triangles are rendered (gathered once, here).
    // Throws homcull::Error on an invalid configuration.
    SceneCuller(const Scene& scene, const std::vector<std::uint32_t>& occluders, const SceneCullerConfig& config);

    // answers[id] for every object of the scene (objects without geometry are view-culled).
    // overlap_exit is the box test's; an object its triangles found hidden reports level of
    // visibility 0.
    void cull(const Camera& camera, std::vector<OccludeeAnswer>& answers, const ParallelFor& parallel = {});

    const SceneCullerConfig& config() const { return config_; }
    const OcclusionBuffer& buffer() const { return buffer_; }
    const OcclusionMaps& maps() const { return maps_; }
    const SceneCullTimings& timings() const { return timings_; }
    const OverlapExitCounts& overlap_exits() const { return exits_; }
    std::size_t occluder_objects() const { return occluder_ids_.size(); }
    std::size_t occluder_triangles() const { return occluders_.triangle_count(); }

private:
    const Scene* scene_;
    SceneCullerConfig config_;
    std::vector<std::uint32_t> occluder_ids_;
    WorldTriangles occluders_;
    OcclusionBuffer buffer_;
    OcclusionMaps maps_;
    SceneCullTimings timings_;
    OverlapExitCounts exits_;
    // Occludee triangles in world space (transformed as ground truth transforms them) for the
    // samples test: object id -> its first vertex in occludee_positions_, or kNotGathered.
    static constexpr std::size_t kNotGathered = ~std::size_t(0);
    std::vector<float> occludee_positions_;
    std::vector<std::size_t> occludee_first_vertex_;
    bool triangle_rectangles_hidden(const Object& object, const glm::dmat4& clip_from_world) const;
    bool triangle_samples_hidden(std::size_t id, const std::array<float, 16>& clip_from_world, float& level_of_visibility) const;
};

// The buffer configuration a SceneCullerConfig asks for (resolved buffer size), for callers
// that want to check it before building a culler. Throws homcull::Error when invalid.
BufferConfig scene_buffer_config(const SceneCullerConfig& config, float near_w);

}  // namespace homcull
