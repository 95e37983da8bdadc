// The ground's albedo read off the surfels (model/ground_albedo.h) and the ground drawn below the horizon
// (ground_colour, sky_pixels, panorama_sky_image): a known answer for each, and the backward's choice to pass
// nothing through the ground.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "fast/trainer_test_util.h"
#include "lumigauss/io/image.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/ground_albedo.h"
#include "lumigauss/relight/relit_sky.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {
namespace {

struct TestSurfel {
    Vec3f normal;
    float side;     // metres (both scales)
    float opacity;  // activated
    Vec3f albedo;   // activated
};

// Raw parameters whose activations are the given ones: the normal is the rotation's third column.
SurfelModel model_of(const std::vector<TestSurfel>& surfels) {
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (const TestSurfel& s : surfels) {
        const Vec3d n = normalize(s.normal.cast<double>());
        const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
        const Vec3d u = normalize(cross(helper, n)), v = cross(n, u);
        const Mat3d r{{{u.x, v.x, n.x}, {u.y, v.y, n.y}, {u.z, v.z, n.z}}};
        const Vec4<double> q = quaternion_from_rotation(r);
        for (int k = 0; k < 3; ++k) raw[int(ModelParam::Xyz)].push_back(0.0f);
        for (int k = 0; k < 4; ++k) raw[int(ModelParam::Rotation)].push_back(float(q[k]));
        for (int k = 0; k < 2; ++k) raw[int(ModelParam::Scaling)].push_back(std::log(s.side));
        raw[int(ModelParam::Opacity)].push_back(inverse_sigmoid(s.opacity));
        // albedo_activation(a) = Y00 * a + 0.5 (above 0).
        for (int c = 0; c < 3; ++c)
            raw[int(ModelParam::Albedo)].push_back(float((s.albedo[c] - 0.5) / sh_const::kY00));
        for (int k = 0; k < kTransferStored; ++k) {
            raw[int(ModelParam::TransferPositive)].push_back(0.0f);
            raw[int(ModelParam::TransferNegative)].push_back(0.0f);
        }
    }
    return SurfelModel::from_raw(std::move(raw));
}

TEST(GroundAlbedo, WeightedMedianOfTheSurfelsFacingUp) {
    const Vec3f up{0, 0, 1};
    std::vector<TestSurfel> s;
    s.push_back({{0, 0, 1}, 2.0f, 0.9f, {0.6f, 0.5f, 0.4f}});  // the plaza: one large surfel
    for (int i = 0; i < 20; ++i)                               // a textured patch: many small dark ones
        s.push_back({{0.1f, 0, -1}, 0.1f, 0.9f, {0.1f, 0.1f, 0.1f}});
    for (int i = 0; i < 5; ++i)  // walls: bright, but vertical, so not the ground
        s.push_back({{1, 0, 0}, 3.0f, 1.0f, {1.0f, 1.0f, 1.0f}});
    const Vec3f a = ground_albedo(model_of(s), up);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], s[0].albedo[c], 2.0 / 1024) << c;
    // A diverged surfel (NaN albedo) is left out, not binned.
    std::vector<TestSurfel> with_nan = s;
    with_nan.push_back({{0, 0, 1}, 9.0f, 1.0f, {std::nanf(""), 0.5f, 0.5f}});
    EXPECT_EQ(ground_albedo(model_of(with_nan), up).x, a.x);
    // Two ground materials: the median moves to the one that covers more (opacity x area).
    s.push_back({{0, 0, 1}, 2.5f, 0.9f, {0.2f, 0.3f, 0.2f}});
    const Vec3f b = ground_albedo(model_of(s), up);
    EXPECT_NEAR(b.x, 0.2f, 2.0 / 1024);
    // The up is any direction, given unnormalised; nothing faces it: 0.
    const Vec3f sideways = ground_albedo(model_of(s), Vec3f{0, 3, 0});
    EXPECT_EQ(sideways.x, 0.0f);
    EXPECT_EQ(ground_albedo(SurfelModel{}, up).y, 0.0f);
}

