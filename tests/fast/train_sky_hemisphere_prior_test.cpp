// The prior on each photo's sky where its camera does not look (train/sky_hemisphere_prior.h): its
// directions, its target (known answers), its gradient (finite differences), and what it is for: a sky that
// a light leaves black away from the sun becomes the photo's sky colour there, also between its directions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/train/sky_hemisphere_prior.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

TEST(SkyHemispherePrior, DirectionsCoverTheUpperHemisphereEvenly) {
    for (const Vec3f up : {Vec3f{0, 0, 1}, Vec3f{0, -1, 0}, normalize(Vec3f{1, 2, -3})}) {
        const std::vector<Vec3f> dirs = upper_hemisphere_directions(up, 64);
        ASSERT_EQ(dirs.size(), 64u);
        Vec3f mean{};
        for (const Vec3f& d : dirs) {
            EXPECT_NEAR(length(d), 1.0f, 1e-5f);
            EXPECT_GT(dot(d, up), 0.0f);
            mean += (1.0f / 64) * d;
        }
        // Uniform over the hemisphere: the mean height is 1/2 and the mean points straight up.
        EXPECT_NEAR(dot(mean, up), 0.5f, 1e-3f);
        EXPECT_LT(length(mean - dot(mean, up) * up), 0.03f);
    }
    EXPECT_THROW(upper_hemisphere_directions({0, 0, 1}, 0), Error);
}

// The prior acts where the camera does not look: a direction inside the image is dropped, one outside it
// or behind the camera kept.
TEST(SkyHemispherePrior, KeepsOnlyTheDirectionsOutOfTheCamerasView) {
    Camera cam;  // looks along +z, 90 deg across: x/z and y/z in [-1, 1] are in the image
    cam.width = 100, cam.height = 100;
    cam.fx = cam.fy = 50, cam.cx = cam.cy = 50;
    cam.rotation = Mat3d::identity();
    const std::vector<Vec3f> dirs = {
        {0, 0, 1}, normalize(Vec3f{0.9f, -0.9f, 1}), normalize(Vec3f{1.2f, 0, 1}), {0, 0, -1}, {1, 0, 0}};
    const std::vector<Vec3f> out = directions_out_of_view(dirs, cam);
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[0].x, dirs[2].x);
    EXPECT_EQ(out[1].z, -1.0f);
    EXPECT_EQ(out[2].x, 1.0f);
    // Turned to look along -z, the camera sees the direction behind it before.
    cam.rotation = Mat3d{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};
    EXPECT_EQ(directions_out_of_view(std::vector<Vec3f>{{0, 0, -1}}, cam).size(), 0u);
}

TEST(SkyHemispherePrior, TargetIsTheMeanSkyColourAsRadiance) {
    // Four pixels: two sky pixels, a saturated sky pixel (the sun: left out), one ground pixel.
    const std::vector<float> photo = {0.4f, 0.5f,  0.6f, 0.6f, 0.7f, 0.8f,
                                      1.0f, 0.99f, 0.9f, 0.1f, 0.1f, 0.1f};
    const std::vector<float> sky = {1, 0.75f, 1, 0.25f};
    const std::optional<Vec3f> t = mean_sky_radiance(photo, sky, 2);
    ASSERT_TRUE(t.has_value());
    EXPECT_NEAR(t->x, std::pow(0.5, 2.2), 1e-6);
    EXPECT_NEAR(t->y, std::pow(0.6, 2.2), 1e-6);
    EXPECT_NEAR(t->z, std::pow(0.7, 2.2), 1e-6);
    EXPECT_FALSE(mean_sky_radiance(photo, sky, 3).has_value()) << "two usable pixels are fewer than three";
    EXPECT_FALSE(mean_sky_radiance(photo, std::vector<float>(4, 0.0f), 1).has_value());
    EXPECT_THROW(mean_sky_radiance(photo, std::vector<float>(3, 1.0f), 1), Error);
}

