// Ramamoorthi-Hanrahan irradiance, the cosine-lobe projection and the shadowed transfer dot product
// (shading/irradiance.h).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "fast/sh_test_util.h"
#include "lumigauss/shading/irradiance.h"

namespace lumigauss {
namespace {

using sh_test::fd_gradient;
using sh_test::fd_gradient_sh;

constexpr double kPi = std::numbers::pi;

// Calls f(direction, solid angle) over a midpoint (theta, phi) grid with exact cell areas.
template <typename F>
void integrate_sphere(int width, int height, F&& f) {
    for (int i = 0; i < height; ++i) {
        const double theta = kPi * (i + 0.5) / height, half = kPi / (2 * height);
        const double d_omega = (2 * kPi / width) * (std::cos(theta - half) - std::cos(theta + half));
        for (int j = 0; j < width; ++j) {
            const double phi = 2 * kPi * (j + 0.5) / width;
            f(Vec3d{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)},
              d_omega);
        }
    }
}

// Grace Cathedral (RH 2001 table, 2 decimals) and the irradiance oracle of
// research/nerfosr_protocol_and_data.md 3.4-3.5, printed to 6 decimals.
TEST(ShIrradiance, GraceCathedralOracle) {
    const ShCoeffs<double> grace{{{0.79, 0.44, 0.54},
                                  {0.39, 0.35, 0.60},
                                  {-0.34, -0.18, -0.27},
                                  {-0.29, -0.06, 0.01},
                                  {-0.11, -0.05, -0.12},
                                  {-0.26, -0.22, -0.47},
                                  {-0.16, -0.09, -0.15},
                                  {0.56, 0.21, 0.14},
                                  {0.21, -0.05, -0.30}}};
    const double s = 1 / std::sqrt(3.0);
    const struct {
        Vec3d n, e;
    } oracle[] = {
        {{0, 0, 1}, {0.272921, 0.161153, 0.127951}}, {{0, 0, -1}, {0.968784, 0.529551, 0.680549}},
        {{1, 0, 0}, {0.533087, 0.329382, 0.397239}}, {{-1, 0, 0}, {1.126617, 0.452181, 0.376773}},
        {{0, 1, 0}, {1.048752, 0.791851, 1.258428}}, {{0, -1, 0}, {0.250556, 0.075521, 0.030435}},
        {{s, s, s}, {0.612668, 0.437768, 0.550728}},
    };
    for (const auto& row : oracle) {
        const Vec3d e = irradiance(grace, row.n);
        // 6 printed decimals plus the oracle's stated <= 1e-6 agreement.
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(e[c], row.e[c], 2e-6) << "n=(" << row.n.x << "," << row.n.y << "," << row.n.z << ")";
        const Vec3f ef = irradiance(grace.cast<float>(), row.n.cast<float>());
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(ef[c], row.e[c], 5e-6);
    }
}

TEST(ShIrradiance, ConstantsAreTheOfficialOnesToTheirPrecision) {
    using namespace rh_const;
    EXPECT_NEAR(kC1, 0.429043, 1e-6);
    EXPECT_NEAR(kC2, 0.511664, 1e-6);
    EXPECT_NEAR(kC3, 0.743125, 1.5e-6);
    EXPECT_NEAR(kC4, 0.886227, 1e-6);
    EXPECT_NEAR(kC5, 0.247708, 1e-6);
}

// A uniform sky of radiance R gives E = pi R for every normal (no 1/pi in E).
TEST(ShIrradiance, UniformSkyGivesPiTimesRadiance) {
    const double radiance = 0.7;
    ShCoeffs<double> sh;
    sh.c[0] = Vec3d{1, 1, 1} * (radiance * 4 * kPi * sh_const::kY00);  // projection of the constant
    std::mt19937_64 rng(10);
    for (int t = 0; t < 10; ++t)
        EXPECT_NEAR(irradiance(sh, sh_test::random_unit(rng)).y, kPi * radiance, 1e-12);
}

TEST(ShIrradiance, EqualsDotWithCosineLobe) {
    std::mt19937_64 rng(11);
    for (int trial = 0; trial < 200; ++trial) {
        const ShCoeffs<double> env = sh_test::random_sh(rng);
        const Vec3d n = sh_test::random_unit(rng);
        double lobe[kShCount];
        cosine_lobe_sh(n, lobe);
        const Vec3d e = irradiance(env, n), s = shadowed_radiance(lobe, env);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], s[c], 1e-13);
    }
}

