// The world's up from level cameras (cameras/up_axis.h) and the starting points added on a bare ground
// (train/ground_seeds.h): known answers on synthetic cameras and points.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/train/ground_seeds.h"

namespace lumigauss {
namespace {

// A level camera (x axis horizontal, +z up world) at `eye` looking towards `target`, pitched up by `pitch`.
Mat3d pitched_camera(Vec3d eye, Vec3d target, double pitch_degrees) {
    Vec3d f = target - eye;
    f.z = 0;
    f = normalize(f);
    const double p = pitch_degrees * std::numbers::pi / 180;
    const Vec3d forward = std::cos(p) * f + std::sin(p) * Vec3d{0, 0, 1};
    const Vec3d right = normalize(cross(forward, Vec3d{0, 0, 1}));
    const Vec3d down = cross(forward, right);
    return Mat3d{{right, down, forward}};  // rows: the camera's axes in the world (world-to-camera)
}

TEST(CameraUpDirection, LevelCamerasLookingUpStillGiveTheVertical) {
    // Photos from one side of a building, all pitched up 10 deg: their mean -y leans 10 deg towards it.
    std::vector<Mat3d> rotations;
    for (int i = 0; i < 12; ++i) {
        const double a = std::numbers::pi * (-0.3 + 0.6 * i / 11.0) - std::numbers::pi / 2;
        rotations.push_back(pitched_camera({40 * std::cos(a), 40 * std::sin(a), 1.6}, {0, 0, 10}, 10));
    }
    Vec3d mean{};
    for (const Mat3d& r : rotations) mean += -r.row(1);
    EXPECT_LT(normalize(mean).z, std::cos(8 * std::numbers::pi / 180)) << "the mean -y should lean";
    const Vec3d up = camera_up_direction(rotations);
    EXPECT_NEAR(up.z, 1.0, 1e-9);
    // Facing one way only, the x axes do not pin up: the mean -y without its part along them.
    const std::vector<Mat3d> one_way(3, pitched_camera({0, -40, 1.6}, {0, 0, 1.6}, 0));
    EXPECT_NEAR(camera_up_direction(one_way).z, 1.0, 1e-9);
    EXPECT_EQ(length(camera_up_direction({})), 0.0);
    // Upside-down cameras (y up) give -z: the sign follows the cameras' -y.
    std::vector<Mat3d> flipped = rotations;
    for (Mat3d& r : flipped) r = Mat3d{{-1.0 * r.row(0), -1.0 * r.row(1), r.row(2)}};
    EXPECT_NEAR(camera_up_direction(flipped).z, -1.0, 1e-9);
}

struct GroundScene {
    std::vector<Vec3f> points, colours;
    std::vector<Vec3d> cameras;
};

// A ground at z = 0.5 with points only beyond 20 m from the centre (the near ground left bare), a wall of
// points standing on it (from 0.4 m up: its base is no ground colour), and cameras 1.6 m above the ground at
// 10 m from the centre.
GroundScene bare_ground_scene() {
    GroundScene s;
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-60, 60), n(-0.02, 0.02), h(0.9, 20);
    while (s.points.size() < 3000) {
        const double x = u(rng), y = u(rng);
        if (x * x + y * y < 20 * 20) continue;
        s.points.push_back(Vec3d{x, y, 0.5 + n(rng)}.cast<float>());
        s.colours.push_back(x > 0 ? Vec3f{0.8f, 0.2f, 0.2f} : Vec3f{0.2f, 0.2f, 0.8f});
    }
    for (int i = 0; i < 600; ++i) {
        s.points.push_back(Vec3d{u(rng) / 6, 3.0, h(rng)}.cast<float>());
        s.colours.push_back({0.5f, 0.5f, 0.5f});
    }
    for (int i = 0; i < 8; ++i) {
        const double a = 2 * std::numbers::pi * i / 8;
        s.cameras.push_back({10 * std::cos(a), 10 * std::sin(a), 2.1});
    }
    return s;
}

TEST(GroundSeeds, FillTheBareGroundAroundTheCamerasOnThePlane) {
    const GroundScene s = bare_ground_scene();
    GroundSeedOptions o;
    o.reach = 0.5;  // of the extent 20: 10 m around each foot
    const GroundSeeds g = ground_seeds(s.points, s.colours, s.cameras, {0, 0, 1}, 20.0, o);
    ASSERT_TRUE(g.found);
    EXPECT_NEAR(g.height, 0.5, 0.02);
    EXPECT_GE(g.ground_points, 2900u);
    ASSERT_GT(g.xyz.size(), 100u);
    ASSERT_EQ(g.rgb.size(), g.xyz.size());
    bool near_centre = false;
    for (std::size_t i = 0; i < g.xyz.size(); ++i) {
        const Vec3d p = g.xyz[i].cast<double>();
        EXPECT_NEAR(p.z, 0.5, 0.02);
        const double r = std::hypot(p.x, p.y);
        // Within the reach of some foot (feet 10 m out, reach 10 m).
        EXPECT_LE(r, 20.0 + g.spacing) << i;
        near_centre = near_centre || r < 5;
        // Coloured as the nearest ground point: red on the +x side, blue on the -x side.
        if (p.x > 4) {
            EXPECT_GT(g.rgb[i].x, 0.7f) << i;
        }
        if (p.x < -4) {
            EXPECT_GT(g.rgb[i].z, 0.7f) << i;
        }
    }
    EXPECT_TRUE(near_centre);
    // The limit coarsens the grid instead of cutting the area short.
    o.max_seeds = g.xyz.size() / 4;
    const GroundSeeds coarse = ground_seeds(s.points, s.colours, s.cameras, {0, 0, 1}, 20.0, o);
    EXPECT_LE(coarse.xyz.size(), o.max_seeds);
    EXPECT_GT(coarse.spacing, g.spacing);
    bool coarse_near_centre = false;
    for (const Vec3f& p : coarse.xyz) coarse_near_centre = coarse_near_centre || std::hypot(p.x, p.y) < 6;
    EXPECT_TRUE(coarse_near_centre);
}

TEST(GroundSeeds, NoneWithoutAGroundUnderTheCameras) {
    GroundScene s = bare_ground_scene();
    // Turned upside down: the "ground" is above every camera.
    for (Vec3f& p : s.points) p.z = 5.0f - p.z;
    EXPECT_FALSE(ground_seeds(s.points, s.colours, s.cameras, {0, 0, 1}, 20.0).found);
    // Points scattered in a volume: no height holds a quarter of them.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-30, 30), z(-30, 2);
    std::vector<Vec3f> cloud;
    for (int i = 0; i < 3000; ++i) cloud.push_back({u(rng), u(rng), z(rng)});
    const GroundSeeds none =
        ground_seeds(cloud, std::vector<Vec3f>(cloud.size()), s.cameras, {0, 0, 1}, 20.0);
    EXPECT_FALSE(none.found);
    EXPECT_TRUE(none.xyz.empty());
    // No cameras, no up, too few points.
    EXPECT_FALSE(ground_seeds(s.points, s.colours, {}, {0, 0, 1}, 20.0).found);
    EXPECT_FALSE(ground_seeds(s.points, s.colours, s.cameras, {0, 0, 0}, 20.0).found);
    EXPECT_FALSE(ground_seeds({s.points.begin(), s.points.begin() + 10},
                              {s.colours.begin(), s.colours.begin() + 10}, s.cameras, {0, 0, 1}, 20.0)
                     .found);
}

}  // namespace
}  // namespace lumigauss
