// Per-surfel colour (both modes, two-sided transfer) and the transfer-function losses of
// shading/surfel_shading.h, with their VJPs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fast/sh_test_util.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {
namespace {

using sh_test::uniform;

constexpr double kFdEps = 1e-6;

// An environment whose irradiance is comfortably above the 1e-5 floor everywhere: a strong DC term.
ShCoeffs<double> bright_env(std::mt19937_64& rng) {
    ShCoeffs<double> env = sh_test::random_sh(rng);
    for (Vec3d& c : env.c) c = 0.2 * c;
    env.c[0] = env.c[0] + Vec3d{3.0, 3.0, 3.0};
    return env;
}

void random_transfer(std::mt19937_64& rng, double out[kShCount]) {
    for (int k = 0; k < kShCount; ++k) out[k] = 0.2 * uniform(rng);
    out[0] = 1.0 + 0.2 * uniform(rng);  // keeps the shadowed light well above the floor
}

// Raw albedo with activated values in (0.2, 0.8): away from the max(0, .) kink.
Vec3d random_albedo_raw(std::mt19937_64& rng) {
    Vec3d a;
    for (int c = 0; c < 3; ++c) a[c] = (uniform(rng, 0.2, 0.8) - 0.5) / sh_const::kY00;
    return a;
}

// A fixed weighted sum of the 6 channels, so that one scalar checks the whole VJP.
struct Scene {
    ShCoeffs<double> env;
    Vec3d albedo_raw, normal;
    double pos[kShCount], neg[kShCount];
    double w[kSurfelColourChannels];
    bool positive_side = true;

    double loss() const {
        double out[kSurfelColourChannels];
        surfel_colour_both(env, albedo_raw, normal, pos, neg, positive_side, out);
        double l = 0;
        for (int i = 0; i < kSurfelColourChannels; ++i) l += w[i] * out[i];
        return l;
    }
};

Scene random_scene(std::mt19937_64& rng, bool positive_side) {
    Scene s;
    s.env = bright_env(rng);
    s.albedo_raw = random_albedo_raw(rng);
    s.normal = sh_test::random_unit(rng);
    random_transfer(rng, s.pos);
    random_transfer(rng, s.neg);
    for (double& w : s.w) w = uniform(rng);
    s.positive_side = positive_side;
    return s;
}

// Central difference of Scene::loss w.r.t. the scalar that get(scene) refers to.
template <typename Get>
double fd_scalar(const Scene& s0, Get&& get) {
    Scene hi = s0, lo = s0;
    get(hi) += kFdEps;
    get(lo) -= kFdEps;
    return (hi.loss() - lo.loss()) / (2 * kFdEps);
}

TEST(ShadingSurfelColour, BothModesVjpMatchesFiniteDifferences) {
    std::mt19937_64 rng(11);
    for (int trial = 0; trial < 20; ++trial) {
        const Scene s = random_scene(rng, trial % 2 == 0);
        double g_pos[kShCount]{}, g_neg[kShCount]{};
        ShCoeffs<double> g_env;
        const SurfelColourGrad<double> g = surfel_colour_both_vjp(s.env, s.albedo_raw, s.normal, s.pos, s.neg,
                                                                  s.positive_side, s.w, g_pos, g_neg, g_env);
        const double tol = 1e-7;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(g.albedo_raw[c], fd_scalar(s, [c](Scene& x) -> double& { return x.albedo_raw[c]; }),
                        tol);
            EXPECT_NEAR(g.normal[c], fd_scalar(s, [c](Scene& x) -> double& { return x.normal[c]; }), tol);
        }
        for (int k = 0; k < kShCount; ++k) {
            EXPECT_NEAR(g_pos[k], fd_scalar(s, [k](Scene& x) -> double& { return x.pos[k]; }), tol);
            EXPECT_NEAR(g_neg[k], fd_scalar(s, [k](Scene& x) -> double& { return x.neg[k]; }), tol);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(g_env.c[k][c],
                            fd_scalar(s, [k, c](Scene& x) -> double& { return x.env.c[k][c]; }), tol);
        }
    }
}

