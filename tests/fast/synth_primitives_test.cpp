// Ray-primitive intersection and surface sampling of the synthetic scenes, and the pose helpers.
#include <gtest/gtest.h>

#include <cmath>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/synth/camera_paths.h"
#include "lumigauss/synth/colmap_with_tracks.h"
#include "lumigauss/synth/rng.h"
#include "lumigauss/synth/world.h"

namespace lumigauss {
namespace {

using synth::Ray;

TEST(SynthPrimitives, BoxHitHasTheFaceNormal) {
    const synth::Primitive box = synth::make_box({-1, -1, 0}, {1, 1, 2}, 0);
    const auto h = synth::intersect(box, Ray{{0, -5, 1}, {0, 1, 0}}, 0, 1e9);
    ASSERT_TRUE(h);
    EXPECT_DOUBLE_EQ(h->t, 4.0);
    EXPECT_EQ(h->normal.y, -1.0);
    EXPECT_FALSE(synth::intersect(box, Ray{{0, -5, 3}, {0, 1, 0}}, 0, 1e9));
    EXPECT_FALSE(synth::intersect(box, Ray{{0, -5, 1}, {0, 1, 0}}, 0, 3.9));  // beyond t_max
}

TEST(SynthPrimitives, CylinderSideAndCap) {
    const synth::Primitive cyl = synth::make_cylinder(2, 3, 0.5, 1, 4, 0);
    auto side = synth::intersect(cyl, Ray{{2, -5, 2}, {0, 1, 0}}, 0, 1e9);
    ASSERT_TRUE(side);
    EXPECT_NEAR(side->t, 7.5, 1e-12);
    EXPECT_NEAR(side->normal.y, -1.0, 1e-12);
    auto cap = synth::intersect(cyl, Ray{{2.1, 3, 10}, {0, 0, -1}}, 0, 1e9);
    ASSERT_TRUE(cap);
    EXPECT_NEAR(cap->t, 6.0, 1e-12);
    EXPECT_EQ(cap->normal.z, 1.0);
    EXPECT_FALSE(synth::intersect(cyl, Ray{{2, -5, 4.5}, {0, 1, 0}}, 0, 1e9));
}

TEST(SynthPrimitives, SphereAndGround) {
    const synth::Primitive s = synth::make_sphere({0, 0, 5}, 2, 0);
    const auto h = synth::intersect(s, Ray{{0, 0, 10}, {0, 0, -1}}, 0, 1e9);
    ASSERT_TRUE(h);
    EXPECT_NEAR(h->t, 3.0, 1e-12);
    EXPECT_NEAR(h->normal.z, 1.0, 1e-12);
    const synth::Primitive g = synth::make_ground(300, 0);
    const auto gh = synth::intersect(g, Ray{{0, 0, 2}, normalize(Vec3d{1, 0, -1})}, 0, 1e9);
    ASSERT_TRUE(gh);
    EXPECT_NEAR(gh->t, 2 * std::sqrt(2.0), 1e-12);
    EXPECT_FALSE(synth::intersect(g, Ray{{0, 0, 2}, {0, 0, 1}}, 0, 1e9));
}

// A sampled surface point is where a ray coming in along -normal first meets the primitive.
TEST(SynthPrimitives, SurfaceSamplesLieOnTheSurface) {
    const synth::Primitive prims[] = {synth::make_box({-1, -2, 0}, {3, 1, 2}, 0),
                                      synth::make_cylinder(1, 1, 0.7, 0.5, 3, 0),
                                      synth::make_sphere({0, 2, 1}, 1.5, 0)};
    synth::Rng rng(5);
    for (const auto& p : prims)
        for (int i = 0; i < 200; ++i) {
            const auto s = synth::sample_surface(p, rng.uniform(), rng.uniform(), rng.uniform());
            const Ray ray{s.position + 10.0 * s.normal, -s.normal};
            const auto h = synth::intersect(p, ray, 0, 1e9);
            ASSERT_TRUE(h);
            EXPECT_NEAR(h->t, 10.0, 1e-9);
            EXPECT_NEAR(dot(h->normal, s.normal), 1.0, 1e-9);
        }
}

// The faces partition the surface: their areas add up, each maps the unit square onto the surface with the
// face's own normal, uniformly by area (the image of a small parameter square has area face_area * da * db).
TEST(SynthPrimitives, FacesMapTheUnitSquareUniformlyByArea) {
    const synth::Primitive prims[] = {synth::make_box({-1, -2, 0}, {3, 1, 2}, 0),
                                      synth::make_cylinder(1, 1, 0.7, 0.5, 3, 0),
                                      synth::make_sphere({0, 2, 1}, 1.5, 0)};
    synth::Rng rng(9);
    for (const auto& p : prims) {
        double total = 0;
        for (int f = 0; f < synth::face_count(p); ++f) {
            total += synth::face_area(p, f);
            for (int i = 0; i < 50; ++i) {
                const double a = rng.uniform(0.05, 0.95), b = rng.uniform(0.05, 0.95), d = 1e-5;
                const auto s = synth::sample_face(p, f, a, b);
                const auto h = synth::intersect(p, Ray{s.position + 1e-3 * s.normal, -s.normal}, 0, 1);
                ASSERT_TRUE(h);
                EXPECT_NEAR(h->t, 1e-3, 1e-9);
                EXPECT_NEAR(dot(h->normal, s.normal), 1.0, 1e-9);
                const Vec3d du = synth::sample_face(p, f, a + d, b).position - s.position;
                const Vec3d dv = synth::sample_face(p, f, a, b + d).position - s.position;
                EXPECT_NEAR(dot(du, dv), 0.0, 1e-3 * length(du) * length(dv));  // orthogonal parameters
                EXPECT_NEAR(length(cross(du, dv)) / (d * d), synth::face_area(p, f),
                            1e-3 * synth::face_area(p, f));
            }
        }
        EXPECT_NEAR(total, synth::surface_area(p), 1e-9 * total);
        // Inside is strictly inside: the centre of the bounds is, a lifted surface point is not.
        EXPECT_TRUE(synth::contains(p, 0.5 * (p.lo + p.hi)));
        const auto s = synth::sample_face(p, 0, 0.3, 0.6);
        EXPECT_FALSE(synth::contains(p, s.position + 1e-6 * s.normal));
        EXPECT_TRUE(synth::contains(p, s.position - 1e-6 * s.normal));
    }
}

TEST(SynthPrimitives, LandmarksAreWithinTheirBoundsAndCastShadows) {
    for (const std::string& name : synth::landmark_names()) {
        const synth::Landmark l = synth::build_landmark(name);
        EXPECT_LE(l.world.prims.size(), 100u);
        for (std::size_t i = 1; i < l.world.prims.size(); ++i) {  // 0 is the ground
            const auto& p = l.world.prims[i];
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(p.lo[a], l.bbox_lo[a] - 1e-9) << name << " primitive " << i;
                EXPECT_LE(p.hi[a], l.bbox_hi[a] + 1e-9) << name << " primitive " << i;
            }
            EXPECT_LT(std::size_t(p.material), l.world.materials.size());
        }
        // A point on the ground just in front of the entrance is shadowed by a sun low in the north (+Y).
        const Vec3d c = 0.5 * (l.bbox_lo + l.bbox_hi);
        EXPECT_TRUE(synth::occluded(l.world, Ray{{c.x, c.y, 0.01}, normalize(Vec3d{0, 1, 0.3})}));
    }
}

TEST(SynthPrimitives, LookAtAndQuaternionRoundTrip) {
    const Vec3d eye{-20, -30, 1.7}, target{0, 0, 8};
    const Mat3d r = synth::look_at_rotation(eye, target, 0.05);
    // Rows: camera x (right), y (down), z (forward) in world coordinates.
    EXPECT_NEAR(dot(r.row(2), normalize(target - eye)), 1.0, 1e-12);
    EXPECT_GT(dot(r.row(1), Vec3d{0, 0, -1}), 0.9);  // image down is world down
    const Mat3d back = rotation_from_unit_quaternion(quaternion_from_rotation(r));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(back(i, j), r(i, j), 1e-12);
    const Vec4<double> q = quaternion_from_rotation(r);
    EXPECT_GE(q.x, 0.0);
}

TEST(SynthPrimitives, CameraRayThroughProjection) {
    Camera cam;
    cam.width = 64, cam.height = 48, cam.fx = cam.fy = 60, cam.cx = 32, cam.cy = 24;
    cam.rotation = synth::look_at_rotation({5, -40, 2}, {0, 0, 6}, 0.02);
    cam.translation = -(cam.rotation * Vec3d{5, -40, 2});
    const synth::Ray ray = synth::camera_ray(cam, 10.25, 40.75);
    const Vec3d p = cam.world_to_camera(ray.origin + 17.0 * ray.dir);
    EXPECT_NEAR(cam.fx * p.x / p.z + cam.cx, 10.25, 1e-9);
    EXPECT_NEAR(cam.fy * p.y / p.z + cam.cy, 40.75, 1e-9);
}

}  // namespace
}  // namespace lumigauss
