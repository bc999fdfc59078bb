// The vertices of a point set's convex hull: quickhull (Barber, Dobkin and Huhdanpaa, "The
// quickhull algorithm for convex hulls", ACM TOMS 1996), in double.
//
// Why not Qhull itself: the hull is made when an engine loads its objects, through the C
// interface's allocator in time, and Qhull allocates with malloc and reports errors with
// longjmp across our frames. The sort only needs the hull's vertices, and any superset of
// them is still correct (the tests run on the convex hull of whatever points they are given),
// so this one falls back to every distinct point whenever its own checks find the hull broken.
#include <homcull/detail/memory.hpp>
#include <homcull/error.hpp>
#include <homcull/visibility_sort.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace homcull {
namespace {

struct HullFace {
    std::uint32_t v[3];
    glm::dvec3 normal;  // outward, unit length
    double offset;      // dot(normal, p) - offset: the signed distance of p above the face
    detail::Vector<std::uint32_t> outside;  // points above this face and no face made before
    bool alive = true;

    double distance(const glm::dvec3& p) const { return glm::dot(normal, p) - offset; }
};

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; }

class Quickhull {
public:
    Quickhull(const detail::Vector<glm::dvec3>& points, double tolerance) : p_(points), eps_(tolerance) {}

    // False when the points have no volume (no starting tetrahedron) or the hull came out
    // broken; then the caller keeps every point.
    bool run(detail::Vector<std::uint32_t>& vertices) {
        if (!start()) return false;
        for (std::size_t f = 0; f < faces_.size(); ++f) {
            // faces_ grows as points are added: every face made is visited once.
            while (faces_[f].alive && !faces_[f].outside.empty()) add_farthest(f);
        }
        return collect(vertices);
    }

    // The hull's faces as (outward unit normal, offset): dot(normal, p) <= offset inside.
    void faces(detail::Vector<glm::dvec4>& out) const {
        out.clear();
        for (const HullFace& face : faces_)
            if (face.alive) out.emplace_back(face.normal, face.offset);
    }

private:
    const detail::Vector<glm::dvec3>& p_;
    double eps_;
    detail::Vector<HullFace> faces_;
    // Directed edge -> its face (from the hooks current where the hull is made, as every
    // container here: the C interface's hulls come from the engine's allocator).
    std::unordered_map<std::uint64_t, std::uint32_t, std::hash<std::uint64_t>, std::equal_to<std::uint64_t>,
                       detail::HookAllocator<std::pair<const std::uint64_t, std::uint32_t>>>
        edge_face_;

    bool make_face(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t* made) {
        HullFace face;
        face.v[0] = a, face.v[1] = b, face.v[2] = c;
        const glm::dvec3 n = glm::cross(p_[b] - p_[a], p_[c] - p_[a]);
        const double length = glm::length(n);
        if (!(length > 0.0)) return false;
        face.normal = n / length;
        face.offset = glm::dot(face.normal, p_[a]);
        *made = std::uint32_t(faces_.size());
        for (int k = 0; k < 3; ++k) {
            if (!edge_face_.emplace(edge_key(face.v[k], face.v[(k + 1) % 3]), *made).second) return false;
        }
        faces_.push_back(std::move(face));
        return true;
    }

    void kill_face(std::uint32_t f) {
        HullFace& face = faces_[f];
        face.alive = false;
        for (int k = 0; k < 3; ++k) edge_face_.erase(edge_key(face.v[k], face.v[(k + 1) % 3]));
    }