// The cosine lobe's SH coefficients are its projection: integral of max(0, n.w) Y_k(w) dw.
TEST(ShIrradiance, CosineLobeIsTheProjectionOfTheClampedCosine) {
    std::mt19937_64 rng(12);
    for (int trial = 0; trial < 3; ++trial) {
        const Vec3d n = sh_test::random_unit(rng);
        double numeric[kShCount]{};
        integrate_sphere(1024, 512, [&](Vec3d w, double d_omega) {
            double y[kShCount];
            sh_basis(w, y);
            const double cosine = std::fmax(0.0, dot(n, w));
            for (int k = 0; k < kShCount; ++k) numeric[k] += cosine * y[k] * d_omega;
        });
        double lobe[kShCount];
        cosine_lobe_sh(n, lobe);
        for (int k = 0; k < kShCount; ++k) EXPECT_NEAR(lobe[k], numeric[k], 1e-4) << "k=" << k;
    }
}

// For an environment of degree <= 2, the RH formula is the exact cosine integral.
TEST(ShIrradiance, MatchesBruteForceCosineIntegral) {
    std::mt19937_64 rng(13);
    for (int trial = 0; trial < 3; ++trial) {
        const ShCoeffs<double> env = sh_test::random_sh(rng);
        Vec3d normals[8];
        for (Vec3d& n : normals) n = sh_test::random_unit(rng);
        Vec3d numeric[8]{};
        integrate_sphere(1024, 512, [&](Vec3d w, double d_omega) {
            const Vec3d radiance = eval_sh(env, w);
            for (int i = 0; i < 8; ++i)
                numeric[i] += (std::fmax(0.0, dot(normals[i], w)) * d_omega) * radiance;
        });
        for (int i = 0; i < 8; ++i) {
            const Vec3d e = irradiance(env, normals[i]);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(e[c], numeric[i][c], 1e-3) << "trial " << trial << " n " << i;
        }
    }
}

TEST(ShIrradiance, VjpsMatchFiniteDifferences) {
    std::mt19937_64 rng(14);
    for (int trial = 0; trial < 50; ++trial) {
        const ShCoeffs<double> env = sh_test::random_sh(rng);
        const Vec3d n = sh_test::random_vec(rng), g_out = sh_test::random_vec(rng);
        const Vec3d want_n = fd_gradient([&](Vec3d p) { return dot(g_out, irradiance(env, p)); }, n);
        const Vec3d got_n = irradiance_vjp_normal(env, n, g_out);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(got_n[i], want_n[i], 1e-8);

        const ShCoeffs<double> want =
            fd_gradient_sh([&](const ShCoeffs<double>& s) { return dot(g_out, irradiance(s, n)); }, env);
        ShCoeffs<double> got = sh_test::random_sh(rng);
        const ShCoeffs<double> before = got;
        irradiance_vjp_coeffs(n, g_out, got);
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got.c[k][c] - before.c[k][c], want.c[k][c], 1e-8);
    }
}