TEST(SkyHemispherePrior, GradientMatchesFiniteDifferences) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-0.4f, 0.4f);
    ShCoeffs<float> env{};
    for (auto& c : env.c) c = {u(rng), u(rng), u(rng)};
    Sh4Coeffs<float> residual{};
    for (auto& c : residual.c) c = {u(rng), u(rng), u(rng)};
    const Vec3f target{0.3f, 0.4f, 0.6f};
    const std::vector<Vec3f> dirs = upper_hemisphere_directions(normalize(Vec3f{0.2f, -1, 0.1f}), 64);
    const double weight = 2.5;
    Sh4Coeffs<float> g{};
    const double loss = sky_hemisphere_prior(dirs, env, residual, target, weight, g);
    EXPECT_GT(loss, 0.0);
    const double h = 1e-3;
    for (int k = 0; k < kSh4Count; ++k)
        for (int ch = 0; ch < 3; ++ch) {
            Sh4Coeffs<float> plus = residual, minus = residual;
            plus.c[k][ch] += float(h), minus.c[k][ch] -= float(h);
            Sh4Coeffs<float> unused{};
            const double numeric = weight *
                                   (sky_hemisphere_prior(dirs, env, plus, target, 0.0, unused) -
                                    sky_hemisphere_prior(dirs, env, minus, target, 0.0, unused)) /
                                   (2 * h);
            EXPECT_NEAR(g.c[k][ch], numeric, 2e-3 + 1e-2 * std::abs(numeric)) << "k " << k << " ch " << ch;
        }
    // The gradient is added to what the output holds.
    Sh4Coeffs<float> twice = g;
    sky_hemisphere_prior(dirs, env, residual, target, weight, twice);
    EXPECT_FLOAT_EQ(twice.c[3][1], 2 * g.c[3][1]);
}

// A light with a strong sun low in the sky, as a degree-2 SH draws it: bright towards the sun, below zero
// (drawn black) on the other side. Descending the prior alone, its residual turns the whole upper
// hemisphere into the photo's sky colour, also at directions between the prior's own.
TEST(SkyHemispherePrior, DescentTurnsABlackSkyIntoThePhotosSky) {
    const Vec3f up{0, 0, 1}, sun = normalize(Vec3f{1, 0, 0.3f});
    ShCoeffs<float> env{};
    float y[kShCount];
    sh_basis(sun, y);
    for (int k = 0; k < kShCount; ++k) env.c[k] = (3.0f * y[k]) * Vec3f{1, 0.9f, 0.8f};
    const Vec3f target{0.25f, 0.35f, 0.6f};
    const std::vector<Vec3f> probe = upper_hemisphere_directions(up, 401);  // none of them the prior's
    const auto black_share = [&](const Sh4Coeffs<float>& r) {
        int black = 0;
        for (const Vec3f& d : probe) {
            const Vec3f s{sky_channel(sky_radiance(env, &r, d).x), sky_channel(sky_radiance(env, &r, d).y),
                          sky_channel(sky_radiance(env, &r, d).z)};
            black += std::max({s.x, s.y, s.z}) < 0.1f ? 1 : 0;
        }
        return double(black) / double(probe.size());
    };
    Sh4Coeffs<float> residual{};
    ASSERT_GT(black_share(residual), 0.25) << "the sun's light must leave much of the sky black";
    const std::vector<Vec3f> dirs = upper_hemisphere_directions(up, kSkyHemisphereDirections);
    double first = 0, last = 0;
    for (int step = 0; step < 3000; ++step) {
        Sh4Coeffs<float> g{};
        last = sky_hemisphere_prior(dirs, env, residual, target, 1.0, g);
        if (step == 0) first = last;
        for (int k = 0; k < kSh4Count; ++k) residual.c[k] = residual.c[k] - 2.0f * g.c[k];
    }
    EXPECT_LT(last, 0.05 * first);
    EXPECT_EQ(black_share(residual), 0.0);
    // Between the prior's directions too, the sky is near the target.
    double error = 0;
    for (const Vec3f& d : probe) error += double(length(sky_radiance(env, &residual, d) - target));
    EXPECT_LT(error / double(probe.size()), 0.1);
}

}  // namespace
}  // namespace lumigauss