    // The starting tetrahedron: the two points farthest apart among the axis extremes, the
    // point farthest from their line, and the point farthest from that plane.
    bool start() {
        const std::size_t n = p_.size();
        std::uint32_t extreme[6] = {0, 0, 0, 0, 0, 0};
        for (std::uint32_t i = 0; i < n; ++i) {
            for (int axis = 0; axis < 3; ++axis) {
                if (p_[i][axis] < p_[extreme[2 * axis]][axis]) extreme[2 * axis] = i;
                if (p_[i][axis] > p_[extreme[2 * axis + 1]][axis]) extreme[2 * axis + 1] = i;
            }
        }
        std::uint32_t a = 0, b = 0;
        double best = -1.0;
        for (int i = 0; i < 6; ++i)
            for (int j = i + 1; j < 6; ++j) {
                const double d = glm::length(p_[extreme[i]] - p_[extreme[j]]);
                if (d > best) best = d, a = extreme[i], b = extreme[j];
            }
        if (!(best > eps_)) return false;
        const glm::dvec3 axis = glm::normalize(p_[b] - p_[a]);
        std::uint32_t c = 0;
        best = -1.0;
        for (std::uint32_t i = 0; i < n; ++i) {
            const glm::dvec3 r = p_[i] - p_[a];
            const double d = glm::length(r - axis * glm::dot(r, axis));
            if (d > best) best = d, c = i;
        }
        if (!(best > eps_)) return false;
        const glm::dvec3 normal = glm::normalize(glm::cross(p_[b] - p_[a], p_[c] - p_[a]));
        std::uint32_t d = 0;
        best = -1.0;
        for (std::uint32_t i = 0; i < n; ++i) {
            const double h = std::abs(glm::dot(p_[i] - p_[a], normal));
            if (h > best) best = h, d = i;
        }
        if (!(best > eps_)) return false;
        // Wind the base so that d lies below it (its normal points away from d).
        if (glm::dot(p_[d] - p_[a], normal) > 0.0) std::swap(b, c);
        std::uint32_t made[4];
        if (!make_face(a, b, c, &made[0]) || !make_face(a, d, b, &made[1]) || !make_face(b, d, c, &made[2]) ||
            !make_face(c, d, a, &made[3]))
            return false;
        for (std::uint32_t i = 0; i < n; ++i) {
            if (i == a || i == b || i == c || i == d) continue;
            assign(i, made, 4);
        }
        return true;
    }

    // Puts point i on the outside list of the first face it lies above (none: it is inside).
    void assign(std::uint32_t i, const std::uint32_t* faces, std::size_t count) {
        for (std::size_t k = 0; k < count; ++k) {
            if (faces_[faces[k]].distance(p_[i]) > eps_) {
                faces_[faces[k]].outside.push_back(i);
                return;
            }
        }
    }

    // Adds face f's farthest outside point: removes every face it sees, then fans new faces
    // from it to the horizon, the edges between the faces it sees and those it does not.
    void add_farthest(std::size_t f) {
        detail::Vector<std::uint32_t>& outside = faces_[f].outside;
        std::uint32_t apex = outside[0];
        for (std::uint32_t i : outside)
            if (faces_[f].distance(p_[i]) > faces_[f].distance(p_[apex])) apex = i;
        const glm::dvec3& q = p_[apex];

        detail::Vector<std::uint32_t> seen(1, std::uint32_t(f));
        detail::Vector<char> is_seen(faces_.size(), 0);
        is_seen[f] = 1;
        for (std::size_t k = 0; k < seen.size(); ++k) {
            const HullFace& face = faces_[seen[k]];
            for (int e = 0; e < 3; ++e) {
                const auto twin = edge_face_.find(edge_key(face.v[(e + 1) % 3], face.v[e]));
                if (twin == edge_face_.end()) continue;  // cannot happen on a closed hull
                const std::uint32_t g = twin->second;
                if (!is_seen[g] && faces_[g].distance(q) > eps_) {
                    is_seen[g] = 1;
                    seen.push_back(g);
                }
            }
        }
        detail::Vector<std::pair<std::uint32_t, std::uint32_t>> horizon;
        for (std::uint32_t g : seen) {
            const HullFace& face = faces_[g];
            for (int e = 0; e < 3; ++e) {
                const auto twin = edge_face_.find(edge_key(face.v[(e + 1) % 3], face.v[e]));
                if (twin == edge_face_.end() || !is_seen[twin->second]) horizon.emplace_back(face.v[e], face.v[(e + 1) % 3]);
            }
        }
        detail::Vector<std::uint32_t> orphans;
        for (std::uint32_t g : seen) {
            for (std::uint32_t i : faces_[g].outside)
                if (i != apex) orphans.push_back(i);
            faces_[g].outside.clear();
            faces_[g].outside.shrink_to_fit();
            kill_face(g);
        }
        detail::Vector<std::uint32_t> made;
        for (const auto& [a, b] : horizon) {
            std::uint32_t g;
            if (!make_face(a, b, apex, &g)) {
                broken_ = true;
                return;
            }
            made.push_back(g);
        }
        for (std::uint32_t i : orphans) assign(i, made.data(), made.size());
    }

