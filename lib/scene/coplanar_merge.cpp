#include "scene/coplanar_merge.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <vector>

#include <meshoptimizer.h>

namespace homcull::detail {
namespace {

// 128-bit integers (GCC and Clang): the products below reach 2^126 at most.
__extension__ typedef __int128 Int;
__extension__ typedef unsigned __int128 UInt;
using Point = std::array<std::int64_t, 3>;
using Vector = std::array<Int, 3>;

// Coordinates need at most this many bits on the grid: differences take 41, cross products 83,
// a plane's offset (a reduced normal times a point, summed) 126.
constexpr int kGridBits = 40;

Vector cross(const Point& o, const Point& a, const Point& b) {
    const Int ax = a[0] - o[0], ay = a[1] - o[1], az = a[2] - o[2];
    const Int bx = b[0] - o[0], by = b[1] - o[1], bz = b[2] - o[2];
    return {ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx};
}

Int absolute(Int v) { return v < 0 ? -v : v; }

constexpr Int k63 = Int(1) << 63;

// a / d for d > 0 that divides a: in 64 bits when both fit (a 128-bit division is a library
// call, several times slower, and most normals fit).
Int divide(Int a, Int d) {
    if (a > -k63 && a < k63 && d < k63) return Int(std::int64_t(a) / std::int64_t(d));
    return a / d;
}

Int gcd(Int a, Int b) {
    a = absolute(a), b = absolute(b);
    if (a < k63 && b < k63) return Int(std::gcd(std::uint64_t(a), std::uint64_t(b)));
    while (b != 0) {
        const Int r = a % b;
        a = b, b = r;
    }
    return a;
}

// A triangle's plane, exactly: its normal divided by the normal's gcd (so that every triangle of
// the plane facing the same way has the same one) and the offset of its points along it.
struct Plane {
    Vector normal;
    Int offset;
    bool operator==(const Plane& o) const { return normal == o.normal && offset == o.offset; }
};

struct PlaneHash {
    std::size_t operator()(const Plane& p) const {
        std::uint64_t h = 0;
        for (const Int x : {p.normal[0], p.normal[1], p.normal[2], p.offset}) {
            // Both halves of each 128-bit value, mixed (splitmix64's multiplier).
            h = (h ^ std::uint64_t(x) ^ std::uint64_t(UInt(x) >> 64)) * 0x9E3779B97F4A7C15ull;
            h ^= h >> 29;
        }
        return std::size_t(h);
    }
};

// The positions on the finest binary grid that holds them all: each coordinate an integer
// multiple of 2^lowest (the lowest set bit among them). False when that takes more than
// kGridBits bits, or a coordinate is not finite.
bool integer_grid(const float* positions, const std::vector<std::uint32_t>& vertices, std::vector<Point>& grid) {
    int lowest = 1 << 20;
    float largest = 0.0f;
    for (const std::uint32_t v : vertices)
        for (int axis = 0; axis < 3; ++axis) {
            const float x = positions[3 * std::size_t(v) + std::size_t(axis)];
            if (!std::isfinite(x)) return false;
            if (x == 0.0f) continue;
            int exponent = 0;
            const float mantissa = std::frexp(x, &exponent);  // |mantissa| in [0.5, 1): x = mantissa 2^exponent
            std::uint32_t bits = std::uint32_t(std::abs(std::ldexp(double(mantissa), 24)));  // 24 significant bits, exact
            int trailing = 0;
            while ((bits & 1u) == 0) bits >>= 1, ++trailing;
            lowest = std::min(lowest, exponent - 24 + trailing);
            largest = std::max(largest, std::abs(x));
        }
    if (largest == 0.0f) lowest = 0;
    if (std::ldexp(double(largest), -lowest) >= std::ldexp(1.0, kGridBits)) return false;
    grid.resize(vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i)
        for (int axis = 0; axis < 3; ++axis)
            grid[i][std::size_t(axis)] = std::int64_t(std::ldexp(double(positions[3 * std::size_t(vertices[i]) + std::size_t(axis)]), -lowest));
    return true;
}

struct Merger {
    std::vector<Point> point;                      // per welded vertex
    std::vector<std::array<std::uint32_t, 3>> tri;  // welded vertices
    std::vector<int> plane_of;                      // per triangle: its plane, -1 degenerate
    std::vector<Plane> planes;
    std::vector<int> axis_of_plane;                 // the normal's largest component: the sign test's
    std::vector<bool> alive;
    std::vector<std::vector<std::uint32_t>> around;  // per vertex: the triangles that used it (some dead)
    std::vector<std::uint8_t> kept;                  // per vertex: it stays (merge_coplanar_triangles' keep)

