// Degree-2 real SH basis (shading/sh.h): values, orthonormality, VJPs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fast/sh_test_util.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {
namespace {

using namespace sh_const;
using sh_test::fd_gradient;
using sh_test::fd_gradient_sh;

constexpr double kPi = std::numbers::pi;

TEST(ShBasis, ConstantsAreTheDesignLiteralsAtFullPrecision) {
    EXPECT_NEAR(kY00, 0.282095, 1e-6);
    EXPECT_NEAR(kY1, 0.488603, 1e-6);
    EXPECT_NEAR(kY2, 1.092548, 1e-6);
    EXPECT_NEAR(kY20, 0.315392, 1e-6);
    EXPECT_NEAR(kY22, 0.546274, 1e-6);
    EXPECT_DOUBLE_EQ(kY00, 0.5 / std::sqrt(kPi));
    EXPECT_DOUBLE_EQ(kY20, std::sqrt(5.0) / (4 * std::sqrt(kPi)));
}

TEST(ShBasis, ValuesAtAxes) {
    const auto expect_basis = [](Vec3d dir, const double(&want)[kShCount]) {
        double y[kShCount];
        sh_basis(dir, y);
        for (int k = 0; k < kShCount; ++k) EXPECT_NEAR(y[k], want[k], 1e-15) << "k=" << k;
    };
    // Order (0,0),(1,-1),(1,0),(1,1),(2,-2),(2,-1),(2,0),(2,1),(2,2): y, z, x in band 1.
    expect_basis({1, 0, 0}, {kY00, 0, 0, kY1, 0, 0, -kY20, 0, kY22});
    expect_basis({0, 1, 0}, {kY00, kY1, 0, 0, 0, 0, -kY20, 0, -kY22});
    expect_basis({0, 0, 1}, {kY00, 0, kY1, 0, 0, 0, 2 * kY20, 0, 0});
    expect_basis({0, 0, -1}, {kY00, 0, -kY1, 0, 0, 0, 2 * kY20, 0, 0});
    const double h = std::sqrt(0.5);
    expect_basis({h, h, 0}, {kY00, kY1 * h, 0, kY1 * h, kY2 / 2, 0, -kY20, 0, 0});
    expect_basis({0, h, h}, {kY00, kY1 * h, kY1 * h, 0, 0, kY2 / 2, kY20 / 2, 0, -kY22 / 2});
    expect_basis({h, 0, h}, {kY00, 0, kY1 * h, kY1 * h, 0, 0, kY20 / 2, kY2 / 2, kY22 / 2});
}

// Integral of Y_i Y_j over the sphere by a midpoint rule in (theta, phi) with exact cell areas.
TEST(ShBasis, OrthonormalByQuadrature) {
    constexpr int kW = 1024, kH = 512;
    double gram[kShCount][kShCount]{};
    for (int i = 0; i < kH; ++i) {
        const double theta = kPi * (i + 0.5) / kH, half = kPi / (2 * kH);
        const double d_omega = (2 * kPi / kW) * (std::cos(theta - half) - std::cos(theta + half));
        for (int j = 0; j < kW; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / kW;
            double y[kShCount];
            sh_basis(Vec3d{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)},
                     y);
            for (int a = 0; a < kShCount; ++a)
                for (int b = 0; b < kShCount; ++b) gram[a][b] += y[a] * y[b] * d_omega;
        }
    }
    for (int a = 0; a < kShCount; ++a)
        for (int b = 0; b < kShCount; ++b) EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 1e-4) << a << "," << b;
}

TEST(ShBasis, EvalIsTheCoefficientWeightedBasis) {
    std::mt19937_64 rng(1);
    const ShCoeffs<double> sh = sh_test::random_sh(rng);
    const Vec3d d = sh_test::random_unit(rng);
    double y[kShCount];
    sh_basis(d, y);
    Vec3d want{};
    for (int k = 0; k < kShCount; ++k) want += y[k] * sh.c[k];
    const Vec3d got = eval_sh(sh, d);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-15);
}

TEST(ShBasis, BasisVjpMatchesFiniteDifferences) {
    std::mt19937_64 rng(2);
    for (int trial = 0; trial < 50; ++trial) {
        double g[kShCount];
        for (double& v : g) v = sh_test::uniform(rng);
        const Vec3d d = sh_test::random_vec(rng);  // the VJP is of the polynomial, on or off the sphere
        const auto loss = [&](Vec3d p) {
            double y[kShCount], s = 0;
            sh_basis(p, y);
            for (int k = 0; k < kShCount; ++k) s += g[k] * y[k];
            return s;
        };
        const Vec3d want = fd_gradient(loss, d), got = sh_basis_vjp(d, g);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], 1e-8) << "trial " << trial;
    }
}

TEST(ShBasis, EvalShVjpsMatchFiniteDifferences) {
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 50; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const Vec3d d = sh_test::random_unit(rng), g_out = sh_test::random_vec(rng);
        const Vec3d want_dir = fd_gradient([&](Vec3d p) { return dot(g_out, eval_sh(sh, p)); }, d);
        const Vec3d got_dir = eval_sh_vjp_dir(sh, d, g_out);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(got_dir[i], want_dir[i], 1e-8);

        const ShCoeffs<double> want =
            fd_gradient_sh([&](const ShCoeffs<double>& s) { return dot(g_out, eval_sh(s, d)); }, sh);
        ShCoeffs<double> got = sh_test::random_sh(rng);  // accumulates: start from something non-zero
        const ShCoeffs<double> before = got;
        eval_sh_vjp_coeffs(d, g_out, got);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got.c[k][c] - before.c[k][c], want.c[k][c], 1e-8);
    }
}

TEST(ShBasis, FloatAgreesWithDouble) {
    std::mt19937_64 rng(4);
    for (int trial = 0; trial < 100; ++trial) {
        const ShCoeffs<double> sh = sh_test::random_sh(rng);
        const Vec3d d = sh_test::random_unit(rng);
        const Vec3d want = eval_sh(sh, d);
        const Vec3f got = eval_sh(sh.cast<float>(), d.cast<float>());
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5);
    }
}

}  // namespace
}  // namespace lumigauss