    // The hull's vertices, after checking that it is closed (every edge has its twin) and
    // convex at every edge (each face's far vertex across an edge lies below it).
    bool collect(detail::Vector<std::uint32_t>& vertices) {
        if (broken_) return false;
        detail::Vector<char> used(p_.size(), 0);
        for (const HullFace& face : faces_) {
            if (!face.alive) continue;
            for (int e = 0; e < 3; ++e) {
                const auto twin = edge_face_.find(edge_key(face.v[(e + 1) % 3], face.v[e]));
                if (twin == edge_face_.end()) return false;
                const HullFace& other = faces_[twin->second];
                for (std::uint32_t v : other.v)
                    if (face.distance(p_[v]) > 4.0 * eps_) return false;
                used[face.v[e]] = 1;
            }
        }
        vertices.clear();
        for (std::uint32_t i = 0; i < p_.size(); ++i)
            if (used[i]) vertices.push_back(i);
        return vertices.size() >= 4;
    }

    bool broken_ = false;
};

// Points within this of a face count as on it: a few float roundings of the largest
// coordinate, far below what the sort's tests resolve.
double hull_tolerance(const detail::Vector<glm::dvec3>& p) {
    double extent = 0.0;
    for (const glm::dvec3& q : p) extent = std::max({extent, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
    return 1e-12 + extent * 1e-9;
}

// Whether every point lies inside the faces (dot(normal, p) <= offset), and the least factor
// by which the hull, grown about `centre`, holds them all.
double needed_growth(const detail::Vector<glm::dvec4>& faces, const detail::Vector<glm::dvec3>& points, const glm::dvec3& centre) {
    double growth = 1.0;
    for (const glm::dvec4& f : faces) {
        const glm::dvec3 n(f);
        const double room = f.w - glm::dot(n, centre);
        if (!(room > 0.0)) return -1.0;  // the centre is not inside
        for (const glm::dvec3& q : points) growth = std::max(growth, glm::dot(n, q - centre) / room);
    }
    return growth;
}

// At most `limit` points whose hull holds all of `hull` (the vertices of a convex hull): that
// many of them spread by farthest-point sampling (in the box's unit coordinates, so that a thin
// object keeps points around its girth), their hull grown about its centroid until it holds
// every vertex, and checked again after the rounding to float. Empty when that fails.
detail::Vector<glm::vec3> grown_hull(detail::Vector<glm::vec3> hull, std::size_t limit) {
    // In a fixed order, so that the same points given in any order make the same hull.
    std::sort(hull.begin(), hull.end(), [](const glm::vec3& a, const glm::vec3& b) {
        return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
    });
    glm::dvec3 lo(hull[0]), hi(hull[0]);
    for (const glm::vec3& v : hull) lo = glm::min(lo, glm::dvec3(v)), hi = glm::max(hi, glm::dvec3(v));
    const glm::dvec3 middle = 0.5 * (lo + hi);
    const double largest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const glm::dvec3 half = glm::max(0.5 * (hi - lo), glm::dvec3(1e-6 * largest + 1e-30));
    detail::Vector<glm::dvec3> unit;  // the vertices in the box's unit coordinates
    unit.reserve(hull.size());
    for (const glm::vec3& v : hull) unit.push_back((glm::dvec3(v) - middle) / half);

    detail::Vector<std::uint32_t> chosen;
    detail::Vector<double> gap(unit.size(), 0.0);  // each vertex's distance to the chosen ones
    std::uint32_t next = 0;
    for (std::uint32_t i = 1; i < unit.size(); ++i)
        if (glm::dot(unit[i], unit[i]) > glm::dot(unit[next], unit[next])) next = i;
    for (std::uint32_t i = 0; i < unit.size(); ++i) gap[i] = glm::distance(unit[i], unit[next]);
    chosen.push_back(next);
    while (chosen.size() < limit) {
        next = std::uint32_t(std::max_element(gap.begin(), gap.end()) - gap.begin());
        if (!(gap[next] > 0.0)) break;
        chosen.push_back(next);
        for (std::uint32_t i = 0; i < unit.size(); ++i) gap[i] = std::min(gap[i], glm::distance(unit[i], unit[next]));
    }
    detail::Vector<glm::dvec3> base;
    for (std::uint32_t i : chosen) base.push_back(unit[i]);
    detail::Vector<std::uint32_t> base_vertices;
    Quickhull base_hull(base, hull_tolerance(base));
    if (!base_hull.run(base_vertices)) return {};
    detail::Vector<glm::dvec4> faces;
    base_hull.faces(faces);
    glm::dvec3 centre(0.0);
    for (const glm::dvec3& b : base) centre += b / double(base.size());
    double growth = needed_growth(faces, unit, centre);
    if (growth < 1.0) return {};

    // Grown a little more than needed, rounded to float, then checked in model coordinates; a
    // few more tries with more room when the rounding took a vertex out.
    detail::Vector<glm::dvec3> model(hull.begin(), hull.end());
    for (int attempt = 0; attempt < 4; ++attempt) {
        growth *= 1.0 + 1e-5 * double(1 << (4 * attempt));
        detail::Vector<glm::vec3> out;
        for (std::uint32_t i : base_vertices) out.push_back(glm::vec3(middle + half * (centre + growth * (base[i] - centre))));
        detail::Vector<glm::dvec3> placed(out.begin(), out.end());
        detail::Vector<std::uint32_t> kept;
        Quickhull check(placed, hull_tolerance(placed));
        if (!check.run(kept)) return {};
        check.faces(faces);
        glm::dvec3 inside(0.0);
        for (const glm::dvec3& q : placed) inside += q / double(placed.size());
        if (needed_growth(faces, model, inside) <= 1.0) return out;
    }
    return {};
}

}  // namespace

detail::Vector<glm::vec3> convex_hull_points(const glm::vec3* points, std::size_t count) {
    if (count > 0 && points == nullptr) throw Error("convex_hull_points: null points");
    if (count >= std::size_t(UINT32_MAX)) throw Error("convex_hull_points: more than 2^32 - 1 points");
    // Distinct points in first-seen order (exact duplicates only: near ones are the hull's job).
    detail::Vector<glm::vec3> distinct;
    distinct.reserve(count);
    {
        detail::Vector<std::uint32_t> order(count);
        for (std::uint32_t i = 0; i < count; ++i) {
            const glm::vec3& p = points[i];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw Error("convex_hull_points: point " + std::to_string(i) + " is not finite");
            order[i] = i;
        }
        auto less = [&](std::uint32_t a, std::uint32_t b) {
            const glm::vec3 &p = points[a], &q = points[b];
            if (p.x != q.x) return p.x < q.x;
            if (p.y != q.y) return p.y < q.y;
            if (p.z != q.z) return p.z < q.z;
            return a < b;
        };
        std::sort(order.begin(), order.end(), less);
        detail::Vector<char> keep(count, 0);
        for (std::size_t k = 0; k < count; ++k)
            if (k == 0 || points[order[k]] != points[order[k - 1]]) keep[order[k]] = 1;
        for (std::size_t i = 0; i < count; ++i)
            if (keep[i]) distinct.push_back(points[i]);
    }
    if (distinct.size() < 5) return distinct;

    detail::Vector<glm::dvec3> p(distinct.begin(), distinct.end());
    detail::Vector<std::uint32_t> vertices;
    if (!Quickhull(p, hull_tolerance(p)).run(vertices)) return distinct;
    detail::Vector<glm::vec3> hull;
    hull.reserve(vertices.size());
    for (std::uint32_t i : vertices) hull.push_back(distinct[i]);
    return hull;
}

detail::Vector<glm::vec3> convex_hull_points(const glm::vec3* points, std::size_t count, std::size_t max_points) {
    detail::Vector<glm::vec3> exact = convex_hull_points(points, count);
    if (max_points == 0 || exact.size() <= std::max<std::size_t>(max_points, 8)) return exact;
    detail::Vector<glm::vec3> grown = grown_hull(exact, std::max<std::size_t>(max_points, 8));
    return grown.empty() ? exact : grown;
}

}  // namespace homcull