// A level camera looking along +x: the top half of the image is above the horizon.
Camera level_camera() {
    Camera cam;
    cam.width = 8, cam.height = 64, cam.fx = cam.fy = 20, cam.cx = 4, cam.cy = 32;
    cam.rotation = Mat3d{{{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}};
    return cam;
}

TEST(GroundBackdrop, DrawnWhereTheSkyHasFaded) {
    const Camera cam = level_camera();
    ShCoeffs<float> env;
    env.c[0] = {1.5f, 1.2f, 1.0f};
    env.c[2] = {0.4f, 0.3f, 0.2f};  // brighter from above
    SkyHorizon horizon{{0, 0, 1}, 4, 4};
    const Image black = sky_image(cam, env, nullptr, horizon);
    horizon.ground_albedo = {0.5f, 0.4f, 0.3f};
    const Image ground = sky_image(cam, env, nullptr, horizon);
    // Known answer: albedo x intensity of the irradiance at the up normal.
    const Vec3f e = irradiance(env, Vec3f{0, 0, 1});
    Vec3f expected;
    for (int c = 0; c < 3; ++c) expected[c] = horizon.ground_albedo[c] * std::pow(e[c], 1.0f / 2.2f);
    const Vec3f colour = horizon_ground_colour(env, horizon);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(colour[c], expected[c], 1e-5) << c;
    int sky = 0, fade = 0, below = 0;
    for (int y = 0; y < cam.height; ++y) {
        const double degrees = -std::asin(pixel_ray_direction(cam, 4, y).z) * 180 / std::numbers::pi;
        if (degrees <= 3.9) {
            ++sky;
            for (int c = 0; c < 3; ++c) EXPECT_EQ(ground.at(4, y, c), black.at(4, y, c));
        }
        if (degrees >= 8.1) {
            ++below;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(ground.at(4, y, c), expected[c], 1e-5);
        }
        if (degrees > 4.1 && degrees < 7.9) {
            // The blend: visible sky plus the rest of the ground.
            ++fade;
            const float visible = sky_visibility(Vec3f{0, 0, 1}, float(std::sin(4 * std::numbers::pi / 180)),
                                                 float(std::sin(8 * std::numbers::pi / 180)),
                                                 pixel_ray_direction(cam, 4, y).cast<float>());
            EXPECT_NEAR(ground.at(4, y, 0), black.at(4, y, 0) + (1 - visible) * expected[0], 1e-5);
        }
    }
    EXPECT_GT(sky, 10);
    EXPECT_GT(fade, 1);
    EXPECT_GT(below, 10);
    // No horizon, no ground.
    EXPECT_EQ(horizon_ground_colour(env, {{0, 0, 1}, 4, 0, {0.5f, 0.4f, 0.3f}}).x, 0.0f);

    // The panorama's sky takes the ground colour it is given in the same places.
    Image pano(16, 8, 3, 0.5f);
    PanoramaSky p;
    p.pixels = &pano;
    p.horizon = horizon;
    p.ground = expected;
    const Image pano_sky = panorama_sky_image(cam, p);
    EXPECT_NEAR(pano_sky.at(4, cam.height - 1, 1), expected.y, 1e-6);
    EXPECT_NEAR(pano_sky.at(4, 0, 1), std::pow(0.5f, 1.0f / 2.2f), 1e-5);
}

TEST(GroundBackdrop, BackwardPassesNothingThroughTheGround) {
    // The ground takes the light as it is: a gradient on pixels that show only ground moves nothing.
    const Camera cam = level_camera();
    const std::vector<Vec3f> rays = pixel_ray_directions(cam);
    ShCoeffs<float> env;
    env.c[0] = {1.5f, 1.2f, 1.0f};
    SkyPixels sky;
    sky_pixels(rays, env, nullptr, sky, {{0, 0, 1}, 4, 4, {0.5f, 0.5f, 0.5f}});
    std::vector<float> g(3 * rays.size(), 0.0f);
    for (std::size_t p = 0; p < rays.size(); ++p)
        if (sky.visibility[p] == 0.0f) g[3 * p] = g[3 * p + 1] = g[3 * p + 2] = 1.0f;
    const SkyGrads grads = sky_pixels_backward(rays, sky, g, {}, false);
    for (int k = 0; k < kShCount; ++k) EXPECT_EQ(grads.env.c[k].x, 0.0f) << k;
}

}  // namespace
}  // namespace lumigauss

namespace lumigauss {
namespace {

TEST(GroundBackdrop, TrainingDrawsTheGroundOfItsCurrentSurfels) {
    TrainConfig c = trainer_test::shrunk_config();
    c.sky_background = true;
    c.sky_horizon_start = 4, c.sky_horizon_fade = 4;
    Trainer off = trainer_test::make_trainer(c);
    EXPECT_EQ(off.sky_horizon().ground_albedo.x, 0.0f);
    c.ground_backdrop = true;
    Trainer on = trainer_test::make_trainer(c);
    const SkyHorizon h = on.sky_horizon();
    const Vec3f expected = ground_albedo(on.state().model, h.up);
    EXPECT_GT(expected.x, 0.0f);
    EXPECT_EQ(h.ground_albedo.x, expected.x);
    EXPECT_EQ(h.ground_albedo.y, expected.y);
    // With object masks the outside of the object is empty space: no ground.
    c.mask_mode = "object";
    EXPECT_EQ(trainer_test::make_trainer(c).sky_horizon().ground_albedo.x, 0.0f);
}

}  // namespace
}  // namespace lumigauss