    // The normal's component on the plane's axis of a triangle made of a, b, c: the sign of its
    // facing against the plane's (the three lie in the plane, so the normals are parallel).
    Int facing(int plane, std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
        return cross(point[a], point[b], point[c])[std::size_t(axis_of_plane[std::size_t(plane)])];
    }

    // One plane's triangles around v as a fan: next[a] = c for each triangle (v, a, c).
    struct Fan {
        int plane;
        std::vector<std::uint32_t> triangles;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;  // (a, c)
        std::uint32_t first = 0, last = 0;  // a boundary fan's ends: c0 (no triangle before), a0 (no triangle after)
        bool boundary = false;
    };

    // Scratch reused from vertex to vertex (the first sweep visits every vertex).
    std::vector<Fan> fan_room;
    std::vector<std::uint32_t> starts, ends, targets;

    // A fan of one triangle cannot lose v (v would have to lie between the triangle's other
    // two corners), so v can go only when each plane around it holds two of its triangles or
    // more. Most vertices of curved meshes fail this: checked before any fan is built.
    bool every_plane_twice(std::uint32_t v) const {
        const auto& ts = around[v];
        for (std::size_t i = 0; i < ts.size(); ++i) {
            if (!alive[ts[i]]) continue;
            const int plane = plane_of[ts[i]];
            if (plane < 0) return false;
            bool twice = false;
            for (std::size_t j = 0; j < ts.size() && !twice; ++j) twice = j != i && alive[ts[j]] && plane_of[ts[j]] == plane;
            if (!twice) return false;
        }
        return true;
    }

