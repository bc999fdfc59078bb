#pragma once
// Occluder triangles as the rasterizer takes them (TriangleInput), how it draws them, and what
// it counts (RasterStats). The occlusion buffer (occlusion_buffer.hpp) renders them.
#include <array>
#include <cstddef>
#include <cstdint>

namespace homcull {

enum class Backface : std::uint8_t {
    none,  // rasterize both sides
    cw,    // cull triangles that are clockwise in NDC (y up): counter-clockwise front faces
    ccw,   // cull counter-clockwise triangles
};

struct RasterStats {
    std::uint64_t triangles_in = 0;       // submitted
    std::uint64_t invalid = 0;            // non-finite vertex or index out of range
    std::uint64_t outside = 0;            // entirely outside the frustum
    std::uint64_t near_clipped = 0;       // crossed the near plane (or the guard band)
    // Reaching more than 2^28 times its nearest w (or near_w) in x, y or w: clipping it in double
    // would lose the precision conservative coverage needs, so it is skipped (as an occluder, safely).
    std::uint64_t too_large = 0;
    std::uint64_t backface_culled = 0;
    std::uint64_t degenerate = 0;         // zero area after projection
    std::uint64_t rasterized = 0;         // triangles (after clipping) that reached the buffer
    // (triangle, subtile) pairs where the triangle covers a sample and is in front of the
    // subtile's reference layer, so that it enters the subtile's layers. Triangles hidden
    // behind the reference layer are skipped before their samples are found: counting only
    // the subtiles they update keeps the figure the same with or without that skip, and
    // with any number of threads.
    std::uint64_t subtiles_updated = 0;
    // Clustered input (ClusteredInput) only. Clusters whose box is outside the view or covers
    // no sample centre; then, per band of subtile rows a cluster's box reaches, the clusters
    // skipped there (their box behind the band's reference layer) and those drawn. The
    // triangle counts above count a cluster's triangles once per band that draws it.
    std::uint64_t clusters_outside = 0;
    std::uint64_t cluster_bands_hidden = 0;
    std::uint64_t cluster_bands_drawn = 0;

