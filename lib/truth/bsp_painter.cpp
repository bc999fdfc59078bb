// The BSP painter's oracle (homcull/truth/bsp_painter.hpp): the tree, its back-to-front order,
// and the painter's algorithm at pixel centres.
#include <homcull/error.hpp>
#include <homcull/frustum.hpp>
#include <homcull/truth/bsp_painter.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace homcull {
namespace {

// Signed distance of p from a polygon's plane, in the plane normal's units.
double plane_side(const BspPolygon& plane, const glm::dvec3& p) { return glm::dot(plane.normal, p) - plane.offset; }

enum class Side { on, front, back, straddling };

// Where a polygon lies against a plane, its vertices within `tolerance` (scaled by the normal's
// length) of the plane counting as on it.
Side classify(const BspPolygon& plane, const BspPolygon& polygon, double tolerance) {
    const double t = tolerance * glm::length(plane.normal);
    bool front = false, back = false;
    for (const glm::dvec3& v : polygon.vertices) {
        const double s = plane_side(plane, v);
        front = front || s > t;
        back = back || s < -t;
    }
    return front && back ? Side::straddling : front ? Side::front : back ? Side::back : Side::on;
}

// Cuts a straddling polygon in two along the plane (Sutherland and Hodgman, one plane): the
// vertices on the plane go to both pieces.
void split(const BspPolygon& plane, const BspPolygon& polygon, double tolerance, BspPolygon& front, BspPolygon& back) {
    const double t = tolerance * glm::length(plane.normal);
    front = back = BspPolygon{{}, polygon.normal, polygon.offset, polygon.object};
    const std::size_t n = polygon.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 &a = polygon.vertices[i], &b = polygon.vertices[(i + 1) % n];
        const double sa = plane_side(plane, a), sb = plane_side(plane, b);
        if (sa >= -t) front.vertices.push_back(a);
        if (sa <= t) back.vertices.push_back(a);
        if ((sa > t && sb < -t) || (sa < -t && sb > t)) {
            const glm::dvec3 cut = a + (b - a) * (sa / (sa - sb));
            front.vertices.push_back(cut);
            back.vertices.push_back(cut);
        }
    }
}

// How many polygons a plane would cut, and how unevenly it would share the others.
std::size_t split_cost(const BspPolygon& plane, const std::vector<BspPolygon>& polygons, double tolerance) {
    std::size_t cuts = 0, front = 0, back = 0;
    for (const BspPolygon& p : polygons) {
        const Side s = classify(plane, p, tolerance);
        cuts += s == Side::straddling;
        front += s == Side::front;
        back += s == Side::back;
    }
    return 8 * cuts + (front > back ? front - back : back - front);
}

}  // namespace