    // Collapses v into a neighbour when it can; then `moved_to` is that neighbour.
    bool collapse(std::uint32_t v, std::uint32_t& moved_to) {
        if (kept[v]) return false;
        if (!every_plane_twice(v)) return false;
        std::size_t fan_count = 0;
        for (const std::uint32_t t : around[v]) {
            if (!alive[t]) continue;
            const int plane = plane_of[t];
            if (plane < 0) return false;
            auto fan = std::find_if(fan_room.begin(), fan_room.begin() + std::ptrdiff_t(fan_count), [&](const Fan& f) { return f.plane == plane; });
            if (fan == fan_room.begin() + std::ptrdiff_t(fan_count)) {
                if (fan_count == fan_room.size()) fan_room.emplace_back();
                fan = fan_room.begin() + std::ptrdiff_t(fan_count++);
                fan->plane = plane, fan->boundary = false;
                fan->triangles.clear(), fan->edges.clear();
            }
            const auto& x = tri[t];
            const int i = x[0] == v ? 0 : x[1] == v ? 1 : 2;
            fan->triangles.push_back(t);
            fan->edges.push_back({x[std::size_t((i + 1) % 3)], x[std::size_t((i + 2) % 3)]});
        }
        if (fan_count == 0) return false;
        const auto fans_begin = fan_room.begin(), fans_end = fan_room.begin() + std::ptrdiff_t(fan_count);
        for (auto f = fans_begin; f != fans_end; ++f) {
            // A manifold fan: each neighbour starts at most one edge and ends at most one.
            starts.clear(), ends.clear();
            for (const auto& edge : f->edges) {
                const std::uint32_t a = edge.first, c = edge.second;  // named, not bound: the lambdas below take them
                if (std::count_if(f->edges.begin(), f->edges.end(), [&](const auto& e) { return e.first == a; }) != 1) return false;
                if (std::count_if(f->edges.begin(), f->edges.end(), [&](const auto& e) { return e.second == c; }) != 1) return false;
                if (std::none_of(f->edges.begin(), f->edges.end(), [&](const auto& e) { return e.second == a; })) starts.push_back(a);
                if (std::none_of(f->edges.begin(), f->edges.end(), [&](const auto& e) { return e.first == c; })) ends.push_back(c);
            }
            if (starts.size() > 1) return false;
            f->boundary = starts.size() == 1;
            if (!f->boundary) continue;
            // v on the region's boundary, from ends[0] (before it) to starts[0] (after it):
            // it goes only when it lies on the straight segment between them.
            f->first = ends[0], f->last = starts[0];
            const Vector turn = cross(point[v], point[f->last], point[f->first]);
            if (turn[0] != 0 || turn[1] != 0 || turn[2] != 0) return false;
            Int along = 0;
            for (std::size_t k = 0; k < 3; ++k) along += Int(point[v][k] - point[f->first][k]) * Int(point[f->last][k] - point[v][k]);
            if (along <= 0) return false;
        }
        // An interior vertex (one closed fan) may go to any neighbour; a boundary one only along
        // its line, to the same neighbour on every plane (no crack where two planes meet).
        targets.clear();
        if (fan_count == 1 && !fans_begin->boundary) {
            for (const auto& e : fans_begin->edges) targets.push_back(e.first);
        } else {
            for (auto f = fans_begin; f != fans_end; ++f)
                if (!f->boundary) return false;
            for (const std::uint32_t u : {fans_begin->first, fans_begin->last})
                if (std::all_of(fans_begin, fans_end, [&](const Fan& f) { return f.first == u || f.last == u; })) targets.push_back(u);
        }
        for (const std::uint32_t u : targets) {
            // Every triangle that keeps its area, re-made with u for v, must face as its plane.
            bool valid = true;
            for (auto f = fans_begin; f != fans_end; ++f) {
                const Int sign = planes[std::size_t(f->plane)].normal[std::size_t(axis_of_plane[std::size_t(f->plane)])];
                for (const auto& [a, c] : f->edges) {
                    if (a == u || c == u) continue;
                    const Int n = facing(f->plane, u, a, c);
                    if (n == 0 || (n > 0) != (sign > 0)) valid = false;
                }
            }
            if (!valid) continue;
            for (auto f = fans_begin; f != fans_end; ++f)
                for (const std::uint32_t t : f->triangles) {
                    auto& x = tri[t];
                    if (x[0] == u || x[1] == u || x[2] == u) {
                        alive[t] = false;
                        continue;
                    }
                    for (std::uint32_t& w : x)
                        if (w == v) w = u;
                    around[u].push_back(t);
                }
            around[v].clear();
            moved_to = u;
            return true;
        }
        return false;
    }
};

}  // namespace

std::size_t merge_coplanar_triangles(const float* positions, std::uint32_t* triangles, std::size_t triangle_count, const std::uint8_t* keep) {
    if (triangle_count < 2) return triangle_count;
    // Weld equal positions by their bytes (+0 and -0 apart, which only keeps a vertex), with
    // meshoptimizer's vertex remap as the project welds elsewhere (closed_occludees.cpp): each
    // welded vertex keeps the first index that had its position, for the output.
    Merger m;
    const auto [lowest_index, highest_index] = std::minmax_element(triangles, triangles + 3 * triangle_count);
    const std::uint32_t base = *lowest_index;
    std::vector<unsigned> local(3 * triangle_count);
    for (std::size_t i = 0; i < local.size(); ++i) local[i] = triangles[i] - base;
    std::vector<unsigned> remap(std::size_t(*highest_index - base) + 1);
    const std::size_t unique = meshopt_generateVertexRemap(remap.data(), local.data(), local.size(), positions + 3 * std::size_t(base),
                                                           remap.size(), 3 * sizeof(float));
    std::vector<std::uint32_t> original(unique, ~0u);  // per welded vertex
    std::vector<std::uint32_t> welded_of(3 * triangle_count);
    for (std::size_t i = 0; i < local.size(); ++i) {
        const unsigned w = remap[local[i]];
        welded_of[i] = w;
        if (original[w] == ~0u) original[w] = triangles[i];
    }
    if (!integer_grid(positions, original, m.point)) return triangle_count;
    m.kept.assign(original.size(), 0);
    if (keep)
        for (std::size_t i = 0; i < 3 * triangle_count; ++i) m.kept[welded_of[i]] |= keep[triangles[i]];

    m.tri.resize(triangle_count);
    m.plane_of.assign(triangle_count, -1);
    m.alive.assign(triangle_count, true);
    m.around.resize(original.size());
    {
        std::vector<std::uint32_t> uses(original.size(), 0);  // each list allocated once
        for (const std::uint32_t w : welded_of) ++uses[w];
        for (std::size_t v = 0; v < uses.size(); ++v) m.around[v].reserve(uses[v]);
    }
    // Triangles around the same vertex lie in one plane exactly when their normals point the
    // same way (the plane through the vertex is then the same). Most triangles of curved meshes
    // have no such neighbour: a test in double (rounding far inside its tolerance, so it can
    // only let extra pairs through) finds the triangles that may, and only those get their
    // exact plane; the others keep -1, which stops a collapse of their vertices just as a plane
    // no other triangle there shares would (every_plane_twice), and which no collapse changes:
    // a triangle that had no coplanar neighbour never gets one.
    std::vector<std::array<double, 3>> direction(triangle_count);
    std::vector<std::uint8_t> may_share(triangle_count, 0);
    for (std::size_t t = 0; t < triangle_count; ++t) {
        auto& x = m.tri[t];
        for (std::size_t k = 0; k < 3; ++k) x[k] = welded_of[3 * t + k];
        for (const std::uint32_t v : x) m.around[v].push_back(std::uint32_t(t));
        const Vector n = cross(m.point[x[0]], m.point[x[1]], m.point[x[2]]);
        for (std::size_t k = 0; k < 3; ++k) direction[t][k] = double(n[k]);
    }
    for (const auto& ts : m.around)
        for (std::size_t i = 0; i < ts.size(); ++i)
            for (std::size_t j = i + 1; j < ts.size(); ++j) {
                const auto& a = direction[ts[i]];
                const auto& b = direction[ts[j]];
                const double c0 = a[1] * b[2] - a[2] * b[1], c1 = a[2] * b[0] - a[0] * b[2], c2 = a[0] * b[1] - a[1] * b[0];
                const double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2], bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
                const double along = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                if (along > 0 && c0 * c0 + c1 * c1 + c2 * c2 <= 1e-20 * aa * bb) may_share[ts[i]] = may_share[ts[j]] = 1;
            }
    std::unordered_map<Plane, int, PlaneHash> plane_ids;
    for (std::size_t t = 0; t < triangle_count; ++t) {
        const auto& x = m.tri[t];
        if (!may_share[t] || x[0] == x[1] || x[1] == x[2] || x[0] == x[2]) continue;
        Vector n = cross(m.point[x[0]], m.point[x[1]], m.point[x[2]]);
        const Int g = gcd(gcd(n[0], n[1]), n[2]);
        if (g == 0) continue;  // no area
        if (g != 1)
            for (Int& c : n) c = divide(c, g);
        Int offset = 0;
        for (std::size_t k = 0; k < 3; ++k) offset += n[k] * m.point[x[0]][k];
        const auto [at, added] = plane_ids.insert({Plane{n, offset}, int(m.planes.size())});
        if (added) {
            m.planes.push_back(at->first);
            std::size_t axis = 0;
            for (std::size_t k = 1; k < 3; ++k)
                if (absolute(n[k]) > absolute(n[axis])) axis = k;
            m.axis_of_plane.push_back(int(axis));
        }
        m.plane_of[t] = at->second;
    }
    // Every vertex once, then again those around a collapse (their fans changed).
    std::vector<std::uint32_t> pending(original.size());
    std::vector<std::uint8_t> is_pending(original.size(), 1);
    for (std::size_t v = 0; v < original.size(); ++v) pending[v] = std::uint32_t(original.size() - 1 - v);
    while (!pending.empty()) {
        const std::uint32_t v = pending.back();
        pending.pop_back();
        is_pending[v] = 0;
        std::uint32_t u = 0;
        if (!m.collapse(v, u)) continue;
        for (const std::uint32_t t : m.around[u]) {
            if (!m.alive[t]) continue;
            for (const std::uint32_t w : m.tri[t])
                if (!is_pending[w]) is_pending[w] = 1, pending.push_back(w);
        }
    }
    std::size_t kept = 0;
    for (std::size_t t = 0; t < triangle_count; ++t) {
        if (!m.alive[t]) continue;
        for (std::size_t k = 0; k < 3; ++k) triangles[3 * kept + k] = original[m.tri[t][k]];
        ++kept;
    }
    return kept;
}

}  // namespace homcull::detail