TEST(ShadingSurfelColour, BothEqualsSingleModesInRasterLayout) {
    std::mt19937_64 rng(12);
    const Scene s = random_scene(rng, false);
    double out[kSurfelColourChannels];
    surfel_colour_both(s.env, s.albedo_raw, s.normal, s.pos, s.neg, s.positive_side, out);
    const Vec3d sh = surfel_colour_shadowed(s.env, s.albedo_raw, s.pos, s.neg, s.positive_side);
    const Vec3d un = surfel_colour_unshadowed(s.env, s.albedo_raw, s.normal);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(out[c], sh[c]);
        EXPECT_EQ(out[3 + c], un[c]);
    }
}

// Required known answer: a transfer equal to the cosine-lobe projection at the normal makes the shadowed
// colour equal to the unshadowed one, on either side.
TEST(ShadingSurfelColour, CosineLobeTransferMatchesUnshadowed) {
    std::mt19937_64 rng(13);
    for (int trial = 0; trial < 50; ++trial) {
        const ShCoeffs<double> env = bright_env(rng);
        const Vec3d albedo_raw = random_albedo_raw(rng);
        const Vec3d n = sh_test::random_unit(rng);
        double lobe[kShCount], junk[kShCount];
        cosine_lobe_sh(n, lobe);
        for (double& j : junk) j = uniform(rng);
        for (const bool positive : {true, false}) {
            const double* pos = positive ? lobe : junk;
            const double* neg = positive ? junk : lobe;
            const Vec3d sh = surfel_colour_shadowed(env, albedo_raw, pos, neg, positive);
            const Vec3d un = surfel_colour_unshadowed(env, albedo_raw, n);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(sh[c], un[c], 1e-6 * std::fabs(un[c])) << trial;
        }
    }
}

TEST(ShadingSurfelColour, GammaClampAndAlbedoOrder) {
    // Albedo activation: max(0, Y00 a + 0.5); a = 0 gives 0.5, a very negative raw value gives 0.
    const Vec3d alb = albedo_activation(Vec3d{0.0, (0.9 - 0.5) / sh_const::kY00, -10.0});
    EXPECT_DOUBLE_EQ(alb.x, 0.5);
    EXPECT_NEAR(alb.y, 0.9, 1e-15);
    EXPECT_EQ(alb.z, 0.0);
    // No upper clamp on the albedo.
    EXPECT_NEAR(albedo_activation(Vec3d{10.0, 0.0, 0.0}).x, 0.5 + 10 * sh_const::kY00, 1e-14);

    // Light -> colour: albedo * max(H, 1e-5)^(1/2.2), gamma after the clamp, albedo after the gamma.
    EXPECT_DOUBLE_EQ(light_to_colour(1.0, 0.7), 0.7);
    EXPECT_NEAR(light_to_colour(2.0, 0.5), 0.5 * std::pow(2.0, 1 / 2.2), 1e-15);
    EXPECT_NEAR(light_to_colour(0.25, 1.0), std::pow(0.25, 1 / 2.2), 1e-15);
    const double floor_colour = 0.8 * std::pow(1e-5, 1 / 2.2);  // ~0.0043, not 0
    EXPECT_NEAR(light_to_colour(-3.0, 0.8), floor_colour, 1e-15);
    EXPECT_NEAR(light_to_colour(0.0, 0.8), floor_colour, 1e-15);
    EXPECT_EQ(light_to_colour(5.0, 0.0), 0.0);
    // Values above 1 are not clamped before rasterisation.
    EXPECT_GT(light_to_colour(100.0, 1.0), 8.0);
    EXPECT_NEAR(light_intensity(100.0), std::pow(100.0, 1 / 2.2), 1e-12);

    // Below the floor the light receives no gradient, the albedo still does (through the floor value).
    double g_albedo = 0;
    EXPECT_EQ(light_to_colour_vjp(-3.0, 0.8, 1.0, g_albedo), 0.0);
    EXPECT_NEAR(g_albedo, std::pow(1e-5, 1 / 2.2), 1e-15);
    // Above it: d/dH (a H^(1/2.2)) = a/2.2 H^(1/2.2 - 1).
    g_albedo = 0;
    EXPECT_NEAR(light_to_colour_vjp(4.0, 0.5, 2.0, g_albedo), 2.0 * 0.5 / 2.2 * std::pow(4.0, 1 / 2.2 - 1),
                1e-14);
    EXPECT_NEAR(g_albedo, 2.0 * std::pow(4.0, 1 / 2.2), 1e-14);
}