BspTree::BspTree(const Scene& scene) {
    anchor_ = scene_anchor(scene);
    std::vector<BspPolygon> all;
    glm::dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
    for (std::uint32_t id = 0; id < scene.objects.size(); ++id) {
        const Object& object = scene.objects[id];
        const Mesh& mesh = scene.meshes[object.mesh];
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
            BspPolygon p;
            p.object = id;
            for (int k = 0; k < 3; ++k) {
                // The vertices as the ray scene places them (transform_point_from's floats).
                const glm::dvec3 v(transform_point_from(object.world, mesh.positions[mesh.indices[3 * t + std::size_t(k)]], anchor_));
                if (!std::isfinite(v.x + v.y + v.z)) throw Error("BSP tree: object " + std::to_string(id) + " has a vertex that is not finite");
                p.vertices.push_back(v);
                lo = glm::min(lo, v), hi = glm::max(hi, v);
            }
            p.normal = glm::cross(p.vertices[1] - p.vertices[0], p.vertices[2] - p.vertices[0]);
            if (!(glm::length(p.normal) > 0.0)) continue;  // degenerate: covers no pixel
            p.offset = glm::dot(p.normal, p.vertices[0]);
            all.push_back(std::move(p));
        }
    }
    if (all.empty()) return;
    const double tolerance = 1e-9 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-300});
    // Built without recursion (a tree over thousands of polygons can be as deep).
    struct Work {
        std::int32_t node;
        std::vector<BspPolygon> polygons;
    };
    std::vector<Work> work;
    nodes_.push_back({});
    work.push_back({0, std::move(all)});
    while (!work.empty()) {
        Work w = std::move(work.back());
        work.pop_back();
        // The splitter: the cheapest of up to 8 candidates spread over the list.
        std::size_t best = 0, best_cost = ~std::size_t(0);
        const std::size_t step = std::max<std::size_t>(1, w.polygons.size() / 8);
        for (std::size_t c = 0; c < w.polygons.size(); c += step) {
            const std::size_t cost = split_cost(w.polygons[c], w.polygons, tolerance);
            if (cost < best_cost) best = c, best_cost = cost;
        }
        const BspPolygon plane = w.polygons[best];
        std::vector<BspPolygon> front, back;
        nodes_[std::size_t(w.node)].first = std::uint32_t(polygons_.size());
        for (BspPolygon& p : w.polygons) {
            switch (classify(plane, p, tolerance)) {
            case Side::on: polygons_.push_back(std::move(p)); break;
            case Side::front: front.push_back(std::move(p)); break;
            case Side::back: back.push_back(std::move(p)); break;
            case Side::straddling: {
                BspPolygon f, b;
                split(plane, p, tolerance, f, b);
                ++splits_;
                if (f.vertices.size() >= 3) front.push_back(std::move(f));
                if (b.vertices.size() >= 3) back.push_back(std::move(b));
                break;
            }
            }
        }
        nodes_[std::size_t(w.node)].count = std::uint32_t(polygons_.size()) - nodes_[std::size_t(w.node)].first;
        if (!front.empty()) {
            nodes_[std::size_t(w.node)].front = std::int32_t(nodes_.size());
            nodes_.push_back({});
            work.push_back({nodes_[std::size_t(w.node)].front, std::move(front)});
        }
        if (!back.empty()) {
            nodes_[std::size_t(w.node)].back = std::int32_t(nodes_.size());
            nodes_.push_back({});
            work.push_back({nodes_[std::size_t(w.node)].back, std::move(back)});
        }
    }
}

void BspTree::painter_order(const glm::dvec3& world_eye, std::vector<const BspPolygon*>& order) const {
    order.clear();
    if (nodes_.empty()) return;
    const glm::dvec3 eye = world_eye - anchor_;
    // A node's items, last drawn first on the stack: a subtree (>= 0) or its own polygons (~node).
    std::vector<std::int32_t> stack{0};
    while (!stack.empty()) {
        const std::int32_t item = stack.back();
        stack.pop_back();
        if (item < 0) {
            const Node& node = nodes_[std::size_t(~item)];
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k) order.push_back(&polygons_[k]);
            continue;
        }
        const Node& node = nodes_[std::size_t(item)];
        const double side = plane_side(polygons_[node.first], eye);
        // The eye's side goes last (nearest); the node's own polygons between, unless the eye
        // lies in their plane (edge-on: they cover no pixel).
        const std::int32_t near = side > 0.0 ? node.front : node.back, far = side > 0.0 ? node.back : node.front;
        if (near >= 0) stack.push_back(near);
        if (side != 0.0) stack.push_back(~item);
        if (far >= 0) stack.push_back(far);
    }
}

