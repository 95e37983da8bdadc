// The sky behind the surfels: the degree-4 basis (orthonormal, bands 0-2 equal to sh.h's), the display
// transform and its derivative, pixel rays, and the sky's backward against finite differences in double.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh_degree4.h"
#include "lumigauss/shading/sky_colour.h"
#include "lumigauss/shading/sky_image.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

TEST(ShDegree4, BasisIsOrthonormalOnTheSphere) {
    // Midpoint quadrature over (theta, phi): exact enough for polynomials of degree 8 at this resolution.
    const int rows = 400, cols = 800;
    double gram[kSh4Count][kSh4Count] = {};
    for (int i = 0; i < rows; ++i) {
        const double theta = std::numbers::pi * (i + 0.5) / rows;
        const double w = std::sin(theta) * (std::numbers::pi / rows) * (2 * std::numbers::pi / cols);
        for (int j = 0; j < cols; ++j) {
            const double phi = 2 * std::numbers::pi * (j + 0.5) / cols;
            const Vec3d d{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
            double y[kSh4Count];
            sh4_basis(d, y);
            for (int a = 0; a < kSh4Count; ++a)
                for (int b = 0; b < kSh4Count; ++b) gram[a][b] += w * y[a] * y[b];
        }
    }
    for (int a = 0; a < kSh4Count; ++a)
        for (int b = 0; b < kSh4Count; ++b)
            EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-4) << a << "," << b;
}

TEST(ShDegree4, FirstNineAreTheDegreeTwoBasis) {
    const Vec3d d = (1.0 / length(Vec3d{0.3, -0.5, 0.81})) * Vec3d{0.3, -0.5, 0.81};
    double y4[kSh4Count], y2[kShCount];
    sh4_basis(d, y4);
    sh_basis(d, y2);
    for (int k = 0; k < kShCount; ++k) EXPECT_DOUBLE_EQ(y4[k], y2[k]);
}

TEST(SkyColour, DisplayTransformFloorsAndClips) {
    EXPECT_NEAR(sky_channel(0.25), std::pow(0.25, 1 / 2.2), 1e-12);
    EXPECT_NEAR(sky_channel(-3.0), std::pow(kSkyRadianceFloor, 1 / 2.2), 1e-12);
    EXPECT_EQ(sky_channel(4.0), 1.0);
    EXPECT_EQ(sky_channel_derivative(-1.0), 0.0);
    EXPECT_EQ(sky_channel_derivative(2.0), 0.0);
    const double h = 1e-7;
    EXPECT_NEAR(sky_channel_derivative(0.3), (sky_channel(0.3 + h) - sky_channel(0.3 - h)) / (2 * h), 1e-6);
}

TEST(SkyColour, ResidualAddsToTheEnvironment) {
    ShCoeffs<double> env;
    env.c[0] = {0.8, 0.9, 1.0}, env.c[2] = {0.2, 0.1, 0.0};
    Sh4Coeffs<double> residual;
    residual.c[0] = {0.1, 0.0, -0.1}, residual.c[12] = {0.05, 0.05, 0.05};  // a band-0 and a band-3 term
    const Vec3d up{0, 0, 1};
    double y[kSh4Count];
    sh4_basis(up, y);
    const Vec3d r = sky_radiance(env, &residual, up);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(r[c],
                    y[0] * (env.c[0][c] + residual.c[0][c]) + y[2] * env.c[2][c] + y[12] * residual.c[12][c],
                    1e-12);
    EXPECT_NEAR(sky_radiance<double>(env, nullptr, up).x, eval_sh(env, up).x, 1e-15);
}

TEST(SkyColour, VisibilityFadesBelowTheHorizon) {
    const double start = std::sin(4 * std::numbers::pi / 180), end = std::sin(8 * std::numbers::pi / 180);
    const auto at = [&](double degrees_below, Vec3d up = {0, 0, 1}) {
        const double a = -degrees_below * std::numbers::pi / 180;
        return sky_visibility(up, start, end, Vec3d{std::cos(a), 0, std::sin(a)});
    };
    EXPECT_EQ(at(-30), 1.0);  // above the horizon
    EXPECT_EQ(at(0), 1.0);
    EXPECT_EQ(at(4), 1.0);  // the fade starts
    EXPECT_NEAR(at(6), (end - std::sin(6 * std::numbers::pi / 180)) / (end - start), 1e-12);
    EXPECT_GT(at(6), 0.45);
    EXPECT_LT(at(6), 0.55);
    EXPECT_EQ(at(8.01), 0.0);  // gone
    EXPECT_EQ(at(90), 0.0);
    // Measured from the given up, not from +z: about -y (COLMAP's y down), a ray along +z is level.
    EXPECT_EQ(sky_visibility(Vec3d{0, -1, 0}, start, end, Vec3d{0, 0, 1}), 1.0);
    EXPECT_EQ(sky_visibility(Vec3d{0, -1, 0}, start, end, Vec3d{0, 1, 0}), 0.0);
}

