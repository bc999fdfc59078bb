// GJK's intersection test (no distances) between hull(eye + back) and front; see
// hull_occlusion.hpp. The simplex cases follow the usual Voronoi-region reduction; each face
// normal is oriented away from the simplex's other vertex, so no winding has to be kept.
#include "hull_occlusion.hpp"

#include <cmath>

namespace homcull::sort_detail {

namespace {

// The index of the hull's point farthest along world direction d.
std::uint32_t support_index(const PlacedHull& hull, const glm::dvec3& d) {
    const glm::mat4& m = hull.transform;
    // The model-space direction: max over p of d . (M p + t) is max over p of (M^T d) . p.
    const glm::vec3 w(d);
    const float dx = w.x * m[0][0] + w.y * m[0][1] + w.z * m[0][2];
    const float dy = w.x * m[1][0] + w.y * m[1][1] + w.z * m[1][2];
    const float dz = w.x * m[2][0] + w.y * m[2][1] + w.z * m[2][2];
    return hull.scan(hull.x, hull.y, hull.z, hull.count, dx, dy, dz);
}

// The world point of the hull's point i.
glm::dvec3 world_point(const PlacedHull& hull, std::uint32_t i) {
    return glm::dvec3(hull.transform * glm::vec4(hull.x[i], hull.y[i], hull.z[i], 1.0f));
}

}  // namespace

glm::dvec3 support_point(const PlacedHull& hull, const glm::dvec3& d) { return world_point(hull, support_index(hull, d)); }

namespace {

// A point of the Minkowski difference hull(back, plus the eye when given) - front, whose
// containing the origin means the two sets meet, with the points it was made from.
struct DifferencePoint {
    glm::dvec3 at{0.0};
    std::uint32_t back = 0, front = 0;  // back's is GjkHint::kEye for the eye
};

struct Difference {
    const PlacedHull& front;
    const PlacedHull& back;
    const glm::dvec3* eye;
    GjkWork* work;