TEST(ShadingSurfelColour, DeadAlbedoAndFlooredLightGetNoGradient) {
    std::mt19937_64 rng(14);
    Scene s = random_scene(rng, true);
    s.albedo_raw.y = -10.0;     // activated albedo 0: rgb 0 and no gradient to the raw value
    ShCoeffs<double> env_dark;  // all zero: both lights are floored
    double g_pos[kShCount]{}, g_neg[kShCount]{};
    ShCoeffs<double> g_env;
    const SurfelColourGrad<double> g = surfel_colour_both_vjp(env_dark, s.albedo_raw, s.normal, s.pos, s.neg,
                                                              true, s.w, g_pos, g_neg, g_env);
    EXPECT_EQ(g.albedo_raw.y, 0.0);
    EXPECT_NE(g.albedo_raw.x, 0.0);
    EXPECT_EQ(sh_test::max_abs(g_env), 0.0);
    for (int k = 0; k < kShCount; ++k) EXPECT_EQ(g_pos[k], 0.0);
    EXPECT_EQ(g.normal.x, 0.0);
}

// The camera-facing flag picks the set for the value and routes the gradient to that set only.
TEST(ShadingSurfelColour, TwoSidedSelectionRoutesValuesAndGradients) {
    std::mt19937_64 rng(15);
    const ShCoeffs<double> env = bright_env(rng);
    const Vec3d albedo_raw = random_albedo_raw(rng);
    double a[kShCount], b[kShCount];
    random_transfer(rng, a);
    random_transfer(rng, b);
    const Vec3d light_a = shadowed_radiance(a, env), light_b = shadowed_radiance(b, env);
    const Vec3d alb = albedo_activation(albedo_raw);
    const Vec3d on_pos = surfel_colour_shadowed(env, albedo_raw, a, b, true);
    const Vec3d on_neg = surfel_colour_shadowed(env, albedo_raw, a, b, false);
    for (int c = 0; c < 3; ++c) {
        EXPECT_DOUBLE_EQ(on_pos[c], light_to_colour(light_a[c], alb[c]));
        EXPECT_DOUBLE_EQ(on_neg[c], light_to_colour(light_b[c], alb[c]));
    }
    for (const bool positive : {true, false}) {
        double g_pos[kShCount]{}, g_neg[kShCount]{};
        ShCoeffs<double> g_env;
        surfel_colour_shadowed_vjp(env, albedo_raw, a, b, positive, Vec3d{1.0, 0.5, -0.3}, g_pos, g_neg,
                                   g_env);
        const double* used = positive ? g_pos : g_neg;
        const double* unused = positive ? g_neg : g_pos;
        double used_norm = 0;
        for (int k = 0; k < kShCount; ++k) {
            EXPECT_EQ(unused[k], 0.0);
            used_norm += std::fabs(used[k]);
        }
        EXPECT_GT(used_norm, 0.0);
    }
}