TEST(SkyImage, NothingIsDrawnWhereTheHorizonHidesTheSky) {
    Camera cam;  // looking along world +x, level: the top half of the image is above the horizon
    cam.width = 8, cam.height = 64, cam.fx = cam.fy = 20, cam.cx = 4, cam.cy = 32;
    cam.rotation = Mat3d{{{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}};
    ShCoeffs<float> env;
    env.c[0] = {1.5f, 1.5f, 1.5f};  // bright in every direction, below the horizon too
    const Image open = sky_image(cam, env);
    const Image cut = sky_image(cam, env, nullptr, {{0, 0, 1}, 4, 4});
    for (int y = 0; y < cam.height; ++y) {
        const double below = -std::asin(pixel_ray_direction(cam, 4, y).z) * 180 / std::numbers::pi;
        SCOPED_TRACE(below);
        EXPECT_GT(open.at(4, y, 0), 0.5f);
        if (below <= 3.9) {
            EXPECT_FLOAT_EQ(cut.at(4, y, 0), open.at(4, y, 0));
        }
        if (below >= 8.1) {
            EXPECT_EQ(cut.at(4, y, 0), 0.0f);
        }
        if (below > 4.1 && below < 7.9) {
            EXPECT_GT(cut.at(4, y, 0), 0.0f);
            EXPECT_LT(cut.at(4, y, 0), open.at(4, y, 0));
        }
    }
    // No fade, no horizon: the default draws every direction.
    EXPECT_EQ(sky_image(cam, env, nullptr, {{0, 0, 1}, 4, 0}).pixels, open.pixels);
}

TEST(SkyImage, PixelRaysFollowTheCamera) {
    Camera cam;
    cam.width = 64, cam.height = 48, cam.fx = cam.fy = 50, cam.cx = 32, cam.cy = 24;
    // Camera looking along world +x, image y down = world -z (COLMAP: rows of R are the camera axes).
    cam.rotation = Mat3d{{{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}};
    const Vec3d centre = pixel_ray_direction(cam, 31.5, 23.5);
    EXPECT_NEAR(centre.x, 1, 1e-12);
    EXPECT_NEAR(centre.z, 0, 1e-12);
    EXPECT_GT(pixel_ray_direction(cam, 31.5, 0).z, 0.3);  // the top row looks up
    EXPECT_LT(pixel_ray_direction(cam, 31.5, 47).z, -0.3);
    const std::vector<Vec3f> rays = pixel_ray_directions(cam);
    ASSERT_EQ(rays.size(), 64u * 48u);
    const Vec3d r = pixel_ray_direction(cam, 5, 7);
    EXPECT_NEAR(rays[7 * 64 + 5].y, r.y, 1e-6);
    EXPECT_NEAR(length(rays[100].cast<double>()), 1.0, 1e-6);
}

void check_sky_backward(const SkyHorizon& horizon) {
    const Camera cam = testing::test_camera(9, 7);
    const std::vector<Vec3f> rays = pixel_ray_directions(cam);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    ShCoeffs<float> env;
    Sh4Coeffs<float> residual;
    for (auto& c : env.c) c = {float(0.1 * u(rng)), float(0.1 * u(rng)), float(0.1 * u(rng))};
    env.c[0] = {1.2f, 1.0f, 0.9f};  // positive but below the clip at 1 for most rays
    for (auto& c : residual.c) c = {float(0.05 * u(rng)), float(0.05 * u(rng)), float(0.05 * u(rng))};
    std::vector<float> wc(3 * rays.size()), wr(3 * rays.size());
    for (float& w : wc) w = float(u(rng));
    for (float& w : wr) w = float(u(rng));
    const auto loss = [&] {
        SkyPixels sky;
        sky_pixels(rays, env, &residual, sky, horizon);
        double l = 0;
        for (std::size_t i = 0; i < wc.size(); ++i)
            l += double(wc[i]) * sky.colour[i] + double(wr[i]) * sky.radiance[i];
        return l;
    };
    SkyPixels sky;
    sky_pixels(rays, env, &residual, sky, horizon);
    const SkyGrads g = sky_pixels_backward(rays, sky, wc, wr);
    const auto check = [&](float& x, float analytic, const char* what, int k) {
        const float x0 = x;
        const double h = 1e-2;  // float sky: rounding / h stays well under the tolerance
        x = float(x0 + h);
        const double lp = loss();
        x = float(x0 - h);
        const double lm = loss();
        x = x0;
        EXPECT_NEAR(analytic, (lp - lm) / (2 * h), 2e-3 * std::max(1.0, double(std::abs(analytic))))
            << what << " " << k;
    };
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) check(env.c[k][c], g.env.c[k][c], "env", k);
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) check(residual.c[k][c], g.residual.c[k][c], "residual", k);
}

TEST(SkyImage, BackwardMatchesFiniteDifferences) {
    check_sky_backward({});
}

TEST(SkyImage, BackwardMatchesFiniteDifferencesWithAHorizon) {
    // The test camera looks roughly along +z with y down: an up near -y puts the horizon across its view.
    const Camera cam = testing::test_camera(9, 7);
    const std::vector<Vec3f> rays = pixel_ray_directions(cam);
    const Vec3f up = normalize(Vec3f{0.0f, -1.0f, 0.25f});
    int faded = 0;
    SkyPixels sky;
    sky_pixels(rays, ShCoeffs<float>{}, nullptr, sky, {up, 2, 10});
    for (float v : sky.visibility) faded += v > 0 && v < 1;
    ASSERT_GT(faded, 5);  // the fade crosses the image, so its slope is checked
    check_sky_backward({up, 2, 10});
}

}  // namespace
}  // namespace lumigauss