std::vector<std::uint32_t> paint_ids(const std::vector<const BspPolygon*>& order, const glm::dvec3& anchor, const Camera& camera,
                                     Resolution display, std::vector<std::uint8_t>* ambiguous) {
    validate_camera(camera);
    validate_resolution(display);
    if (camera.ortho_height > 0.0) throw Error("paint_ids: orthographic cameras are not supported");
    const CameraBasis basis = camera_basis(camera);
    const double aspect = display.aspect();
    const double tan_half = std::tan(glm::radians(camera.fov_y_degrees) * 0.5);
    const glm::dvec3 eye = camera.eye - anchor;
    std::vector<std::uint32_t> ids(std::size_t(display.width) * std::size_t(display.height), kNoObject);
    std::vector<const BspPolygon*> last(ids.size(), nullptr);  // the polygon each pixel shows
    if (ambiguous) ambiguous->assign(ids.size(), 0);
    // Whether polygon b lies in polygon a's plane: coincident surfaces of two objects, whose
    // order is a tie (the BSP keeps them in one node, in no particular order; Embree breaks
    // the tie its own way).
    const auto coplanar = [](const BspPolygon& a, const BspPolygon& b) {
        const double n = glm::length(a.normal);
        for (const glm::dvec3& v : b.vertices)
            if (!(std::abs(glm::dot(a.normal, v) - a.offset) <= 1e-9 * n * (glm::length(v) + 1.0))) return false;
        return true;
    };
    std::vector<glm::dvec3> in, out;
    for (const BspPolygon* polygon : order) {
        // Relative to the eye, clipped to the view depths [near, far].
        in.clear();
        for (const glm::dvec3& v : polygon->vertices) in.push_back(v - eye);
        for (const double sign : {1.0, -1.0}) {
            const double bound = sign > 0.0 ? camera.near_plane : camera.far_plane;
            out.clear();
            for (std::size_t i = 0; i < in.size(); ++i) {
                const glm::dvec3 &a = in[i], &b = in[(i + 1) % in.size()];
                const double sa = sign * (glm::dot(a, basis.forward) - bound), sb = sign * (glm::dot(b, basis.forward) - bound);
                if (sa >= 0.0) out.push_back(a);
                if ((sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0)) out.push_back(a + (b - a) * (sa / (sa - sb)));
            }
            std::swap(in, out);
        }
        if (in.size() < 3) continue;
        // Its pixels: the bounding box of its projection, then each centre's ray against its edges.
        double x0 = HUGE_VAL, x1 = -HUGE_VAL, y0 = HUGE_VAL, y1 = -HUGE_VAL;
        for (const glm::dvec3& v : in) {
            const double z = glm::dot(v, basis.forward);
            const double nx = glm::dot(v, basis.right) / (z * tan_half * aspect), ny = glm::dot(v, basis.up) / (z * tan_half);
            x0 = std::min(x0, (nx + 1.0) * 0.5 * display.width), x1 = std::max(x1, (nx + 1.0) * 0.5 * display.width);
            y0 = std::min(y0, (1.0 - ny) * 0.5 * display.height), y1 = std::max(y1, (1.0 - ny) * 0.5 * display.height);
        }
        const int i0 = std::max(0, int(std::floor(x0)) - 1), i1 = std::min(display.width - 1, int(std::ceil(x1)) + 1);
        const int j0 = std::max(0, int(std::floor(y0)) - 1), j1 = std::min(display.height - 1, int(std::ceil(y1)) + 1);
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i) {
                const glm::dvec3 d = ray_direction(camera, basis, aspect, pixel_to_ndc(display, i + 0.5, j + 0.5));
                // Inside when the ray passes on the same side of every edge (either orientation:
                // back faces are surfaces too); within 1e-9 of an edge's plane: ambiguous.
                bool positive = true, negative = true, near_edge = false;
                for (std::size_t k = 0; k < in.size(); ++k) {
                    const glm::dvec3 n = glm::cross(in[k], in[(k + 1) % in.size()]);
                    const double s = glm::dot(n, d), tolerance = 1e-9 * glm::length(n) * glm::length(d);
                    near_edge = near_edge || std::abs(s) <= tolerance;
                    positive = positive && s >= -tolerance;
                    negative = negative && s <= tolerance;
                }
                if (!(positive || negative)) continue;
                const std::size_t pixel = std::size_t(j) * std::size_t(display.width) + std::size_t(i);
                const bool tie = last[pixel] && last[pixel]->object != polygon->object && coplanar(*last[pixel], *polygon);
                ids[pixel] = polygon->object;
                last[pixel] = polygon;
                if (ambiguous) (*ambiguous)[pixel] = near_edge || tie ? 1 : 0;  // as certain as the last polygon drawn there
            }
    }
    return ids;
}

}  // namespace homcull
