// The incremental visibility sort (Snyder and Lengyel's IVS) as Tarjan's strongly connected
// components over the "is hidden by" relation, found lazily.
//
// Tarjan's algorithm (Tarjan, "Depth-first search and linear graph algorithms", SIAM J.
// Computing, 1972) emits a component only after every component it reaches. Following edges
// from an object to the objects that may hide it, it therefore emits the occluders' layers
// before the layer they hide: front to back, with each cycle as one layer. Three things keep
// the tests few:
// - an object already emitted is never tested again: its layer is in front of whatever is
//   being visited, whether or not it hides it (Tarjan ignores edges to finished components);
// - an edge to an object still on the stack is tested only when it could lower the visited
//   object's low link (inside a large cycle most cannot);
// - the roots are visited in the last frame's order. Where that order still holds, each
//   object finds none of its occluders unvisited, and the order comes out unchanged, after
//   one test per pair that the extents cannot settle and the order does not already cover.
// Each test (may_hide) runs the cheap rejections first and GJK last; pairs of objects that
// have not moved answer from what an earlier frame learned (pair_cache.hpp).
// The components do not depend on the order of the visit, so a sort from scratch (nearest
// first) gives the same layers; the order within what the occlusions leave free may differ.
#include <homcull/error.hpp>
#include <homcull/visibility_sort.hpp>

#include "common/isa_choice.hpp"
#include "extent_tree.hpp"
#include "hull_occlusion.hpp"
#include "image_outline.hpp"
#include "pair_cache.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

namespace homcull {

using sort_detail::Extent;
using sort_detail::ExtentTree;
using sort_detail::PlacedHull;

namespace {

constexpr std::size_t kMaxPlanes = 16;

double now_ms() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A face normal of an object's bounding box (unit; cross products of the half axes, so that
// sheared boxes are right too), with the box's centre and reach along it and the eye's place.
struct BoxFace {
    glm::vec3 normal{0.0f};
    float at_centre = 0, reach = 0, at_eye = 0;
    bool usable = false;  // false for a flat box's degenerate normal
};

// An object as this frame sees it: its bounding sphere about the eye.
struct Placed {
    glm::vec3 centre{0.0f};
    float radius = 0;
    glm::vec3 direction{0.0f};  // unit, from the eye to the centre
    float sine = 1, cosine = 0;  // of the sphere's half-angle seen from the eye
    float farthest = 0;         // distance from the eye to the sphere's far side
    glm::vec3 half_axis[3];     // the bounding box about `centre`: centre +- each half axis
    glm::vec3 core[2];          // the core segment's ends (two hull points), in the world
    BoxFace faces[3];
    bool surrounds_eye = false;
    bool active = false;
};

// Whether a plane normal to one of a few axes parts front's bounding box from the hull of the
// eye and back's bounding box, with more than `margin` between them: then front cannot hide
// any of back. The axes: the boxes' face normals (cross products of their half axes, so that
// sheared boxes are right too) and the line between their centres. Cheap, and it settles most
// pairs where front lies behind back; GJK on the hulls takes the rest.
bool parted_on_box_axes(const Placed& front, const Placed& back, const glm::vec3& eye, float margin) {
    // Along n: whether back's box, spanning at_b +- reach_b, and the eye lie wholly on one side
    // of front's box, spanning at_f +- reach_f, with more than the margin between.
    const auto parted = [&](float at_f, float reach_f, float at_b, float reach_b, float at_eye, float gap) {
        const float low_b = std::min(at_b - reach_b, at_eye), high_b = std::max(at_b + reach_b, at_eye);
        return high_b < at_f - reach_f - gap || at_f + reach_f < low_b - gap;
    };
    const auto reach = [](const glm::vec3& n, const glm::vec3 (&h)[3]) {
        return std::abs(glm::dot(n, h[0])) + std::abs(glm::dot(n, h[1])) + std::abs(glm::dot(n, h[2]));
    };
    // The face normals, with what place() worked out along them for their own box and the eye.
    for (int k = 0; k < 3; ++k) {
        const BoxFace& face = front.faces[k];
        if (face.usable && parted(face.at_centre, face.reach, glm::dot(face.normal, back.centre), reach(face.normal, back.half_axis),
                                  face.at_eye, margin))
            return true;
    }
    for (int k = 0; k < 3; ++k) {
        const BoxFace& face = back.faces[k];
        if (face.usable && parted(glm::dot(face.normal, front.centre), reach(face.normal, front.half_axis), face.at_centre, face.reach,
                                  face.at_eye, margin))
            return true;
    }
    const glm::vec3 n = front.centre - back.centre;
    const float length = glm::length(n);
    if (!(length > 0.0f)) return false;
    return parted(glm::dot(n, front.centre), reach(n, front.half_axis), glm::dot(n, back.centre), reach(n, back.half_axis), glm::dot(n, eye),
                  margin * length);
}

// Six times the signed volume of the tetrahedron abcd: positive when d lies on the side of the
// plane abc that cross(b - a, c - a) points to.
double orientation(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
    return glm::dot(glm::cross(b - a, c - a), d - a);
}

// A proof, without GJK, that front may hide back: front's core segment (inside front's hull)
// crosses the triangle of the eye and back's core segment (inside the hull of the eye and
// back's hull), so the two sets meet. Long thin objects whose images cross pass it. The
// segment crosses the triangle when its ends lie on either side of the triangle's plane and
// the line through it passes inside the triangle's three edges (the signs of the signed
// volumes; Ericson, "Real-Time Collision Detection", 2005, section 5.3.4). Flat cases
// (collinear or coplanar points) give no proof and go to GJK.
bool cores_cross(const Placed& front, const Placed& back, const glm::dvec3& eye) {
    const glm::dvec3 p(front.core[0]), q(front.core[1]), b0(back.core[0]), b1(back.core[1]);
    const double at_p = orientation(eye, b0, b1, p), at_q = orientation(eye, b0, b1, q);
    if ((at_p > 0.0 && at_q > 0.0) || (at_p < 0.0 && at_q < 0.0) || (at_p == 0.0 && at_q == 0.0)) return false;
    const double s0 = orientation(p, q, eye, b0), s1 = orientation(p, q, b0, b1), s2 = orientation(p, q, b1, eye);
    const bool all_up = s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0, all_down = s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0;
    return (all_up || all_down) && !(s0 == 0.0 && s1 == 0.0 && s2 == 0.0);
}

enum Visit : std::uint8_t { kUnvisited = 0, kOnStack = 1, kDone = 2 };

}  // namespace

struct VisibilitySorter::State {
    // Shapes: hull points as structure of arrays, and each shape's bounding sphere.
    detail::Vector<float> x, y, z;
    detail::Vector<std::uint32_t> shape_first, shape_count;
    detail::Vector<glm::vec3> shape_centre;  // of the points' bounding box
    detail::Vector<glm::vec3> shape_half;    // half the box's sides
    detail::Vector<float> shape_radius;      // of the bounding sphere about the box's centre
    detail::Vector<glm::vec3> shape_core;    // the lowest and highest point along each model axis (6 a shape)
    detail::Vector<std::uint32_t> object_shape;