// The renderers run these in float: every function instantiated in float agrees with double.
TEST(ShIrradiance, FloatAgreesWithDouble) {
    std::mt19937_64 rng(16);
    const auto near_vec = [](Vec3f f, Vec3d d, double tol) {
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(f[i], d[i], tol);
    };
    for (int trial = 0; trial < 50; ++trial) {
        const ShCoeffs<double> env = sh_test::random_sh(rng);
        const ShCoeffs<float> envf = env.cast<float>();
        const Vec3d n = sh_test::random_unit(rng), g = sh_test::random_vec(rng);
        const Vec3f nf = n.cast<float>(), gf = g.cast<float>();
        near_vec(irradiance(envf, nf), irradiance(env, n), 1e-5);
        near_vec(irradiance_vjp_normal(envf, nf, gf), irradiance_vjp_normal(env, n, g), 1e-5);

        double lobe[kShCount], basis_g[kShCount];
        float lobef[kShCount], basis_gf[kShCount];
        cosine_lobe_sh(n, lobe);
        cosine_lobe_sh(nf, lobef);
        for (int k = 0; k < kShCount; ++k) {
            EXPECT_NEAR(lobef[k], lobe[k], 1e-6);
            basis_g[k] = sh_test::uniform(rng);
            basis_gf[k] = static_cast<float>(basis_g[k]);
        }
        near_vec(sh_basis_vjp(nf, basis_gf), sh_basis_vjp(n, basis_g), 1e-5);
        near_vec(shadowed_radiance(lobef, envf), shadowed_radiance(lobe, env), 1e-5);

        ShCoeffs<double> g_env;
        ShCoeffs<float> g_envf;
        double g_t[kShCount] = {};
        float g_tf[kShCount] = {};
        shadowed_radiance_vjp(lobe, env, g, g_t, g_env);
        shadowed_radiance_vjp(lobef, envf, gf, g_tf, g_envf);
        irradiance_vjp_coeffs(n, g, g_env);
        irradiance_vjp_coeffs(nf, gf, g_envf);
        EXPECT_LT(sh_test::max_abs_diff(g_envf.cast<double>(), g_env), 1e-5);
        for (int k = 0; k < kShCount; ++k) EXPECT_NEAR(g_tf[k], g_t[k], 1e-5);
    }
}

TEST(ShShadowed, IsTheTransferDotProductPerChannel) {
    const double transfer[kShCount] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    ShCoeffs<double> env;
    for (int k = 0; k < kShCount; ++k) env.c[k] = {1.0, k == 4 ? 1.0 : 0.0, -0.5};
    const Vec3d s = shadowed_radiance(transfer, env);
    EXPECT_DOUBLE_EQ(s.x, 45.0);
    EXPECT_DOUBLE_EQ(s.y, 5.0);
    EXPECT_DOUBLE_EQ(s.z, -22.5);
}

TEST(ShShadowed, VjpMatchesFiniteDifferences) {
    std::mt19937_64 rng(15);
    for (int trial = 0; trial < 50; ++trial) {
        const ShCoeffs<double> env = sh_test::random_sh(rng);
        const Vec3d g_out = sh_test::random_vec(rng);
        double transfer[kShCount];
        for (double& t : transfer) t = sh_test::uniform(rng);

        double g_transfer[kShCount] = {};
        ShCoeffs<double> g_env;
        shadowed_radiance_vjp(transfer, env, g_out, g_transfer, g_env);

        const ShCoeffs<double> want_env = fd_gradient_sh(
            [&](const ShCoeffs<double>& s) { return dot(g_out, shadowed_radiance(transfer, s)); }, env);
        EXPECT_LT(sh_test::max_abs_diff(g_env, want_env), 1e-8);
        for (int k = 0; k < kShCount; ++k) {
            const double eps = 1e-6, keep = transfer[k];
            transfer[k] = keep + eps;
            const double hi = dot(g_out, shadowed_radiance(transfer, env));
            transfer[k] = keep - eps;
            const double lo = dot(g_out, shadowed_radiance(transfer, env));
            transfer[k] = keep;
            EXPECT_NEAR(g_transfer[k], (hi - lo) / (2 * eps), 1e-8);
        }
    }
}

}  // namespace
}  // namespace lumigauss