    RasterStats& operator+=(const RasterStats& o) {
        triangles_in += o.triangles_in, invalid += o.invalid, outside += o.outside, near_clipped += o.near_clipped;
        too_large += o.too_large, backface_culled += o.backface_culled, degenerate += o.degenerate, rasterized += o.rasterized;
        subtiles_updated += o.subtiles_updated;
        clusters_outside += o.clusters_outside, cluster_bands_hidden += o.cluster_bands_hidden, cluster_bands_drawn += o.cluster_bands_drawn;
        return *this;
    }
    bool operator==(const RasterStats& o) const {
        return triangles_in == o.triangles_in && invalid == o.invalid && outside == o.outside && near_clipped == o.near_clipped &&
               too_large == o.too_large && backface_culled == o.backface_culled && degenerate == o.degenerate &&
               rasterized == o.rasterized && subtiles_updated == o.subtiles_updated && clusters_outside == o.clusters_outside &&
               cluster_bands_hidden == o.cluster_bands_hidden && cluster_bands_drawn == o.cluster_bands_drawn;
    }
};

// The order one render call draws its triangles in. The buffer keeps what is drawn first best:
// a triangle behind what is already drawn is skipped before its rows are computed, and a
// layer of near samples takes the farther triangles behind it rather than being dropped for
// them. nearest_first (the default) therefore sorts each call's triangles by their nearest
// vertex before drawing them (raster/draw_order.hpp): on workload S1, whose triangles come in
// random depth order, that renders faster and culls more (docs/occlusion-buffer.md, "Draw
// order"). It costs a pass over the vertices and a sorted copy of the indices (or, without
// indices, of the positions; on one thread, for positions of 4 floats, a sorted list of the
// triangles' numbers instead), kept by the buffer. as_given draws the triangles as they come,
// for inputs already sorted. The order, and so the bits, are the same on every instruction
// set and with any job system. nearest_first takes at most 2^32 - 1 triangles per call.
enum class DrawOrder : std::uint8_t { nearest_first, as_given };

// Vertex input as engines have it: positions (x, y, z, or x, y, z, w as floats) every
// `stride` bytes, and triangles as 16- or 32-bit index triples (or none: consecutive
// vertices). Positions are multiplied by model_to_clip as (x, y, z, 1) or (x, y, z, w).
struct TriangleInput {
    const void* positions = nullptr;
    int position_components = 3;       // 3 or 4
    std::size_t position_stride = 12;  // bytes between consecutive positions
    // Positions must hold vertex_count vertices: with indices and at most two vertices per
    // triangle, render() transforms every one of them once (not only those indexed).
    std::size_t vertex_count = 0;
    const void* indices = nullptr;     // nullptr: triangles are vertices 3k, 3k+1, 3k+2
    bool indices_16bit = false;
    std::size_t triangle_count = 0;
    std::array<float, 16> model_to_clip{};  // column-major, as glm and OpenGL
    Backface backface = Backface::cw;
    // Optional, one byte per triangle: bit k set when the edge from its vertex k to vertex
    // k + 1 is shared with another triangle of the occluders (compute_shared_edges finds them
    // once per mesh), with edge_apexes saying which. A silhouette edge keeps a coverage margin,
    // which keeps coverage conservative; an edge whose neighbour lies on the other side of it
    // in this view needs none (a sample on it is covered by one of the two), so meshes leave no
    // cracks. Whether the neighbour lies on the other side is decided per render from its
    // third vertex (docs/occlusion-buffer.md, "Why it never hides what is visible"): at a view
    // silhouette of a closed mesh, next to a degenerate neighbour or one whose facing cannot be
    // told, the edge keeps its margin. Without flags every edge keeps its margin.
    const std::uint8_t* shared_edges = nullptr;
    // Required with shared_edges, three per triangle: the vertex number (as the indices number
    // vertices, or 3t + k without indices) of the third vertex of the neighbour across edge k,
    // read only where the edge's bit is set. A number not below vertex_count drops the flag.
    const std::uint32_t* edge_apexes = nullptr;
    DrawOrder order = DrawOrder::nearest_first;
    // model_to_clip is an orthographic projection (BufferConfig::orthographic): it must match
    // the buffer's (render and test_triangles throw homcull::Error otherwise).
    bool orthographic = false;
    // The positions are clip-space points already, (x, y, z, w): 4 packed floats a vertex
    // (position_components 4, position_stride 16), no indices and no shared-edge flags;
    // model_to_clip is not read (the identity). The form of an occluder soup an engine has
    // transformed itself, and of workload S1. Drawn nearest first, such a soup is sorted as
    // notes of the reference cells each triangle covers, and the render drops most hidden
    // triangles without reading them (docs/occlusion-buffer.md, "Reference cells"); the bits
    // are those of the same triangles drawn with the identity matrix. render() and
    // test_triangles throw homcull::Error for a clip_space input that breaks these rules or is
    // orthographic.
    bool clip_space = false;
};

// Finds the edges that two triangles of a mesh share (the same two positions, bit for bit,
// in opposite order as consistently wound neighbours have them) and writes the
// TriangleInput::shared_edges bits and, for each shared edge, the apex of one neighbour across
// it (TriangleInput::edge_apexes: 3 per triangle; kNoApex where the edge is not shared).
// `indices` may be null (vertices 3k, 3k+1, 3k+2). Meant for load time: it allocates 36 bytes per
// triangle, and a table numbering the positions: up to 80 bytes per vertex from the lowest
// index the triangles use to the highest, or per index when that range is longer. Throws homcull::Error when positions
// or an output are missing, the stride is below one position (12 bytes), or there are 2^32 / 3
// triangles or more.
constexpr std::uint32_t kNoApex = 0xFFFFFFFFu;
void compute_shared_edges(const float* positions, std::size_t position_stride, std::size_t vertex_count,
                          const std::uint32_t* indices, std::size_t triangle_count, std::uint8_t* shared_edges,
                          std::uint32_t* edge_apexes);

}  // namespace homcull