// Gradients of coefficients accumulate (the environment is shared by every surfel of an image).
TEST(ShadingSurfelColour, CoefficientGradientsAccumulate) {
    std::mt19937_64 rng(16);
    const Scene s = random_scene(rng, true);
    double g_pos[kShCount]{}, g_neg[kShCount]{};
    ShCoeffs<double> g_env;
    surfel_colour_both_vjp(s.env, s.albedo_raw, s.normal, s.pos, s.neg, true, s.w, g_pos, g_neg, g_env);
    const ShCoeffs<double> once = g_env;
    const double pos0 = g_pos[0];
    surfel_colour_both_vjp(s.env, s.albedo_raw, s.normal, s.pos, s.neg, true, s.w, g_pos, g_neg, g_env);
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(g_env.c[k][c], 2 * once.c[k][c], 1e-14);
    EXPECT_NEAR(g_pos[0], 2 * pos0, 1e-14);
}

// The renderers run in float: the same templates instantiate and agree with double to float precision.
TEST(ShadingSurfelColour, FloatMatchesDouble) {
    std::mt19937_64 rng(17);
    const Scene s = random_scene(rng, false);
    float pos[kShCount], neg[kShCount], out_f[kSurfelColourChannels], g_pos[kShCount]{}, g_neg[kShCount]{};
    float w[kSurfelColourChannels];
    for (int k = 0; k < kShCount; ++k) pos[k] = float(s.pos[k]), neg[k] = float(s.neg[k]);
    for (int i = 0; i < kSurfelColourChannels; ++i) w[i] = float(s.w[i]);
    const ShCoeffs<float> env = s.env.cast<float>();
    surfel_colour_both(env, s.albedo_raw.cast<float>(), s.normal.cast<float>(), pos, neg, false, out_f);
    double out_d[kSurfelColourChannels];
    surfel_colour_both(s.env, s.albedo_raw, s.normal, s.pos, s.neg, false, out_d);
    for (int i = 0; i < kSurfelColourChannels; ++i) EXPECT_NEAR(out_f[i], out_d[i], 1e-5);
    ShCoeffs<float> g_env;
    const SurfelColourGrad<float> g = surfel_colour_both_vjp(
        env, s.albedo_raw.cast<float>(), s.normal.cast<float>(), pos, neg, false, w, g_pos, g_neg, g_env);
    EXPECT_TRUE(std::isfinite(g.normal.x) && std::isfinite(g.albedo_raw.y));
    const Vec3f d = cube_normalized_direction(Vec3f{0.5f, -0.2f, 0.9f});
    const TransferLossSums<float> ls = transfer_loss_sums(pos, s.normal.cast<float>(), &d, 1);
    float g_t[kShCount]{};
    transfer_loss_vjp(pos, s.normal.cast<float>(), &d, 1, transfer_loss_scales(ls, {1.f, 1.f, 1.f}), g_t);
    EXPECT_EQ(ls.samples, 1);
}

// ---------------------------------------------------------------------------------------------------------
// Transfer losses

std::vector<Vec3d> random_directions(std::mt19937_64& rng, int n) {
    std::vector<Vec3d> d(n);
    for (Vec3d& v : d) v = cube_normalized_direction(sh_test::random_vec(rng));
    return d;
}

TEST(ShadingSurfelLoss, CubeNormalizedDirection) {
    const Vec3d d = cube_normalized_direction(Vec3d{0.3, -0.4, 0.0});
    EXPECT_NEAR(d.x, 0.3 / (0.5 + 1e-7), 1e-15);
    EXPECT_NEAR(d.y, -0.4 / (0.5 + 1e-7), 1e-15);
    EXPECT_EQ(d.z, 0.0);
}

