// The ground plane under the cameras (cameras/ground_plane.h) and the up it refines (scene_up_direction,
// cameras/up_axis.h): found among walls and clutter, refused when sloped beyond kMaxGroundTilt, and deciding
// the up where the cameras' level x axes all point one way.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "lumigauss/cameras/ground_plane.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/camera.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/util/rng.h"

namespace lumigauss {
namespace {

enum class TestRandom { kPoints };

double degrees_between(Vec3d a, Vec3d b) {
    return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

// A camera at `centre` looking along `forward` with its x axis level (perpendicular to +z).
Camera level_camera(Vec3d centre, Vec3d forward) {
    const Vec3d f = normalize(forward);
    const Vec3d right = normalize(cross(f, Vec3d{0, 0, 1}));
    Camera c;
    c.rotation = {{right, cross(f, right), f}};
    c.translation = -1.0 * (c.rotation * centre);
    return c;
}

// A plaza: ground points on the plane through the origin with normal `ground_normal` (a 40 x 40 grid over
// 20 x 20 m, 1 mm of noise), a wall (x = 6, 0..8 m high), and a tenth as many random points in the air.
std::vector<Vec3d> plaza_points(Vec3d ground_normal = {0, 0, 1}) {
    Rng rng(7, TestRandom::kPoints);
    const Vec3d n = normalize(ground_normal);
    std::vector<Vec3d> points;
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 40; ++j) {
            const double x = -10 + 0.5 * i, y = -10 + 0.5 * j;
            // The height that puts (x, y) on the plane n . p = 0.
            const double z = -(n.x * x + n.y * y) / n.z + 0.001 * rng.normal();
            points.push_back({x, y, z});
        }
    for (int i = 0; i < 20; ++i)
        for (int k = 0; k < 16; ++k) points.push_back({6, -5 + 0.5 * i, 0.5 * k});
    for (int i = 0; i < 160; ++i)
        points.push_back({rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(0.5, 1.5)});
    return points;
}

std::vector<Vec3d> centres_of(const std::vector<Camera>& cameras) {
    std::vector<Vec3d> out;
    for (const Camera& c : cameras) out.push_back(c.center());
    return out;
}

std::vector<Mat3d> rotations_of(const std::vector<Camera>& cameras) {
    std::vector<Mat3d> out;
    for (const Camera& c : cameras) out.push_back(c.rotation);
    return out;
}

// Eight level cameras at eye height on a circle, looking at the centre.
std::vector<Camera> cameras_around() {
    std::vector<Camera> cams;
    for (int k = 0; k < 8; ++k) {
        const double a = 2 * std::numbers::pi * k / 8;
        const Vec3d c{8 * std::cos(a), 8 * std::sin(a), 1.7};
        cams.push_back(level_camera(c, Vec3d{0, 0, 1.7} - c));
    }
    return cams;
}

TEST(GroundPlane, FoundAmongWallsAndClutterFromATiltedGuess) {
    const std::vector<Vec3d> points = plaza_points();
    const std::vector<Vec3d> centres = centres_of(cameras_around());
    const Vec3d guess = rotation_about_axis(Vec3d{1, 0, 0}, 15 * std::numbers::pi / 180) * Vec3d{0, 0, 1};
    const GroundPlane g = find_ground_plane(points, centres, guess);
    ASSERT_TRUE(g.found);
    EXPECT_LT(degrees_between(g.normal, {0, 0, 1}), 0.05);
    EXPECT_NEAR(g.offset, 0.0, 0.01);
    EXPECT_GE(g.inliers, 1600u);
    EXPECT_LT(g.inliers, 1700u) << "the wall's foot and the clutter are not the ground";
    const GroundPlane again = find_ground_plane(points, centres, guess);
    EXPECT_EQ(again.normal.x, g.normal.x) << "deterministic";
    EXPECT_EQ(again.inliers, g.inliers);
}

TEST(GroundPlane, NotFoundWhereThereIsNone) {
    const std::vector<Vec3d> centres = centres_of(cameras_around());
    // Sloped by 40 degrees from the guess: not a ground.
    const Vec3d steep = rotation_about_axis(Vec3d{0, 1, 0}, 40 * std::numbers::pi / 180) * Vec3d{0, 0, 1};
    EXPECT_FALSE(find_ground_plane(plaza_points(steep), centres, {0, 0, 1}).found);
    // Everything above the cameras, or too few points.
    std::vector<Vec3d> above;
    for (Vec3d p : plaza_points()) above.push_back(p + Vec3d{0, 0, 10});
    EXPECT_FALSE(find_ground_plane(above, centres, {0, 0, 1}).found);
    EXPECT_FALSE(find_ground_plane({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, centres, {0, 0, 1}).found);
    EXPECT_FALSE(find_ground_plane(plaza_points(), {}, {0, 0, 1}).found);
    // Random points in a box: no plane holds a fifth of them.
    Rng rng(3, TestRandom::kPoints);
    std::vector<Vec3d> cloud;
    for (int i = 0; i < 2000; ++i)
        cloud.push_back({rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(-5, 1)});
    EXPECT_FALSE(find_ground_plane(cloud, centres, {0, 0, 1}).found);
}

// Photos of one facade, all looking north and 15 degrees up at it: their x axes all point east, so the
// cameras alone take the up from their mean -y, which tilts by the mean pitch. The ground fixes it.
TEST(SceneUp, TheGroundDecidesWhereEveryPhotoFacesOneWay) {
    const double pitch = 15 * std::numbers::pi / 180;
    std::vector<Camera> cams;
    for (int k = 0; k < 6; ++k)
        cams.push_back(level_camera({-5.0 + 2 * k, -8, 1.7}, {0, std::cos(pitch), std::sin(pitch)}));
    const Vec3d cameras_only = camera_up_direction(rotations_of(cams));
    EXPECT_GT(degrees_between(cameras_only, {0, 0, 1}), 14.0) << "the cameras alone tilt by their pitch";
    const Vec3d up = estimate_up_axis(cams, plaza_points());
    EXPECT_LT(degrees_between(up, {0, 0, 1}), 0.05);
    EXPECT_EQ(estimate_up_axis(cams).x, cameras_only.x) << "no points: the cameras' up";
}

// Level photos all around on a street sloping 10 degrees: the x axes pin the up, the ground moves it by
// about a degree (w = 0.05 per camera against their horizontal spread of 0.5 per camera).
TEST(SceneUp, ASlopeMovesTheUpOfCamerasAllAroundOnlyALittle) {
    const Vec3d slope = rotation_about_axis(Vec3d{0, 1, 0}, 10 * std::numbers::pi / 180) * Vec3d{0, 0, 1};
    const std::vector<Camera> cams = cameras_around();
    const Vec3d up = estimate_up_axis(cams, plaza_points(slope));
    const double moved = degrees_between(up, {0, 0, 1});
    EXPECT_GT(moved, 0.5);
    EXPECT_LT(moved, 1.5);
    // Same as the cameras alone on a level ground.
    EXPECT_LT(degrees_between(estimate_up_axis(cams, plaza_points()), {0, 0, 1}), 0.01);
}

}  // namespace
}  // namespace lumigauss
