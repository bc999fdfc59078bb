#pragma once
// Splitting "polygon soups" (models without object structure: one huge mesh) into objects the
// culler can cull one by one, so that the back of a dense model can hide behind its front
// (Zhang 1998, sec. 8.2.1: subdivide the bounding box of the polygon centres into M x N x P
// cells, recursively, until the cells are small enough; each cell's polygons are one object).
//
// Object ids change: the result lists, for each object of the input in order, either the
// object itself or its cells, so answers and ground truth computed on the result refer to the
// cells, not to the original objects.
#include <homcull/scene.hpp>

#include <cstddef>

namespace homcull {

struct SoupSubdivision {
    // Objects with more triangles than this are split; 0 = no splitting.
    std::size_t max_triangles = 0;
};

// The scene with every object of more than options.max_triangles triangles replaced by its
// cells (see soup_subdivision.cpp for the rule), finalized.
//   - Objects kept whole are copied as they are and keep sharing their meshes. So is an object
//     whose triangle centres all coincide (it cannot be split).
//   - A cell is named "<object name>#<cell path>". The path has one group of three digits per
//     level, the cell's x, y and z halves ("101.010"). Cells are listed in the order of their
//     names.
//   - A cell has the original's transform and extras, plus the extra "soup_cell" holding its
//     path (replacing any earlier "soup_cell"), and a mesh of its own. That mesh holds only the
//     vertices its triangles use, in their original order and bit-identical, so world positions
//     (transform_point) and the edges shared between cells are exactly the original's.
//   - Every triangle lands in exactly one cell, with its vertices in their original order.
//   - A mesh is dropped when every object that used it was split.
//   - Scene::source gains " (soup cells <= T triangles)" when some object was split.
// Throws homcull::Error when an object to split names a missing mesh or vertex (the result is
// finalized, which checks the rest).
Scene subdivide_polygon_soups(const Scene& scene, const SoupSubdivision& options);

}  // namespace homcull
