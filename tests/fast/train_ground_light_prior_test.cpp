// The prior that the light below the horizon is the ground's reflection (train/ground_light_prior.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "lumigauss/shading/irradiance.h"
#include "lumigauss/train/ground_light_prior.h"

namespace lumigauss {
namespace {

TEST(GroundLightPrior, DirectionsAreUnitAndBelowTheHorizon) {
    const Vec3d up = normalize(Vec3d{0.2, -0.1, 1.0});
    Vec3d dirs[kGroundLightDirections];
    ground_light_directions(up, dirs);
    EXPECT_NEAR(dot(dirs[0], up), -1.0, 1e-12);
    int at30 = 0, at60 = 0;
    for (const Vec3d& d : dirs) {
        EXPECT_NEAR(length(d), 1.0, 1e-12);
        const double below = -std::asin(dot(d, up)) * 180 / std::numbers::pi;
        at30 += std::abs(below - 30) < 1e-9, at60 += std::abs(below - 60) < 1e-9;
    }
    EXPECT_EQ(at30, 8);
    EXPECT_EQ(at60, 8);
}

TEST(GroundLightPrior, KnownAnswerForAConstantLight) {
    // Radiance L in every direction: E(up) = pi L, the ground's radiance r pi L, so each of the 17 directions
    // differs by L (1 - r pi) per channel; dl/dL_00 = 2 (1 - r pi) L Y00 / 3 per channel, times the weight
    // (the target held fixed).
    const Vec3d radiance{0.5, 1.0, 2.0};
    const Vec3d reflectance{0.05, 0.1, 0.2};
    ShCoeffs<float> env;
    env.c[0] = (radiance / sh_const::kY00).cast<float>();
    ShCoeffs<float> g;
    const double weight = 3.0;
    const double loss = ground_light_prior(env, Vec3f{0, 0, 1}, reflectance, weight, g);
    double expect = 0;
    for (int c = 0; c < 3; ++c) {
        const double d = radiance[c] * (1 - reflectance[c] * std::numbers::pi);
        expect += d * d / 3;
        EXPECT_NEAR(g.c[0][c], weight * 2 * d / 3 * sh_const::kY00, 1e-5 * std::abs(d)) << c;
    }
    EXPECT_NEAR(loss, expect, 1e-6 * expect);
}

TEST(GroundLightPrior, ReflectanceOfTheModelsGroundOrAnAssumedAlbedo) {
    // The model's own: albedo^2.2 (the display albedo holds the 1/pi).
    const Vec3f albedo{0.5f, 0.7f, 0.3f};
    const Vec3d own = ground_reflectance(albedo, 0.0);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(own[c], std::pow(double(albedo[c]), 2.2), 1e-6) << c;
    // Assumed: rho / pi on average over the channels, in the colour of the model's ground, whatever its
    // level (the gauge between albedo and light).
    const double rho = 0.2;
    const Vec3d assumed = ground_reflectance(albedo, rho);
    const Vec3d dimmer = ground_reflectance(albedo * 0.5f, rho);
    EXPECT_NEAR((assumed.x + assumed.y + assumed.z) / 3, rho / std::numbers::pi, 1e-12);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(assumed[c] / assumed.y, own[c] / own.y, 1e-9) << c;
        EXPECT_NEAR(dimmer[c], assumed[c], 1e-9) << c;
    }
    // Without a ground: nothing of its own, grey when assumed.
    const Vec3d none = ground_reflectance(Vec3f{0, 0, 0}, 0.0);
    const Vec3d grey = ground_reflectance(Vec3f{0, 0, 0}, rho);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(none[c], 0.0) << c;
        EXPECT_NEAR(grey[c], rho / std::numbers::pi, 1e-12) << c;
    }
}

TEST(GroundLightPrior, GradientMatchesFiniteDifferencesWithTheTargetHeld) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    ShCoeffs<double> env;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) env.c[k][c] = u(rng) + (k == 0 ? 2.0 : 0.0);
    const Vec3f up = normalize(Vec3f{0.1f, 0.3f, 1.0f});
    const Vec3d reflectance{0.01, 0.015, 0.03};
    ShCoeffs<float> g;
    ground_light_prior(env.cast<float>(), up, reflectance, 1.0, g);
    // The loss with the target fixed at the unperturbed light's ground radiance.
    const Vec3d e_up = irradiance(env, up.cast<double>());
    Vec3d dirs[kGroundLightDirections];
    ground_light_directions(up.cast<double>(), dirs);
    const auto loss_at = [&](const ShCoeffs<double>& l) {
        double s = 0;
        for (const Vec3d& d : dirs) {
            const Vec3d v = eval_sh(l, d);
            for (int c = 0; c < 3; ++c) {
                const double diff = v[c] - reflectance[c] * e_up[c];
                s += diff * diff / (3.0 * kGroundLightDirections);
            }
        }
        return s;
    };
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) {
            ShCoeffs<double> p = env, m = env;
            const double h = 1e-6;
            p.c[k][c] += h, m.c[k][c] -= h;
            const double numeric = (loss_at(p) - loss_at(m)) / (2 * h);
            EXPECT_NEAR(g.c[k][c], numeric, 1e-4 * std::max(1.0, std::abs(numeric))) << k << " " << c;
        }
}

TEST(GroundLightPrior, NothingWithoutAGround) {
    ShCoeffs<float> env;
    env.c[0] = {1, 1, 1};
    ShCoeffs<float> g;
    EXPECT_EQ(ground_light_prior(env, Vec3f{0, 0, 1}, Vec3d{0, 0, 0}, 1.0, g), 0.0);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(g.c[k][c], 0.0f) << k;
}

}  // namespace
}  // namespace lumigauss