    // The difference's support point along d.
    DifferencePoint operator()(const glm::dvec3& d) const {
        DifferencePoint p;
        p.back = support_index(back, d);
        p.front = support_index(front, -d);
        if (work) work->scans += 2;
        glm::dvec3 a = world_point(back, p.back);
        if (eye && glm::dot(*eye, d) > glm::dot(a, d)) a = *eye, p.back = GjkHint::kEye;
        p.at = a - world_point(front, p.front);
        return p;
    }
    // The point made from these two again, where the objects stand now.
    glm::dvec3 rebuild(std::uint32_t back_index, std::uint32_t front_index) const {
        const glm::dvec3 a = back_index == GjkHint::kEye ? *eye : world_point(back, back_index);
        return a - world_point(front, front_index);
    }
};

// The simplex (newest point last) and the next direction to search. Each function keeps the
// smallest sub-simplex whose region holds the origin; true when the origin is inside it (or on
// it, or the simplex collapsed: the caller then answers "may occlude").
struct Simplex {
    DifferencePoint p[4];
    int n = 0;
};

bool line_case(Simplex& s, glm::dvec3& d) {
    const DifferencePoint A = s.p[1];
    const glm::dvec3 a = A.at, b = s.p[0].at;
    const glm::dvec3 ab = b - a, ao = -a;
    if (glm::dot(ab, ao) > 0.0) {
        d = glm::cross(glm::cross(ab, ao), ab);
        if (glm::dot(d, d) == 0.0) return true;  // the origin lies on the segment
    } else {
        s.p[0] = A, s.n = 1;
        d = ao;
    }
    return false;
}

bool triangle_case(Simplex& s, glm::dvec3& d) {
    const DifferencePoint A = s.p[2], B = s.p[1], C = s.p[0];
    const glm::dvec3 a = A.at, b = B.at, c = C.at;
    const glm::dvec3 ab = b - a, ac = c - a, ao = -a;
    const glm::dvec3 abc = glm::cross(ab, ac);
    if (glm::dot(abc, abc) == 0.0) return true;  // collapsed: give up, conservatively
    if (glm::dot(glm::cross(abc, ac), ao) > 0.0) {
        if (glm::dot(ac, ao) > 0.0) {
            s.p[0] = C, s.p[1] = A, s.n = 2;
            d = glm::cross(glm::cross(ac, ao), ac);
            return glm::dot(d, d) == 0.0;
        }
        s.p[0] = B, s.p[1] = A, s.n = 2;
        return line_case(s, d);
    }
    if (glm::dot(glm::cross(ab, abc), ao) > 0.0) {
        s.p[0] = B, s.p[1] = A, s.n = 2;
        return line_case(s, d);
    }
    const double side = glm::dot(abc, ao);
    if (side == 0.0) return true;  // the origin lies in the triangle
    d = side > 0.0 ? abc : -abc;
    return false;
}

bool tetrahedron_case(Simplex& s, glm::dvec3& d) {
    const DifferencePoint A = s.p[3];
    const glm::dvec3 a = A.at, ao = -a;
    // The three faces through the newest point, each with the vertex it leaves out.
    const int faces[3][3] = {{2, 1, 0}, {1, 0, 2}, {0, 2, 1}};
    for (const auto& f : faces) {
        const DifferencePoint X = s.p[f[0]], Y = s.p[f[1]];
        const glm::dvec3 x = X.at, y = Y.at, opposite = s.p[f[2]].at;
        glm::dvec3 normal = glm::cross(x - a, y - a);
        if (glm::dot(normal, normal) == 0.0) return true;  // flat tetrahedron
        if (glm::dot(normal, opposite - a) > 0.0) normal = -normal;
        if (glm::dot(normal, ao) > 0.0) {
            s.p[0] = Y, s.p[1] = X, s.p[2] = A, s.n = 3;
            return triangle_case(s, d);
        }
    }
    return true;  // below all three faces (the fourth was settled before): inside
}

// Whether the hint's tetrahedron, its corners rebuilt where the objects stand now, still holds
// the origin: on the inner side (or on the plane) of each of its four faces. These are points
// of this frame's difference, so holding the origin proves the sets meet, as GJK's own last
// step would.
bool hint_encloses_origin(const Difference& support, const GjkHint& hint) {
    glm::dvec3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = support.rebuild(hint.back[k], hint.front[k]);
    const int faces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};  // three corners, the one left out
    for (const auto& f : faces) {
        const glm::dvec3 a = p[f[0]];
        glm::dvec3 normal = glm::cross(p[f[1]] - a, p[f[2]] - a);
        const double towards_inside = glm::dot(normal, p[f[3]] - a);
        if (towards_inside == 0.0 || !std::isfinite(towards_inside)) return false;  // flat
        if (towards_inside > 0.0) normal = -normal;  // outwards
        if (glm::dot(normal, -a) > 0.0) return false;
    }
    return true;
}

// GJK's loop: apart with the certificate's direction, or meeting, or not settled. With a hint,
// it first tries the hint's tetrahedron and starts from the hint's direction, and it leaves
// its own last state there for the next frame.
HullContact gjk(const Difference& support, double margin, const glm::dvec3& start, GjkHint* hint) {
    glm::dvec3 d = start;
    if (hint) {
        if (hint->corners == 4 && hint_encloses_origin(support, *hint)) return {Contact::meet, {}};
        hint->corners = 0;
        if (glm::dot(hint->direction, hint->direction) > 0.0f) d = glm::dvec3(hint->direction);
    }
    if (!(glm::dot(d, d) > 0.0)) d = glm::dvec3(1.0, 0.0, 0.0);
    Simplex s;
    const auto leave = [&](Contact contact) {
        if (hint) {
            hint->direction = glm::vec3(d);
            if (contact == Contact::meet && s.n == 4) {
                hint->corners = 4;
                for (int k = 0; k < 4; ++k) hint->back[k] = s.p[k].back, hint->front[k] = s.p[k].front;
            }
        }
        return HullContact{contact, contact == Contact::apart ? d : glm::dvec3(0.0)};
    };
    for (int iteration = 0; iteration < 48; ++iteration) {
        if (support.work) ++support.work->iterations;
        const double length = glm::length(d);
        if (!(length > 0.0)) return leave(Contact::meet);
        d /= length;
        const DifferencePoint a = support(d);
        // The certificate: nothing of the difference reaches past -margin along d, so a plane
        // normal to d parts the two sets with more than `margin` between them.
        if (glm::dot(a.at, d) < -margin) return leave(Contact::apart);
        s.p[s.n++] = a;
        bool inside = false;
        switch (s.n) {
            case 1: d = -a.at; break;
            case 2: inside = line_case(s, d); break;
            case 3: inside = triangle_case(s, d); break;
            default: inside = tetrahedron_case(s, d); break;
        }
        if (inside) return leave(Contact::meet);
    }
    return leave(Contact::unsettled);
}

}  // namespace

bool may_occlude(const PlacedHull& front, const PlacedHull& back, const glm::dvec3& eye, double margin, const glm::dvec3& start,
                 GjkHint* hint, GjkWork* work) {
    // "No" only with the certificate; meeting or not settled: it may.
    return gjk(Difference{front, back, &eye, work}, margin, start, hint).contact != Contact::apart;
}

HullContact hull_contact(const PlacedHull& first, const PlacedHull& second, double margin, const glm::dvec3& start) {
    // The difference first - second is below zero along d when first lies below second.
    return gjk(Difference{second, first, nullptr, nullptr}, margin, start, nullptr);
}

}  // namespace homcull::sort_detail
