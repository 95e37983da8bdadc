// What a photo's shading can tell about its light (eval/light_reference.h): the light recovered exactly when
// the normals cover the sphere, the six directions up and level normals see (and the xz, yz lobes they do
// not), cast shadows dropped from the fit, and the error for a photo without usable pixels.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "lumigauss/eval/light_reference.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

ShCoeffs<double> some_light() {
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    ShCoeffs<double> l;
    for (int j = 0; j < kShCount; ++j) l.c[j] = {u(rng), u(rng), u(rng)};
    l.c[0] = l.c[0] + Vec3d{3, 2.5, 2};
    return l;
}

// A Lambertian sample lit by `light` (no shadow), albedo varying with the index.
ShadingSample lit_sample(const Vec3d& n, const ShCoeffs<double>& light, std::size_t i) {
    ShadingSample s;
    s.normal = (1.0 / length(n)) * n;
    s.albedo = {0.2 + 0.05 * double(i % 7), 0.3 + 0.04 * double(i % 5), 0.6 - 0.05 * double(i % 3)};
    const Vec3d e = irradiance(light, s.normal);
    for (int c = 0; c < 3; ++c) s.radiance[c] = s.albedo[c] / std::numbers::pi * e[c];
    return s;
}

// Fibonacci points on the sphere.
std::vector<Vec3d> sphere_normals(int count) {
    std::vector<Vec3d> out;
    const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
        const double z = 1 - 2 * (i + 0.5) / count, r = std::sqrt(1 - z * z);
        out.push_back({r * std::cos(golden * i), r * std::sin(golden * i), z});
    }
    return out;
}

// The ground and upright walls around it: every normal up or level.
std::vector<Vec3d> up_and_level_normals() {
    std::vector<Vec3d> out(40, Vec3d{0, 0, 1});
    for (int i = 0; i < 24; ++i) out.push_back({std::cos(0.3 + i * 0.26), std::sin(0.3 + i * 0.26), 0});
    return out;
}

void expect_light_near(const ShCoeffs<double>& a, const ShCoeffs<double>& b, double tolerance) {
    for (int j = 0; j < kShCount; ++j)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.c[j][c], b.c[j][c], tolerance) << j << " " << c;
}

TEST(LightReference, NormalsOverTheSphereSeeTheWholeLight) {
    const ShCoeffs<double> light = some_light();
    std::vector<ShadingSample> samples;
    for (const Vec3d& n : sphere_normals(300)) samples.push_back(lit_sample(n, light, samples.size()));
    const PhotoLightReference ref = fit_photo_light_reference(samples);
    EXPECT_EQ(ref.seen_count, 9);
    expect_light_near(ref.light, light, 1e-9);
    expect_light_near(project_light(ref.seen, light), light, 1e-9);
}

TEST(LightReference, UpAndLevelNormalsSeeSixDirectionsAndNotTheXzYzLobes) {
    const ShCoeffs<double> light = some_light();
    std::vector<ShadingSample> samples;
    for (const Vec3d& n : up_and_level_normals()) samples.push_back(lit_sample(n, light, samples.size()));
    const PhotoLightReference ref = fit_photo_light_reference(samples);
    // Level normals: a constant, cos and sin of the azimuth and of twice it; the up normal one more mix.
    EXPECT_EQ(ref.seen_count, 6);
    ShCoeffs<double> lobes;  // yz and xz: zero on every up or level normal
    lobes.c[5] = {1, 2, 3};
    lobes.c[7] = {-2, 1, 0.5};
    expect_light_near(project_light(ref.seen, lobes), ShCoeffs<double>{}, 1e-9);
    ShCoeffs<double> dipole;  // the level dipoles are seen whole
    dipole.c[1] = {1, 0, 0};
    dipole.c[3] = {0, 2, 0};
    expect_light_near(project_light(ref.seen, dipole), dipole, 1e-9);
    // The fit is the seen part of the light, which shades every sample as the whole light does.
    expect_light_near(ref.light, project_light(ref.seen, light), 1e-9);
    for (const ShadingSample& s : samples)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(irradiance(ref.light, s.normal)[c], irradiance(light, s.normal)[c], 1e-9);
}

TEST(LightReference, CastShadowsAreLeftOutOfTheFit) {
    const ShCoeffs<double> light = some_light();
    std::vector<ShadingSample> samples;
    for (const Vec3d& n : sphere_normals(400)) {
        ShadingSample s = lit_sample(n, light, samples.size());
        if (samples.size() % 4 == 1) s.radiance = 0.15 * s.radiance;  // a quarter in shadow
        samples.push_back(s);
    }
    expect_light_near(fit_photo_light_reference(samples).light, light, 1e-9);
}

TEST(LightReference, NoSampleIsAnError) {
    EXPECT_THROW(fit_photo_light_reference({}), Error);
}

}  // namespace
}  // namespace lumigauss
