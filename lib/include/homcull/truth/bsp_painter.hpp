#pragma once
// An exact hidden-surface oracle for visibility sorting: a polygon-aligned BSP tree with
// splitting over a scene's triangles (Fuchs, Kedem and Naylor, "On visible surface generation
// by a priori tree structures", SIGGRAPH 1980), which gives a back-to-front painter's order of
// the polygons from any eye. Drawn in that order with the painter's algorithm at the display's
// pixel centres it must give the id image that Embree's first hits give: the check of the
// classic answer against ray casting, and of object orders against it.
//
// Polygons are convex and planar, in world space relative to the scene's anchor, in double.
// A polygon straddling a splitting plane is cut in two; one lying in it (within a tolerance
// of 1e-9 of the scene's size) stays at that node. The tree is built once; the painter's order
// costs one plane test per node. Meant for tests and tools (scenes of up to some ten thousand
// triangles: splitting can multiply them).
#include <homcull/camera.hpp>
#include <homcull/scene.hpp>

#include <cstdint>
#include <vector>

namespace homcull {

struct BspPolygon {
    std::vector<glm::dvec3> vertices;  // convex, counter-clockwise seen from the front side
    glm::dvec3 normal{0.0};            // of the plane, not normalized
    double offset = 0.0;               // plane: dot(normal, p) == offset
    std::uint32_t object = kNoObject;
};

class BspTree {
public:
    // Over every triangle of the scene's objects (degenerate ones left out). Throws
    // homcull::Error on a non-finite vertex.
    explicit BspTree(const Scene& scene);

    // The polygons from back to front as seen from `eye` (world space); those whose plane
    // holds the eye (seen edge-on) are left out.
    void painter_order(const glm::dvec3& eye, std::vector<const BspPolygon*>& order) const;

    std::size_t polygon_count() const { return polygons_.size(); }
    std::size_t split_count() const { return splits_; }
    glm::dvec3 anchor() const { return anchor_; }

private:
    struct Node {
        std::int32_t front = -1, back = -1;  // child nodes, -1: none
        std::uint32_t first = 0, count = 0;  // polygons lying in its plane, in polygons_
    };
    std::vector<BspPolygon> polygons_;  // grouped by node
    std::vector<Node> nodes_;
    std::size_t splits_ = 0;
    glm::dvec3 anchor_{0.0};
};

// The painter's algorithm at the pixel centres of `display` (rows top to bottom): each polygon
// in `order` overwrites the pixels whose ray from the eye meets it within the camera's view
// depths [near, far]. `ambiguous` (optional) marks the pixels where the answer is not certain
// either way: the ray passes within a rounding tolerance of the last polygon's edge, or that
// polygon overwrote a coplanar one of another object (coincident surfaces: a tie).
// Perspective cameras; throws homcull::Error otherwise or on an invalid camera or resolution.
std::vector<std::uint32_t> paint_ids(const std::vector<const BspPolygon*>& order, const glm::dvec3& anchor, const Camera& camera,
                                     Resolution display, std::vector<std::uint8_t>* ambiguous = nullptr);

}  // namespace homcull
