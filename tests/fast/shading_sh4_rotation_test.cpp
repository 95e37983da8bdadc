// The degree-4 rotation (shading/sh4_rotation.h): the turned SH shows in direction w what the old one showed
// in R^T w, its bands 0-2 are the degree-2 rotation's (sh_rotation.h), and no turn changes nothing.
#include <gtest/gtest.h>

#include <random>

#include "lumigauss/shading/sh4_rotation.h"
#include "lumigauss/shading/sh_rotation.h"

namespace lumigauss {
namespace {

Vec3d evaluate(const Sh4Coeffs<float>& sh, Vec3d dir) {
    double y[kSh4Count];
    sh4_basis(dir, y);
    Vec3d sum{};
    for (int k = 0; k < kSh4Count; ++k) sum += y[k] * sh.c[k].cast<double>();
    return sum;
}

Sh4Coeffs<float> random_sh4(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1, 1);
    Sh4Coeffs<float> sh;
    for (auto& c : sh.c) c = {u(rng), u(rng), u(rng)};
    return sh;
}

Vec3d random_direction(std::mt19937& rng) {
    std::normal_distribution<double> n;
    return normalize(Vec3d{n(rng), n(rng), n(rng)});
}

TEST(Sh4Rotation, TheTurnedSkyShowsInWWhatTheOldShowedInRTransposeW) {
    std::mt19937 rng(11);
    for (int trial = 0; trial < 5; ++trial) {
        const Sh4Coeffs<float> sh = random_sh4(rng);
        const Mat3d r = rotation_about_axis(random_direction(rng), 0.3 + trial);
        const Sh4Coeffs<float> turned = rotate_sh4(sh, r);
        for (int i = 0; i < 20; ++i) {
            const Vec3d w = random_direction(rng);
            const Vec3d want = evaluate(sh, transpose(r) * w), got = evaluate(turned, w);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-4) << "trial " << trial;
        }
    }
}

TEST(Sh4Rotation, BandsZeroToTwoAreTheDegreeTwoRotation) {
    std::mt19937 rng(12);
    const Sh4Coeffs<float> sh = random_sh4(rng);
    const Mat3d r = rotation_about_axis(Vec3d{0, 0, 1}, 0.7);
    ShCoeffs<double> low;
    for (int k = 0; k < kShCount; ++k) low.c[k] = sh.c[k].cast<double>();
    const ShCoeffs<double> want = rotate_sh(low, r);
    const Sh4Coeffs<float> turned = rotate_sh4(sh, r);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(turned.c[k][c], want.c[k][c], 1e-5) << k;
    const Sh4Coeffs<float> same = rotate_sh4(sh, rotation_about_axis(Vec3d{1, 0, 0}, 0.0));
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(same.c[k][c], sh.c[k][c], 1e-5) << k;
}

}  // namespace
}  // namespace lumigauss