    // What stands still: each object's last transform, how often it moved, whether it moved
    // this frame, and what the hull tests learned about pairs of still objects.
    detail::Vector<glm::mat4> last_transform;
    detail::Vector<std::uint32_t> moves;
    detail::Vector<std::uint8_t> still;
    bool seen_a_frame = false;
    sort_detail::PairCache contacts;
    // Where each ordered pair's last full test left GJK (hull_occlusion.hpp), moving or not.
    struct HintEntry {
        std::uint64_t key = 0;
        sort_detail::GjkHint hint;
    };
    sort_detail::PairSlots<HintEntry> hints;

    // This frame.
    detail::Vector<Placed> placed;
    detail::Vector<Extent> extents;
    detail::Vector<std::uint32_t> in_tree, surrounding, roots;
    // Image extents: objects wholly in front of the eye along this frame's view axis have a box
    // in the image plane of that axis (their bounding boxes' corners, projected); the others
    // ("wide") keep their direction boxes only.
    detail::Vector<Extent> image;
    detail::Vector<std::uint8_t> projected;
    detail::Vector<sort_detail::ImageOutline> outlines;  // of the projected objects
    detail::Vector<std::uint32_t> in_image_tree, wide;
    ExtentTree image_tree;
    ExtentTree tree;
    sort_detail::SupportScan scan = &sort_detail::support_scan_reference;
    const glm::mat4* transforms = nullptr;
    glm::dvec3 eye{0.0};
    double margin_scale = 0;

    // Tarjan's state and stacks.
    detail::Vector<std::uint32_t> index, low;
    std::uint32_t next_index = 0;
    detail::Vector<std::uint8_t> visit;
    detail::Vector<std::uint32_t> component_stack;
    struct Frame {
        std::uint32_t object;
        std::uint32_t begin, next, end;  // its candidates: [begin, end) of `candidates`
    };
    detail::Vector<Frame> frames;
    detail::Vector<std::uint32_t> candidates;
    detail::Vector<std::uint32_t> unvisited_candidates;  // order_candidates' scratch

    detail::Vector<std::uint32_t> last_order;
    bool has_last_order = false;
    VisibilitySort result;


