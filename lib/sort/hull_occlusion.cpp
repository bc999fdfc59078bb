// GJK's intersection test (no distances) between hull(eye + back) and front; see
// hull_occlusion.hpp. The simplex cases follow the usual Voronoi-region reduction; each face
// normal is oriented away from the simplex's other vertex, so no winding has to be kept.
#include "hull_occlusion.hpp"

#include <cmath>

namespace homcull::sort_detail {

glm::dvec3 support_point(const PlacedHull& hull, const glm::dvec3& d) {
    const glm::mat4& m = hull.transform;
    // The model-space direction: max over p of d . (M p + t) is max over p of (M^T d) . p.
    const glm::vec3 w(d);
    const float dx = w.x * m[0][0] + w.y * m[0][1] + w.z * m[0][2];
    const float dy = w.x * m[1][0] + w.y * m[1][1] + w.z * m[1][2];
    const float dz = w.x * m[2][0] + w.y * m[2][1] + w.z * m[2][2];
    const std::uint32_t best = hull.scan(hull.x, hull.y, hull.z, hull.count, dx, dy, dz);
    const glm::vec4 p = m * glm::vec4(hull.x[best], hull.y[best], hull.z[best], 1.0f);
    return glm::dvec3(p);
}

namespace {

// Support of hull(back, plus the eye when given) - front along d: the Minkowski difference
// whose containing the origin means the two sets meet.
struct Difference {
    const PlacedHull& front;
    const PlacedHull& back;
    const glm::dvec3* eye;

    glm::dvec3 operator()(const glm::dvec3& d) const {
        glm::dvec3 a = support_point(back, d);
        if (eye && glm::dot(*eye, d) > glm::dot(a, d)) a = *eye;
        return a - support_point(front, -d);
    }
};

// The simplex (newest point last) and the next direction to search. Each function keeps the
// smallest sub-simplex whose region holds the origin; true when the origin is inside it (or on
// it, or the simplex collapsed: the caller then answers "may occlude").
struct Simplex {
    glm::dvec3 p[4];
    int n = 0;
};

bool line_case(Simplex& s, glm::dvec3& d) {
    const glm::dvec3 a = s.p[1], b = s.p[0];
    const glm::dvec3 ab = b - a, ao = -a;
    if (glm::dot(ab, ao) > 0.0) {
        d = glm::cross(glm::cross(ab, ao), ab);
        if (glm::dot(d, d) == 0.0) return true;  // the origin lies on the segment
    } else {
        s.p[0] = a, s.n = 1;
        d = ao;
    }
    return false;
}

bool triangle_case(Simplex& s, glm::dvec3& d) {
    const glm::dvec3 a = s.p[2], b = s.p[1], c = s.p[0];
    const glm::dvec3 ab = b - a, ac = c - a, ao = -a;
    const glm::dvec3 abc = glm::cross(ab, ac);
    if (glm::dot(abc, abc) == 0.0) return true;  // collapsed: give up, conservatively
    if (glm::dot(glm::cross(abc, ac), ao) > 0.0) {
        if (glm::dot(ac, ao) > 0.0) {
            s.p[0] = c, s.p[1] = a, s.n = 2;
            d = glm::cross(glm::cross(ac, ao), ac);
            return glm::dot(d, d) == 0.0;
        }
        s.p[0] = b, s.p[1] = a, s.n = 2;
        return line_case(s, d);
    }
    if (glm::dot(glm::cross(ab, abc), ao) > 0.0) {
        s.p[0] = b, s.p[1] = a, s.n = 2;
        return line_case(s, d);
    }
    const double side = glm::dot(abc, ao);
    if (side == 0.0) return true;  // the origin lies in the triangle
    d = side > 0.0 ? abc : -abc;
    return false;
}

bool tetrahedron_case(Simplex& s, glm::dvec3& d) {
    const glm::dvec3 a = s.p[3], ao = -a;
    // The three faces through the newest point, each with the vertex it leaves out.
    const int faces[3][3] = {{2, 1, 0}, {1, 0, 2}, {0, 2, 1}};
    for (const auto& f : faces) {
        const glm::dvec3 x = s.p[f[0]], y = s.p[f[1]], opposite = s.p[f[2]];
        glm::dvec3 normal = glm::cross(x - a, y - a);
        if (glm::dot(normal, normal) == 0.0) return true;  // flat tetrahedron
        if (glm::dot(normal, opposite - a) > 0.0) normal = -normal;
        if (glm::dot(normal, ao) > 0.0) {
            s.p[0] = y, s.p[1] = x, s.p[2] = a, s.n = 3;
            return triangle_case(s, d);
        }
    }
    return true;  // below all three faces (the fourth was settled before): inside
}

// GJK's loop: apart with the certificate's direction, or meeting, or not settled.
HullContact gjk(const Difference& support, double margin, const glm::dvec3& start) {
    glm::dvec3 d = start;
    if (!(glm::dot(d, d) > 0.0)) d = glm::dvec3(1.0, 0.0, 0.0);
    Simplex s;
    for (int iteration = 0; iteration < 48; ++iteration) {
        const double length = glm::length(d);
        if (!(length > 0.0)) return {Contact::meet, {}};
        d /= length;
        const glm::dvec3 a = support(d);
        // The certificate: nothing of the difference reaches past -margin along d, so a plane
        // normal to d parts the two sets with more than `margin` between them.
        if (glm::dot(a, d) < -margin) return {Contact::apart, d};
        s.p[s.n++] = a;
        bool inside = false;
        switch (s.n) {
            case 1: d = -a; break;
            case 2: inside = line_case(s, d); break;
            case 3: inside = triangle_case(s, d); break;
            default: inside = tetrahedron_case(s, d); break;
        }
        if (inside) return {Contact::meet, {}};
    }
    return {Contact::unsettled, {}};
}

}  // namespace

bool may_occlude(const PlacedHull& front, const PlacedHull& back, const glm::dvec3& eye, double margin, const glm::dvec3& start) {
    // "No" only with the certificate; meeting or not settled: it may.
    return gjk(Difference{front, back, &eye}, margin, start).contact != Contact::apart;
}

HullContact hull_contact(const PlacedHull& first, const PlacedHull& second, double margin, const glm::dvec3& start) {
    // The difference first - second is below zero along d when first lies below second.
    return gjk(Difference{second, first, nullptr}, margin, start);
}

}  // namespace homcull::sort_detail
