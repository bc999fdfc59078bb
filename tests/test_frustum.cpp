#include <homcull/frustum.hpp>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>

#include <limits>
#include <random>
#include <vector>

namespace homcull {
namespace {

Camera looking_down_minus_z() {
    Camera c;
    c.fov_y_degrees = 90.0;
    c.near_plane = 1.0;
    c.far_plane = 100.0;
    return c;
}

Aabb box(glm::vec3 lo, glm::vec3 hi) { return Aabb{lo, hi}; }

// A camera near the origin looking at a random point, with a random field of view.
Camera random_camera(std::mt19937_64& rng, std::uniform_real_distribution<double>& pos, double far_plane) {
    Camera c;
    c.eye = {pos(rng) * 0.2, pos(rng) * 0.2, pos(rng) * 0.2};
    c.target = {pos(rng), pos(rng), pos(rng)};
    c.fov_y_degrees = 30.0 + double(rng() % 90);
    c.near_plane = 0.5;
    c.far_plane = far_plane;
    return c;
}

TEST(Frustum, ObviousCases) {
    const Frustum f = make_frustum(looking_down_minus_z(), 1.0);
    EXPECT_TRUE(intersects(f, box({-1, -1, -10}, {1, 1, -8})));       // straight ahead
    EXPECT_FALSE(intersects(f, box({-1, -1, 5}, {1, 1, 8})));         // behind the eye
    EXPECT_FALSE(intersects(f, box({-1, -1, -300}, {1, 1, -200})));   // beyond far
    EXPECT_FALSE(intersects(f, box({-0.1f, -0.1f, -0.5f}, {0.1f, 0.1f, -0.2f})));  // before near
    EXPECT_TRUE(intersects(f, box({-0.1f, -0.1f, -2}, {0.1f, 0.1f, 0.5f})));       // through near
    EXPECT_FALSE(intersects(f, box({11, -1, -10}, {12, 1, -9})));     // right of the right plane
    EXPECT_TRUE(intersects(f, box({9, -1, -10}, {12, 1, -9})));       // across it
    EXPECT_TRUE(intersects(f, box({-1000, -1000, -1000}, {1000, 1000, 1000})));  // contains it
    EXPECT_FALSE(intersects(f, Aabb{}));                                // empty box
}

// An independent oracle: clip each face of the box by the six frustum planes
// (Sutherland-Hodgman); the bodies meet iff a face keeps some area, or the frustum lies
// inside the box.
bool meets_by_clipping(const Frustum& f, const Aabb& b) {
    const glm::dvec3 lo(b.min), hi(b.max);
    auto corner = [&](int k) { return glm::dvec3((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z); };
    const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& face : faces) {
        std::vector<glm::dvec3> poly = {corner(face[0]), corner(face[1]), corner(face[2]), corner(face[3])};
        for (const auto& plane : f.planes) {
            std::vector<glm::dvec3> out;
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const glm::dvec3 a = poly[i], c = poly[(i + 1) % poly.size()];
                const double da = glm::dot(glm::dvec3(plane), a) + plane.w, dc = glm::dot(glm::dvec3(plane), c) + plane.w;
                if (da >= 0) out.push_back(a);
                if ((da >= 0) != (dc >= 0)) out.push_back(a + (c - a) * (da / (da - dc)));
            }
            poly = out;
            if (poly.empty()) break;
        }
        if (!poly.empty()) return true;
    }
    const glm::dvec3 p = f.corners[0];
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}

bool plane_test(const Frustum& f, const Aabb& b) {  // the usual conservative test
    for (const auto& plane : f.planes) {
        const glm::dvec3 n(plane);
        const glm::dvec3 far_corner(n.x >= 0 ? b.max.x : b.min.x, n.y >= 0 ? b.max.y : b.min.y, n.z >= 0 ? b.max.z : b.min.z);
        if (glm::dot(n, far_corner) + plane.w < 0) return false;
    }
    return true;
}

TEST(Frustum, ExactAgainstClippingOracleOnRandomBoxes) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> pos(-60.0, 60.0), size(0.1, 15.0);
    int disagreements = 0, plane_test_keeps_outside = 0;
    for (int camera_trial = 0; camera_trial < 20; ++camera_trial) {
        const Camera c = random_camera(rng, pos, 80.0);
        const Frustum f = make_frustum(c, 1.6);
        for (int k = 0; k < 2000; ++k) {
            const glm::vec3 lo(glm::dvec3(pos(rng), pos(rng), pos(rng)));
            const Aabb b{lo, lo + glm::vec3(glm::dvec3(size(rng), size(rng), size(rng)))};
            const bool exact = intersects(f, b);
            disagreements += exact != meets_by_clipping(f, b);
            plane_test_keeps_outside += plane_test(f, b) && !exact;
            if (exact) { EXPECT_TRUE(plane_test(f, b)) << "the exact test must never be looser"; }
        }
    }
    EXPECT_EQ(disagreements, 0);
    EXPECT_GT(plane_test_keeps_outside, 0) << "expected boxes near frustum edges that only the exact test rejects";
}