// Constant transfer t = T0 * Y00 in every direction; normal +z; directions +z, -z, +x.
// Targets c = 1, 0, 0.
TEST(ShadingSurfelLoss, HandComputedValues) {
    const Vec3d n{0, 0, 1};
    const Vec3d dirs[3] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}};
    double tr[kShCount]{};

    // t = 0.5 everywhere: inside [0,1]; diffs -0.5, 0.5, 0.5.
    tr[0] = 0.5 / sh_const::kY00;
    TransferLossSums<double> s = transfer_loss_sums(tr, n, dirs, 3);
    EXPECT_EQ(s.below_count, 0);
    EXPECT_EQ(s.above_count, 0);
    EXPECT_EQ(s.samples, 3);
    TransferLosses<double> l = transfer_losses(s);
    EXPECT_EQ(l.range01, 0.0);
    EXPECT_NEAR(l.consistency, 0.25, 1e-14);
    EXPECT_NEAR(l.shadow, (0.25 + 0.25) / 3, 1e-14);

    // t = -0.5: below 0 in all three; diffs -1.5, -0.5, -0.5, never positive.
    tr[0] = -0.5 / sh_const::kY00;
    s = transfer_loss_sums(tr, n, dirs, 3);
    l = transfer_losses(s);
    EXPECT_EQ(s.below_count, 3);
    EXPECT_NEAR(l.range01, 0.25, 1e-14);
    EXPECT_NEAR(l.consistency, (2.25 + 0.25 + 0.25) / 3, 1e-14);
    EXPECT_EQ(l.shadow, 0.0);

    // t = 1.5: above 1 in all; diffs 0.5, 1.5, 1.5.
    tr[0] = 1.5 / sh_const::kY00;
    s = transfer_loss_sums(tr, n, dirs, 3);
    l = transfer_losses(s);
    EXPECT_EQ(s.above_count, 3);
    EXPECT_NEAR(l.range01, 0.25, 1e-14);
    EXPECT_NEAR(l.consistency, (0.25 + 2.25 + 2.25) / 3, 1e-14);
    EXPECT_NEAR(l.shadow, l.consistency, 1e-14);
}

// The official means are over the violating samples of ALL surfels together, not per surfel.
TEST(ShadingSurfelLoss, RangeMeanIsOverViolatingSamplesGlobally) {
    const Vec3d n{0, 0, 1};
    const Vec3d dirs[2] = {{1, 0, 0}, {0, 1, 0}};
    double below[kShCount]{}, inside[kShCount]{}, above[kShCount]{};
    below[0] = -1.0 / sh_const::kY00;  // t = -1: contributes 1 per sample
    inside[0] = 0.5 / sh_const::kY00;
    above[0] = 3.0 / sh_const::kY00;  // t = 3: contributes 4 per sample
    TransferLossSums<double> total = transfer_loss_sums(below, n, dirs, 2);
    total += transfer_loss_sums(inside, n, dirs, 2);
    total += transfer_loss_sums(inside, n, dirs, 2);
    total += transfer_loss_sums(above, n, dirs, 1);
    EXPECT_EQ(total.samples, 7);
    EXPECT_NEAR(transfer_losses(total).range01, 1.0 + 4.0, 1e-14);  // mean 1 over 2, mean 4 over 1
    // No violation at all: the term is exactly 0, not NaN.
    TransferLossSums<double> none = transfer_loss_sums(inside, n, dirs, 2);
    EXPECT_EQ(transfer_losses(none).range01, 0.0);
    EXPECT_EQ(transfer_loss_scales(none, TransferLossWeights<double>{1, 1, 1}).below_sq, 0.0);
}

// A transfer equal to the cosine lobe gives t ~ max(0, n.w) (only up to the degree-2 truncation), and the
// loss is far smaller than for the initial all-0.01 transfer.
TEST(ShadingSurfelLoss, CosineLobeIsNearlyConsistent) {
    std::mt19937_64 rng(21);
    const Vec3d n = sh_test::random_unit(rng);
    const std::vector<Vec3d> dirs = random_directions(rng, 2000);
    double lobe[kShCount], init[kShCount];
    cosine_lobe_sh(n, lobe);
    for (double& v : init) v = 0.01;
    const double lobe_loss = transfer_losses(transfer_loss_sums(lobe, n, dirs.data(), 2000)).consistency;
    const double init_loss = transfer_losses(transfer_loss_sums(init, n, dirs.data(), 2000)).consistency;
    EXPECT_LT(lobe_loss, 0.01);
    EXPECT_GT(init_loss, 0.1);
}

