// Rotation of degree-2 SH lighting (shading/sh_rotation.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fast/sh_test_util.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh_rotation.h"

namespace lumigauss {
namespace {

constexpr double kPi = std::numbers::pi;

void expect_vec_near(Vec3d a, Vec3d b, double tol) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol) << "component " << i;
}

TEST(ShRotation, AxisAngleIsRightHanded) {
    const Mat3d rz = rotation_about_axis(Vec3d{0, 0, 1}, kPi / 2);
    expect_vec_near(rz * Vec3d{1, 0, 0}, {0, 1, 0}, 1e-15);
    expect_vec_near(rz * Vec3d{0, 1, 0}, {-1, 0, 0}, 1e-15);
    // The y-down frame quoted in envmap.h.
    const Mat3d rx = rotation_about_axis(Vec3d{2, 0, 0}, kPi / 2);  // the axis need not be unit
    expect_vec_near(rx.col(0), {1, 0, 0}, 1e-15);
    expect_vec_near(rx.col(1), {0, 0, 1}, 1e-15);
    expect_vec_near(rx.col(2), {0, -1, 0}, 1e-15);
}

// f'(w) = f(R^T w) at 100 random directions, for random rotations.
TEST(ShRotation, RotatesTheFunction) {
    std::mt19937_64 rng(20);
    for (int trial = 0; trial < 20; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const Mat3d r = sh_test::random_rotation(rng);
        const ShCoeffs<double> rotated = rotate_sh(sh, r);
        for (int i = 0; i < 100; ++i) {
            const Vec3d w = sh_test::random_unit(rng);
            expect_vec_near(eval_sh(rotated, w), eval_sh(sh, transpose(r) * w), 1e-9);
        }
    }
}

// The SH of a (band-limited) light from direction s is Y(s); rotating it by R must give Y(R s).
TEST(ShRotation, MovesALightFromSToRS) {
    std::mt19937_64 rng(21);
    for (int trial = 0; trial < 20; ++trial) {
        const Vec3d s = sh_test::random_unit(rng);
        const Mat3d r = sh_test::random_rotation(rng);
        double y[kShCount], want[kShCount];
        sh_basis(s, y);
        sh_basis(r * s, want);
        ShCoeffs<double> light;
        for (int k = 0; k < kShCount; ++k) light.c[k] = {y[k], y[k], y[k]};
        const ShCoeffs<double> moved = rotate_sh(light, r);
        for (int k = 0; k < kShCount; ++k) EXPECT_NEAR(moved.c[k].x, want[k], 1e-12) << "k=" << k;
    }
    // Concretely: a quarter turn about +Z takes a light on +X to +Y.
    double on_x[kShCount], on_y[kShCount];
    sh_basis(Vec3d{1, 0, 0}, on_x);
    sh_basis(Vec3d{0, 1, 0}, on_y);
    ShCoeffs<double> light;
    for (int k = 0; k < kShCount; ++k) light.c[k] = {on_x[k], 0, 0};
    const ShCoeffs<double> moved = rotate_sh(light, rotation_about_axis(Vec3d{0, 0, 1}, kPi / 2));
    for (int k = 0; k < kShCount; ++k) EXPECT_NEAR(moved.c[k].x, on_y[k], 1e-15);
}

TEST(ShRotation, IdentityIsIdentity) {
    const ShRotation rot = sh_rotation(Mat3d::identity());
    for (int i = 0; i < kShCount; ++i)
        for (int j = 0; j < kShCount; ++j) EXPECT_NEAR(rot.m[i][j], i == j ? 1.0 : 0.0, 1e-15);
}

TEST(ShRotation, Composes) {
    std::mt19937_64 rng(22);
    for (int trial = 0; trial < 20; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const Mat3d a = sh_test::random_rotation(rng), b = sh_test::random_rotation(rng);
        // Rotating by B, then by A, is rotating by AB.
        EXPECT_LT(sh_test::max_abs_diff(rotate_sh(rotate_sh(sh, b), a), rotate_sh(sh, a * b)), 1e-12);
        // And R^T undoes R.
        EXPECT_LT(sh_test::max_abs_diff(rotate_sh(rotate_sh(sh, a), transpose(a)), sh), 1e-12);
    }
}

TEST(ShRotation, IsOrthogonal) {
    std::mt19937_64 rng(23);
    const ShRotation rot = sh_rotation(sh_test::random_rotation(rng));
    for (int i = 0; i < kShCount; ++i)
        for (int j = 0; j < kShCount; ++j) {
            double s = 0;
            for (int k = 0; k < kShCount; ++k) s += rot.m[i][k] * rot.m[j][k];
            EXPECT_NEAR(s, i == j ? 1.0 : 0.0, 1e-12);
        }
}

// Rotating the lighting and the normal together leaves the irradiance unchanged.
TEST(ShRotation, CommutesWithIrradiance) {
    std::mt19937_64 rng(24);
    for (int trial = 0; trial < 20; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const Mat3d r = sh_test::random_rotation(rng);
        const Vec3d n = sh_test::random_unit(rng);
        expect_vec_near(irradiance(rotate_sh(sh, r), r * n), irradiance(sh, n), 1e-12);
    }
}

}  // namespace
}  // namespace lumigauss