// frustum_axes with a margin separates only boxes that intersects() finds apart, and keeps a box
// moved apart by less than the margin; without one it is intersects().
TEST(Frustum, AxesWithAMarginSeparateLessThanTheExactTest) {
    Camera c;
    c.eye = {3, 1, -2};
    c.target = {10, 2, -30};
    c.near_plane = 0.5;
    c.far_plane = 80.0;
    const Frustum f = make_frustum(c, 1.6);
    const FrustumAxes exact = frustum_axes(f), widened = frustum_axes(f, 0x1.0p-20);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> pos(-90.0, 90.0), size(0.1, 30.0);
    int apart = 0, kept_by_margin = 0;
    for (int k = 0; k < 20000; ++k) {
        const glm::vec3 lo(glm::dvec3(pos(rng), pos(rng), pos(rng)));
        const Aabb b{lo, lo + glm::vec3(glm::dvec3(size(rng), size(rng), size(rng)))};
        const bool meets = intersects(f, b);
        EXPECT_EQ(separated(exact, b), !meets);
        if (separated(widened, b)) {
            EXPECT_FALSE(meets);
            ++apart;
        }
        kept_by_margin += !meets && !separated(widened, b);
    }
    EXPECT_GT(apart, 1000);
    EXPECT_LT(kept_by_margin, 10);  // the margin is far below these boxes' distances
    // A small box around the eye lies before the near plane, apart either way; so is an empty box.
    const Aabb at_eye{glm::vec3(c.eye - 0.01), glm::vec3(c.eye + 0.01)};
    EXPECT_TRUE(separated(exact, at_eye));
    EXPECT_TRUE(separated(widened, at_eye));
    EXPECT_TRUE(separated(exact, Aabb{}));
    // A box with a coordinate that is not a number, or infinite, is never separated.
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    for (const Aabb& b : {Aabb{{nan, 0, 0}, {1, 1, 1}}, Aabb{{-inf, 0, 0}, {inf, 1, 1}}, Aabb{{200, 200, 200}, {inf, inf, inf}}}) {
        EXPECT_FALSE(separated(exact, b));
        EXPECT_FALSE(separated(widened, b));
    }
    // A far plane at infinity (the scene culler's widening of one at the largest double) puts the
    // far corners at infinity: the axes they reach are left out, so a box straight ahead is never
    // separated (their NaN projections once shrank the extents to the near rectangle).
    Camera unbounded = c;
    unbounded.far_plane = std::numeric_limits<double>::infinity();
    const FrustumAxes no_far = frustum_axes(make_frustum(unbounded, 1.6), 0x1.0p-20);
    const glm::dvec3 ahead = c.eye + 30.0 * glm::normalize(c.target - c.eye);
    EXPECT_FALSE(separated(no_far, Aabb{glm::vec3(ahead - 1.0), glm::vec3(ahead + 1.0)}));
    // A slack in position widens every extent: a box just beyond the far plane is kept.
    const glm::dvec3 far_point = c.eye + 80.5 * glm::normalize(c.target - c.eye);
    const Aabb just_beyond{glm::vec3(far_point - 0.1), glm::vec3(far_point + 0.1)};
    EXPECT_TRUE(separated(exact, just_beyond));
    EXPECT_FALSE(separated(frustum_axes(f, 0.0, glm::dvec3(1.0)), just_beyond));
}