// Total weighted loss over several surfels as a function of one surfel's transfer.
double weighted_total(const std::vector<std::vector<double>>& transfers, const std::vector<Vec3d>& normals,
                      const std::vector<std::vector<Vec3d>>& dirs, const TransferLossWeights<double>& w) {
    TransferLossSums<double> total;
    for (size_t i = 0; i < transfers.size(); ++i)
        total += transfer_loss_sums(transfers[i].data(), normals[i], dirs[i].data(), int(dirs[i].size()));
    return weighted_transfer_loss(transfer_losses(total), w);
}

TEST(ShadingSurfelLoss, VjpMatchesFiniteDifferences) {
    std::mt19937_64 rng(22);
    const TransferLossWeights<double> w{0.7, 1.3, 2.1};
    const int n_surfels = 4;
    std::vector<std::vector<double>> transfers(n_surfels, std::vector<double>(kShCount));
    std::vector<Vec3d> normals(n_surfels);
    std::vector<std::vector<Vec3d>> dirs(n_surfels);
    for (int i = 0; i < n_surfels; ++i) {
        // Wide coefficients so that some samples fall below 0 and some above 1.
        for (double& v : transfers[i]) v = 1.5 * uniform(rng);
        normals[i] = sh_test::random_unit(rng);
        dirs[i] = random_directions(rng, surfel_const::kTransferSamples);
    }
    TransferLossSums<double> total;
    for (int i = 0; i < n_surfels; ++i)
        total += transfer_loss_sums(transfers[i].data(), normals[i], dirs[i].data(), int(dirs[i].size()));
    ASSERT_GT(total.below_count, 0);
    ASSERT_GT(total.above_count, 0);
    const TransferLossScales<double> scales = transfer_loss_scales(total, w);
    for (int i = 0; i < n_surfels; ++i) {
        double g[kShCount]{};
        transfer_loss_vjp(transfers[i].data(), normals[i], dirs[i].data(), int(dirs[i].size()), scales, g);
        for (int k = 0; k < kShCount; ++k) {
            auto hi = transfers, lo = transfers;
            hi[i][k] += kFdEps;
            lo[i][k] -= kFdEps;
            const double fd =
                (weighted_total(hi, normals, dirs, w) - weighted_total(lo, normals, dirs, w)) / (2 * kFdEps);
            EXPECT_NEAR(g[k], fd, 1e-7) << "surfel " << i << " k " << k;
        }
    }
}

// The loss selects the camera-facing set like the colour does; routing is the caller's select_transfer.
TEST(ShadingSurfelLoss, SelectTransferRoutesTheGradient) {
    std::mt19937_64 rng(23);
    double pos[kShCount], neg[kShCount];
    random_transfer(rng, pos);
    random_transfer(rng, neg);
    const Vec3d n = sh_test::random_unit(rng);
    const std::vector<Vec3d> dirs = random_directions(rng, 25);
    for (const bool positive : {true, false}) {
        double g_pos[kShCount]{}, g_neg[kShCount]{};
        const double* t = select_transfer(positive, pos, neg);
        const TransferLossSums<double> s = transfer_loss_sums(t, n, dirs.data(), 25);
        EXPECT_EQ(s.consistency_sq,
                  transfer_loss_sums(positive ? pos : neg, n, dirs.data(), 25).consistency_sq);
        const TransferLossScales<double> sc = transfer_loss_scales(s, TransferLossWeights<double>{1, 1, 1});
        transfer_loss_vjp(t, n, dirs.data(), 25, sc, select_transfer(positive, g_pos, g_neg));
        const double* unused = positive ? g_neg : g_pos;
        for (int k = 0; k < kShCount; ++k) EXPECT_EQ(unused[k], 0.0);
    }
}

}  // namespace
}  // namespace lumigauss