    PlacedHull hull(std::uint32_t object) const {
        const std::uint32_t s = object_shape[object];
        PlacedHull h;
        h.x = x.data() + shape_first[s];
        h.y = y.data() + shape_first[s];
        h.z = z.data() + shape_first[s];
        h.count = shape_count[s];
        h.transform = transforms[object];
        h.scan = scan;
        return h;
    }

    void place(const SortFrame& frame);
    void project(const glm::vec3& from);  // the eye, in float
    const sort_detail::PairContact& learn_contact(std::uint32_t a, std::uint32_t b, double margin);
    void collect_candidates(std::uint32_t object);
    void order_candidates(std::uint32_t object, std::uint32_t begin);
    bool may_hide(std::uint32_t front, std::uint32_t back);
    void visit_from(std::uint32_t root);
    void emit_component(std::uint32_t root);
};

namespace {

// The largest factor by which the transform's linear part stretches a length: the square root
// of a bound on the largest eigenvalue of M^T M (Gershgorin's, exact for rotations with a
// uniform scale).
float stretch_bound(const glm::mat4& m) {
    const glm::mat3 a(m);
    const glm::mat3 g = glm::transpose(a) * a;
    float bound = 0;
    for (int r = 0; r < 3; ++r) bound = std::max(bound, std::abs(g[0][r]) + std::abs(g[1][r]) + std::abs(g[2][r]));
    return std::sqrt(bound);
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct DistanceRange {
    float nearest, farthest;
};

// Distances from the eye to an object's bounding box (centre +- the three half axes): the
// farthest corner exactly, and for the nearest a lower bound, the largest distance to one of
// the box's three slabs (the box is their intersection). Tighter than the bounding sphere's
// for long thin objects.
DistanceRange box_distances(const glm::vec3 (&axis)[3], const BoxFace (&faces)[3], const glm::vec3& centre, const glm::vec3& eye) {
    const glm::vec3 to_eye = eye - centre;
    DistanceRange r{0.0f, 0.0f};
    float farthest_squared = 0.0f;  // one square root for the eight (it keeps the order)
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 c = ((corner & 1) ? axis[0] : -axis[0]) + ((corner & 2) ? axis[1] : -axis[1]) + ((corner & 4) ? axis[2] : -axis[2]);
        farthest_squared = std::max(farthest_squared, glm::dot(c - to_eye, c - to_eye));
    }
    r.farthest = std::sqrt(farthest_squared);
    for (const BoxFace& face : faces)
        if (face.usable) r.nearest = std::max(r.nearest, std::abs(face.at_eye - face.at_centre) - face.reach);
    return r;
}

}  // namespace

void VisibilitySorter::State::place(const SortFrame& frame) {
    const std::size_t n = object_shape.size();
    const glm::vec3 e(frame.eye);
    in_tree.clear();
    surrounding.clear();
    double scale = glm::length(glm::dvec3(e));
    for (std::uint32_t i = 0; i < n; ++i) {
        Placed& p = placed[i];
        p.active = false;
        projected[i] = 0;  // until project() gives it an image box
        const glm::mat4& m = frame.transforms[i];
        still[i] = seen_a_frame && std::memcmp(&m, &last_transform[i], sizeof(glm::mat4)) == 0;
        if (!still[i]) ++moves[i], last_transform[i] = m;
        const std::uint32_t s = object_shape[i];
        p.centre = glm::vec3(m * glm::vec4(shape_centre[s], 1.0f));
        // Grown by a part in 10^6 (and of the centre's distance from the origin): the float
        // roundings of the centre and of every transformed point.
        p.radius = shape_radius[s] * stretch_bound(m) * (1.0f + 1e-6f) + 1e-6f * glm::length(p.centre);
        if (!finite(p.centre) || !std::isfinite(p.radius)) continue;
        bool outside = false;
        for (std::size_t k = 0; k < frame.plane_count && !outside; ++k) {
            const glm::vec4& plane = frame.planes[k];
            outside = glm::dot(glm::vec3(plane), p.centre) + plane.w < -p.radius * glm::length(glm::vec3(plane));
        }
        if (outside) continue;
        p.active = true;
        scale = std::max(scale, double(glm::length(p.centre) + p.radius));
        const glm::vec3 offset = p.centre - e;
        const float distance = glm::length(offset);
        const float tolerance = 1e-6f * (glm::length(p.centre) + glm::length(e) + p.radius);
        const glm::vec3& half = shape_half[s];
        float core_length_squared = -1.0f;
        for (int axis = 0; axis < 3; ++axis) {
            const glm::vec3 lowest_end = glm::vec3(m * glm::vec4(shape_core[6 * s + 2 * axis], 1.0f));
            const glm::vec3 highest_end = glm::vec3(m * glm::vec4(shape_core[6 * s + 2 * axis + 1], 1.0f));
            const float length_squared = glm::dot(highest_end - lowest_end, highest_end - lowest_end);
            if (length_squared > core_length_squared) core_length_squared = length_squared, p.core[0] = lowest_end, p.core[1] = highest_end;
        }
        p.half_axis[0] = glm::vec3(m[0]) * half.x, p.half_axis[1] = glm::vec3(m[1]) * half.y, p.half_axis[2] = glm::vec3(m[2]) * half.z;
        for (int k = 0; k < 3; ++k) {
            BoxFace& face = p.faces[k];
            const glm::vec3 normal = glm::cross(p.half_axis[(k + 1) % 3], p.half_axis[(k + 2) % 3]);
            const float normal_length = glm::length(normal);
            face.usable = normal_length > 0.0f && std::isfinite(normal_length);
            if (!face.usable) continue;
            face.normal = normal / normal_length;
            face.at_centre = glm::dot(face.normal, p.centre);
            face.reach = std::abs(glm::dot(face.normal, p.half_axis[0])) + std::abs(glm::dot(face.normal, p.half_axis[1])) +
                         std::abs(glm::dot(face.normal, p.half_axis[2]));
            face.at_eye = glm::dot(face.normal, e);
        }
        const DistanceRange to_box = box_distances(p.half_axis, p.faces, p.centre, e);
        p.farthest = std::min(distance + p.radius, to_box.farthest + tolerance);
        Extent& box = extents[i];
        p.surrounds_eye = !(distance > p.radius);
        if (p.surrounds_eye) {
            for (int k = 0; k < 3; ++k) box.lo[k] = -1.0f, box.hi[k] = 1.0f;
            box.nearest = 0.0f;
            p.sine = 1.0f, p.cosine = 0.0f;
            surrounding.push_back(i);
            continue;
        }
        p.direction = offset / distance;
        p.sine = p.radius / distance;
        p.cosine = std::sqrt(std::max(0.0f, 1.0f - p.sine * p.sine));
        box.nearest = std::max(distance - p.radius, to_box.nearest - tolerance);
        // The range of each direction component over the sphere's cone: cos(angle to the axis
        // -+ the half-angle), reaching +-1 when the cone holds the axis. Widened by 1e-6
        // against rounding.
        for (int k = 0; k < 3; ++k) {
            const float c = p.direction[k];
            const float across = std::sqrt(std::max(0.0f, 1.0f - c * c)) * p.sine;
            box.lo[k] = c <= -p.cosine ? -1.0f : c * p.cosine - across - 1e-6f;
            box.hi[k] = c >= p.cosine ? 1.0f : c * p.cosine + across + 1e-6f;
        }
        in_tree.push_back(i);
    }
    margin_scale = scale;
    seen_a_frame = true;
    project(e);
}

// The view axis: the mean of the directions to the objects. Each object whose bounding box lies
// wholly within 75 degrees of it gets the box of its corners' central projection onto the plane
// one unit along it (a convex set in front of the eye projects into the hull of its corners'
// projections): two objects can overlap on screen only if those boxes overlap. Much tighter
// than the direction boxes of the spheres for long, thin objects.
void VisibilitySorter::State::project(const glm::vec3& from) {
    in_image_tree.clear();
    wide.clear();
    glm::vec3 sum(0.0f);
    for (std::uint32_t i : in_tree) sum += placed[i].direction;
    const float length = glm::length(sum);
    if (!(length > 1e-3f * float(in_tree.size()))) {
        wide.assign(in_tree.begin(), in_tree.end());
        for (std::uint32_t i : in_tree) projected[i] = 0;
        return;
    }
    const glm::vec3 axis = sum / length;
    const glm::vec3 helper = std::abs(axis.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::vec3 right = glm::normalize(glm::cross(axis, helper)), up = glm::cross(right, axis);
    const float slack = float(1e-6 * margin_scale);
    for (std::uint32_t i : in_tree) {
        const Placed& p = placed[i];
        const glm::vec3* h = p.half_axis;
        const glm::vec3 centre = p.centre - from;
        Extent box;
        box.lo[0] = box.lo[1] = 3.4e38f, box.hi[0] = box.hi[1] = -3.4e38f;
        box.lo[2] = box.hi[2] = 0.0f;
        box.nearest = extents[i].nearest;
        bool in_front = true;
        float least_depth = 3.4e38f;
        glm::vec2 corners[8];
        for (int corner = 0; corner < 8 && in_front; ++corner) {
            const glm::vec3 c = centre + ((corner & 1) ? h[0] : -h[0]) + ((corner & 2) ? h[1] : -h[1]) + ((corner & 4) ? h[2] : -h[2]);
            const float depth = glm::dot(c, axis);
            in_front = depth > 0.25f * glm::length(c) + 2.0f * slack;
            const float across = glm::dot(c, right) / depth, upward = glm::dot(c, up) / depth;
            corners[corner] = glm::vec2(across, upward);
            box.lo[0] = std::min(box.lo[0], across), box.hi[0] = std::max(box.hi[0], across);
            box.lo[1] = std::min(box.lo[1], upward), box.hi[1] = std::max(box.hi[1], upward);
            least_depth = std::min(least_depth, depth);
        }
        projected[i] = in_front;
        if (!in_front) {
            wide.push_back(i);
            continue;
        }
        // Widened for the roundings: a part in 10^6 of the scene's reach, seen at the nearest
        // corner's depth, and of the coordinates themselves.
        float outline_pad = 0;
        for (int k = 0; k < 2; ++k) {
            const float pad = slack / least_depth + 1e-6f * std::max(std::abs(box.lo[k]), std::abs(box.hi[k]));
            box.lo[k] -= pad, box.hi[k] += pad;
            outline_pad = std::max(outline_pad, pad);
        }
        sort_detail::ImageOutline& outline = outlines[i];
        std::copy(corners, corners + 8, outline.corners);
        outline.pad = outline_pad;
        // The longest box axis on screen: between the corners that differ in that axis only.
        int longest = 0;
        for (int k = 1; k < 3; ++k)
            if (glm::dot(h[k], h[k]) > glm::dot(h[longest], h[longest])) longest = k;
        const glm::vec2 along = corners[1 << longest] - corners[0];
        outline.across = glm::vec2(along.y, -along.x);
        image[i] = box;
        in_image_tree.push_back(i);
    }
}

// GJK on two still objects' hulls alone, kept for the frames in which neither moves.
const sort_detail::PairContact& VisibilitySorter::State::learn_contact(std::uint32_t a, std::uint32_t b, double margin) {
    ++result.stats.hull_tests;
    const PlacedHull ha = hull(a), hb = hull(b);
    const sort_detail::HullContact c =
        sort_detail::hull_contact(ha, hb, margin, glm::dvec3(placed[b].centre) - glm::dvec3(placed[a].centre));
    sort_detail::PairContact& e = contacts.slot(a, b, moves[a], moves[b]);
    e.contact = std::uint8_t(c.contact);
    if (c.contact == sort_detail::Contact::apart) {
        // Oriented from the lower id to the higher; the bounds rounded outwards to float.
        const bool a_low = a < b;
        const glm::dvec3 n = a_low ? c.direction : -c.direction;
        const PlacedHull& lower = a_low ? ha : hb;
        const PlacedHull& higher = a_low ? hb : ha;
        e.normal = glm::vec3(n);
        e.below = std::nextafter(float(glm::dot(n, sort_detail::support_point(lower, n))), 3.4e38f);
        e.above = std::nextafter(float(glm::dot(n, sort_detail::support_point(higher, -n))), -3.4e38f);
    }
    return e;
}

void VisibilitySorter::State::collect_candidates(std::uint32_t object) {
    const Placed& p = placed[object];
    if (projected[object]) {
        image_tree.query(image[object], p.farthest, candidates);
        const Extent& directions = extents[object];
        for (std::uint32_t w : wide)
            if (extents[w].nearest < p.farthest && sort_detail::boxes_overlap(extents[w], directions)) candidates.push_back(w);
    } else {
        tree.query(extents[object], p.farthest, candidates);  // every object's direction box
    }
    for (std::uint32_t w : surrounding) candidates.push_back(w);
}

// The order in which an object's candidates [begin, end of `candidates`) are tested. Those
// already emitted go (they are never tested); those on the stack come first, lowest index
// first, then the unvisited ones as collected. Only an edge to an on-stack object with an
// index below the visited object's low link is tested, so the first such edge found with the
// lowest index skips the tests of all the others: inside the shared scenes' large cycles this
// halves the tests (crytek_sponza walk: 1,309 -> 536 GJK runs a frame). The layers do not
// depend on the order.
void VisibilitySorter::State::order_candidates(std::uint32_t object, std::uint32_t begin) {
    std::uint32_t on_stack_end = begin;
    unvisited_candidates.clear();
    for (std::size_t k = begin; k < candidates.size(); ++k) {
        const std::uint32_t w = candidates[k];
        if (w == object || visit[w] == kDone) continue;
        if (visit[w] == kOnStack) candidates[on_stack_end++] = w;
        else unvisited_candidates.push_back(w);
    }
    std::sort(candidates.begin() + begin, candidates.begin() + on_stack_end,
              [&](std::uint32_t a, std::uint32_t b) { return index[a] < index[b]; });
    candidates.resize(on_stack_end);
    candidates.insert(candidates.end(), unvisited_candidates.begin(), unvisited_candidates.end());
}

// Whether `front` may hide part of `back`: the spheres' cones, the boxes' axes, what is known of
// a still pair, then GJK on the hulls.
bool VisibilitySorter::State::may_hide(std::uint32_t front, std::uint32_t back) {
    const Placed& f = placed[front];
    const Placed& b = placed[back];
    if (!f.surrounds_eye && !b.surrounds_eye) {
        // The cones about the eye must overlap: angle between axes <= the half-angles' sum.
        const float cos_sum = f.cosine * b.cosine - f.sine * b.sine;
        if (glm::dot(f.direction, b.direction) < cos_sum - 1e-6f) return false;
    }
    // A part in 10^6 of the scene's reach from the origin: the float roundings of the points
    // here and of the ground truth's (which places vertices in double, then rounds).
    const double margin = 1e-6 * margin_scale;
    if (parted_on_box_axes(f, b, glm::vec3(eye), float(margin))) return false;
    // Objects side by side on screen: a line parts their outlines (image_outline.hpp).
    if (projected[front] && projected[back] && sort_detail::outlines_apart(outlines[front], outlines[back])) return false;
    if (still[front] && still[back]) {
        const sort_detail::PairContact* known = contacts.find(front, back, moves[front], moves[back]);
        if (!known) known = &learn_contact(front, back, margin);
        if (known->contact == std::uint8_t(sort_detail::Contact::meet)) {
            ++result.stats.remembered;
            return true;  // hulls that meet: each may hide the other from anywhere
        }
        if (known->contact == std::uint8_t(sort_detail::Contact::apart)) {
            // The hull of the eye and back stays on back's side of the plane between them, more
            // than this frame's margin from front (the margin may have grown since the pair was
            // learned, so back's own bound is checked against it too).
            const float side = glm::dot(known->normal, glm::vec3(eye));
            const float room = float(margin);
            if (back < front ? std::max(side, known->below) < known->above - room
                             : std::min(side, known->above) > known->below + room) {
                ++result.stats.remembered;
                return false;
            }
        }
    }
    if (cores_cross(f, b, eye)) {
        ++result.stats.core_crossings;
        return true;
    }
    // Where GJK starts without a hint: normal to both core segments (the axis that parts two
    // thin sticks lying one behind the other), towards front; else from back's centre to front's.
    glm::dvec3 start = glm::dvec3(f.centre) - glm::dvec3(b.centre);
    const glm::dvec3 across_cores = glm::cross(glm::dvec3(f.core[1] - f.core[0]), glm::dvec3(b.core[1] - b.core[0]));
    const double side = glm::dot(across_cores, start);
    if (side != 0.0 && std::isfinite(side)) start = side > 0.0 ? across_cores : -across_cores;
    // No GJK on the bounding boxes first: of the pairs the tests above leave, it settled about
    // a quarter (200 toothpicks: 80 of 287 a frame) and cost more than it saved.
    ++result.stats.hull_tests;
    const std::uint64_t key = hints.key_of(front, back);
    HintEntry& entry = hints[key];
    if (entry.key != key) entry = HintEntry{key, {}};
    sort_detail::GjkWork work;
    const bool may = sort_detail::may_occlude(hull(front), hull(back), eye, margin, start, &entry.hint, &work);
    result.stats.gjk_iterations += work.iterations;
    result.stats.support_scans += work.scans;
    return may;
}

void VisibilitySorter::State::emit_component(std::uint32_t root) {
    const std::uint32_t first = std::uint32_t(result.order.size());
    std::uint32_t w;
    do {
        w = component_stack.back();
        component_stack.pop_back();
        visit[w] = kDone;
        result.order.push_back(w);
    } while (w != root);
    const std::uint32_t count = std::uint32_t(result.order.size()) - first;
    std::sort(result.order.begin() + first, result.order.end());
    result.layers.push_back({first, count});
}

// Tarjan's algorithm from one root, without recursion: each frame walks the candidates
// collected when its object was first visited.
void VisibilitySorter::State::visit_from(std::uint32_t root) {
    auto enter = [&](std::uint32_t v) {
        index[v] = low[v] = next_index++;
        visit[v] = kOnStack;
        component_stack.push_back(v);
        const std::uint32_t begin = std::uint32_t(candidates.size());
        collect_candidates(v);
        result.stats.candidates += candidates.size() - begin;
        order_candidates(v, begin);
        frames.push_back({v, begin, begin, std::uint32_t(candidates.size())});
    };
    enter(root);
    while (!frames.empty()) {
        Frame& f = frames.back();
        const std::uint32_t v = f.object;
        if (f.next < f.end) {
            const std::uint32_t w = candidates[f.next++];
            if (w == v || visit[w] == kDone) continue;
            // An edge to an object on the stack matters only when it lowers v's low link: in a
            // large cycle most of them cannot, and their tests are skipped.
            if (visit[w] == kOnStack && index[w] >= low[v]) continue;
            if (!may_hide(w, v)) continue;
            result.pairs.push_back({w, v});
            if (visit[w] == kUnvisited) {
                enter(w);  // f is not used after this
            } else {
                low[v] = std::min(low[v], index[w]);
            }
            continue;
        }
        // Every candidate seen (the children's were appended after v's and are gone): v roots
        // a component when nothing still on the stack below it is reachable from it.
        candidates.resize(f.begin);
        frames.pop_back();
        if (low[v] == index[v]) emit_component(v);
        if (!frames.empty()) {
            const std::uint32_t parent = frames.back().object;
            low[parent] = std::min(low[parent], low[v]);
        }
    }
}

const VisibilitySort& VisibilitySorter::sort(const SortFrame& frame) {
    State& s = *state_;
    if (frame.transforms == nullptr && !s.object_shape.empty()) throw Error("VisibilitySorter::sort: null transforms");
    if (frame.plane_count > kMaxPlanes)
        throw Error("VisibilitySorter::sort: " + std::to_string(frame.plane_count) + " planes, at most " +
                    std::to_string(kMaxPlanes));
    if (frame.plane_count > 0 && frame.planes == nullptr) throw Error("VisibilitySorter::sort: null planes");
    const double start = now_ms();
    VisibilitySort& r = s.result;
    r.order.clear();
    r.layers.clear();
    r.pairs.clear();
    r.stats = VisibilitySortStats{};
    s.transforms = frame.transforms;
    s.eye = glm::dvec3(frame.eye);

    s.place(frame);
    const std::size_t n = s.object_shape.size();
    if (!finite(frame.eye)) {
        for (Placed& p : s.placed) p.active = false;
        s.in_tree.clear(), s.surrounding.clear(), s.in_image_tree.clear(), s.wide.clear();
    }
    const double placed_at = now_ms();
    s.image_tree.build(s.image, s.in_image_tree);
    // The direction tree answers the queries of the objects without an image box (the wide
    // ones and those around the eye) only.
    if (!s.wide.empty() || !s.surrounding.empty()) s.tree.build(s.extents, s.in_tree);
    else s.tree.build(s.extents, s.wide);
    const double tree_at = now_ms();

    // The roots: the last order's objects that are still here, then the others nearest first.
    s.roots.clear();
    for (std::uint32_t i = 0; i < n; ++i) s.visit[i] = kUnvisited;
    if (frame.incremental && s.has_last_order) {
        for (std::uint32_t i : s.last_order)
            if (i < n && s.placed[i].active && s.visit[i] == kUnvisited) s.roots.push_back(i), s.visit[i] = kDone;
    }
    const std::size_t kept = s.roots.size();
    for (std::uint32_t i = 0; i < n; ++i)
        if (s.placed[i].active && s.visit[i] == kUnvisited) s.roots.push_back(i);
    std::sort(s.roots.begin() + kept, s.roots.end(), [&](std::uint32_t a, std::uint32_t b) {
        const float na = s.extents[a].nearest, nb = s.extents[b].nearest;
        return na < nb || (na == nb && a < b);
    });
    for (std::uint32_t i : s.roots) s.visit[i] = kUnvisited;

    s.next_index = 0;
    for (std::uint32_t root : s.roots)
        if (s.visit[root] == kUnvisited) s.visit_from(root);

    r.stats.kept_last_order = s.has_last_order && frame.incremental && r.order == s.last_order;
    s.last_order.assign(r.order.begin(), r.order.end());
    s.has_last_order = true;

    r.stats.sorted = std::uint32_t(r.order.size());
    r.stats.left_out = std::uint32_t(n - r.order.size());
    r.stats.layers = std::uint32_t(r.layers.size());
    for (const SortLayer& layer : r.layers) {
        if (layer.count < 2) continue;
        ++r.stats.cycles;
        r.stats.objects_in_cycles += layer.count;
        r.stats.largest_cycle = std::max(r.stats.largest_cycle, layer.count);
    }
    r.stats.occlusions = r.pairs.size();
    const double end = now_ms();
    r.stats.extents_ms = placed_at - start;
    r.stats.tree_ms = tree_at - placed_at;
    r.stats.order_ms = end - tree_at;
    r.stats.total_ms = end - start;
    return r;
}

VisibilitySorter::VisibilitySorter(const HullPoints* shapes, std::size_t shape_count, const std::uint32_t* object_shapes,
                                   std::size_t object_count)
    : state_(detail::make_hooked<State>()) {
    if ((shape_count > 0 && !shapes) || (object_count > 0 && !object_shapes)) throw Error("VisibilitySorter: null shapes or objects");
    if (object_count >= std::size_t(UINT32_MAX)) throw Error("VisibilitySorter: more than 2^32 - 1 objects");
    State& s = *state_;
    // The instruction set of buffers made now (select_isa's default): the same answers on all.
    const detail::IsaChoice isa = detail::default_isa_choice();
    s.scan = sort_detail::support_scan_for(isa);
    s.tree.use(sort_detail::extent_scan_for(isa));
    s.image_tree.use(sort_detail::extent_scan_for(isa));
    for (std::size_t k = 0; k < shape_count; ++k) {
        const glm::vec3* points = shapes[k].points;
        const std::size_t count = shapes[k].count;
        if (count == 0 || !points) throw Error("VisibilitySorter: shape " + std::to_string(k) + " has no points");
        glm::vec3 lo(points[0]), hi(points[0]);
        for (std::size_t i = 0; i < count; ++i) {
            if (!finite(points[i]))
                throw Error("VisibilitySorter: shape " + std::to_string(k) + ", point " + std::to_string(i) + " is not finite");
            lo = glm::min(lo, points[i]), hi = glm::max(hi, points[i]);
        }
        const glm::vec3 centre = 0.5f * (lo + hi);
        float radius = 0;
        s.shape_first.push_back(std::uint32_t(s.x.size()));
        s.shape_count.push_back(std::uint32_t(count));
        for (std::size_t i = 0; i < count; ++i) {
            const glm::vec3& p = points[i];
            radius = std::max(radius, glm::length(p - centre));
            s.x.push_back(p.x), s.y.push_back(p.y), s.z.push_back(p.z);
        }
        s.shape_centre.push_back(centre);
        // The core segments: along each model axis, the lowest and the highest point. Any two
        // of the points would be correct (the segment between them lies in the hull); each
        // frame takes the one the object's transform makes longest.
        for (int axis = 0; axis < 3; ++axis) {
            std::size_t lowest = 0, highest = 0;
            for (std::size_t i = 1; i < count; ++i) {
                if (points[i][axis] < points[lowest][axis]) lowest = i;
                if (points[i][axis] > points[highest][axis]) highest = i;
            }
            s.shape_core.push_back(points[lowest]);
            s.shape_core.push_back(points[highest]);
        }
        s.shape_half.push_back(0.5f * (hi - lo));
        s.shape_radius.push_back(radius * (1.0f + 1e-6f));
    }
    for (std::size_t i = 0; i < object_count; ++i) {
        if (object_shapes[i] >= shape_count)
            throw Error("VisibilitySorter: object " + std::to_string(i) + " names shape " + std::to_string(object_shapes[i]) +
                        ", but there are " + std::to_string(shape_count));
    }
    s.object_shape.assign(object_shapes, object_shapes + object_count);
    s.last_transform.resize(object_count);
    s.moves.resize(object_count);
    s.still.resize(object_count);
    s.contacts.reset(object_count);
    // Four slots an object: a frame tests a pair or two per object (200 toothpicks: 280 pairs),
    // and a table that stays in the caches costs less than the collisions a larger one avoids.
    s.hints.reset(object_count, 4);
    s.placed.resize(object_count);
    s.image.resize(object_count);
    s.projected.resize(object_count);
    s.outlines.resize(object_count);
    s.extents.resize(object_count);
    s.index.resize(object_count);
    s.low.resize(object_count);
    s.visit.resize(object_count);
}

namespace {

detail::Vector<HullPoints> views_of(const std::vector<std::vector<glm::vec3>>& shapes) {
    detail::Vector<HullPoints> views;
    for (const auto& shape : shapes) views.push_back({shape.data(), shape.size()});
    return views;
}

}  // namespace

VisibilitySorter::VisibilitySorter(const std::vector<std::vector<glm::vec3>>& shapes, const std::vector<std::uint32_t>& object_shapes)
    : VisibilitySorter(views_of(shapes).data(), shapes.size(), object_shapes.data(), object_shapes.size()) {}

VisibilitySorter::~VisibilitySorter() = default;
VisibilitySorter::VisibilitySorter(VisibilitySorter&&) noexcept = default;
VisibilitySorter& VisibilitySorter::operator=(VisibilitySorter&&) noexcept = default;

std::size_t VisibilitySorter::object_count() const { return state_->object_shape.size(); }
std::size_t VisibilitySorter::shape_count() const { return state_->shape_first.size(); }
std::size_t VisibilitySorter::hull_point_count() const { return state_->x.size(); }
const VisibilitySort& VisibilitySorter::last() const { return state_->result; }
void VisibilitySorter::forget_order() {
    state_->has_last_order = false;
    state_->seen_a_frame = false;  // nothing counts as still in the next frame
    state_->contacts.clear();
    state_->hints.clear();
}

}  // namespace homcull