// view_volume_axes of a camera's clip-from-world matrix separates exactly the boxes that
// intersects() finds apart from the camera's frustum when its far plane lies beyond every box,
// perspective and orthographic; with a margin, only such boxes. From clip_from_world * model (a
// translation and a power-of-two scale, so that a model box's world image is a box), it answers
// for the model box what the world test answers for its image.
TEST(Frustum, ViewVolumeOfAClipMatrixIsTheCamerasFrustumWithoutItsFarPlane) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> pos(-60.0, 60.0), size(0.1, 15.0);
    for (const bool orthographic : {false, true}) {
        int apart = 0, apart_with_margin = 0, corner_boxes = 0;
        for (int camera_trial = 0; camera_trial < 20; ++camera_trial) {
            Camera c = random_camera(rng, pos, 1e6);  // the far plane beyond every box: the volume has none
            if (orthographic) c.ortho_height = 20.0 + double(rng() % 40);
            const double aspect = 1.6;
            const Frustum f = make_frustum(c, aspect);
            const glm::dmat4 clip_from_world = projection_matrix(c, aspect) * view_matrix(c);
            const FrustumAxes exact = view_volume_axes(clip_from_world, c.near_plane, orthographic, 0.0);
            const FrustumAxes widened = view_volume_axes(clip_from_world, c.near_plane, orthographic, 0x1.0p-20);
            const glm::dvec3 shift(pos(rng), pos(rng), pos(rng));
            const glm::dmat4 model = glm::scale(glm::translate(glm::dmat4(1.0), shift), glm::dvec3(2.0, 0.5, 4.0));
            const FrustumAxes in_model = view_volume_axes(clip_from_world * model, c.near_plane, orthographic, 0.0);
            ASSERT_GE(exact.plane_count, 5);
            for (int k = 0; k < 2000; ++k) {
                const glm::vec3 lo(glm::dvec3(pos(rng), pos(rng), pos(rng)));
                const Aabb b{lo, lo + glm::vec3(glm::dvec3(size(rng), size(rng), size(rng)))};
                const bool meets = intersects(f, b);
                ASSERT_EQ(separated(exact, b), !meets) << "camera " << camera_trial << ", box " << k;
                apart += !meets;
                if (separated(widened, b)) {
                    EXPECT_FALSE(meets);
                    ++apart_with_margin;
                }
                corner_boxes += !meets && may_meet(f, b);  // apart, yet within every plane alone
                const glm::dvec3 model_lo = (glm::dvec3(b.min) - shift) / glm::dvec3(2.0, 0.5, 4.0);
                const glm::dvec3 model_hi = (glm::dvec3(b.max) - shift) / glm::dvec3(2.0, 0.5, 4.0);
                const Aabb model_box{glm::vec3(model_lo), glm::vec3(model_hi)};
                // The model box's image is b up to the float rounding of its corners: compare
                // only where that cannot matter.
                if (glm::dvec3(model_box.min) * glm::dvec3(2.0, 0.5, 4.0) + shift == glm::dvec3(b.min) &&
                    glm::dvec3(model_box.max) * glm::dvec3(2.0, 0.5, 4.0) + shift == glm::dvec3(b.max)) {
                    EXPECT_EQ(separated(in_model, model_box), !meets) << "model box " << k;
                }
            }
        }
        EXPECT_GT(apart, 10000) << orthographic;
        EXPECT_GT(apart_with_margin, apart - 50) << orthographic;
        EXPECT_GT(corner_boxes, 20) << orthographic << ": expected boxes beside the volume's edges that only the exact axes separate";
    }
    // A degenerate matrix, or one that is not finite, separates nothing.
    const Aabb far_away{{1000, 1000, 1000}, {1001, 1001, 1001}};
    EXPECT_FALSE(separated(view_volume_axes(glm::dmat4(0.0), 0.5, false, 0.0), far_away));
    glm::dmat4 not_finite(1.0);
    not_finite[2][3] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(separated(view_volume_axes(not_finite, 0.5, false, 0.0), far_away));
}

}  // namespace
}  // namespace homcull
