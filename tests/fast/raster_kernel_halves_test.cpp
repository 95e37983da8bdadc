// The per-pixel kernel in its two halves (surfel_kernel.h: splat_hit, then splat_alpha), as the CPU tile
// loops run them. Two properties the dense-reference and finite-difference tests cannot see:
// - Out of reach, the second half must stay in normal floats. The tile loops evaluate whole packs, and a
//   lane whose exponent underflows to a subnormal alpha costs the processor a slow assist per operation
//   (an exponent of -infinity made the tiles 20 % slower without changing any image).
// - The exponent handed from one half to the other is never NaN, and a lane out of reach never counts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/render/cpu/lane_pack.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::cpu {
namespace {

bool normal_or_zero(float x) {
    const int c = std::fpclassify(x);
    return c == FP_NORMAL || c == FP_ZERO;
}

// A splat facing the camera: hit (u, v) = (pixel - centre) / size, so rho = |pixel - centre|^2 / size^2.
raster::SplatGeometry<float> frontal_splat(float size, float opacity, Vec2<float> centre) {
    raster::SplatGeometry<float> g{};
    g.pa = {1, 0, 0};
    g.pb = {0, 1, 0};
    g.pd = {0, 0, size};
    g.tw = {0, 0, 5};
    g.center = centre;
    g.opacity = opacity;
    g.rho_cutoff = float(raster::reach_rho(double(opacity)));
    return g;
}

TEST(SplatKernelHalves, EveryLaneStaysInNormalFloatsAndOutOfReachNeverCounts) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uni(0, 1);
    int out_of_reach = 0, contributing = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const float size = 0.3f + 8 * uni(rng), opacity = 0.005f + 0.995f * uni(rng);
        const auto g = frontal_splat(size, opacity, {64 * uni(rng), 64 * uni(rng)});
        Pack8<float> px, py;
        for (int l = 0; l < kLanes; ++l) px.v[l] = 64 * uni(rng), py.v[l] = 64 * uni(rng);
        // The halves as the tile loops call them, and the whole as everything else does.
        raster::SplatSample<Pack8<float>> hit, smp, whole;
        Pack8<float> rho;
        const auto reached = raster::splat_hit(g, px, py, hit, rho);
        const Pack8<float> exponent = raster::splat_exponent(rho, reached);
        const auto contributes = raster::splat_alpha(g.opacity, exponent, smp);
        const auto evaluated = raster::evaluate_splat(g, px, py, whole);
        for (int l = 0; l < kLanes; ++l) {
            ASSERT_FALSE(std::isnan(exponent[l]));
            ASSERT_TRUE(normal_or_zero(smp.gauss[l])) << "gauss " << smp.gauss[l] << " rho " << rho[l];
            ASSERT_TRUE(normal_or_zero(smp.alpha[l])) << "alpha " << smp.alpha[l] << " rho " << rho[l];
            ASSERT_EQ(contributes[l] != 0, evaluated[l] != 0);
            if (!reached[l]) {
                ++out_of_reach;
                ASSERT_EQ(contributes[l], 0) << "a lane out of reach counted";
            } else if (contributes[l]) {
                ++contributing;
                ASSERT_EQ(smp.alpha[l], whole.alpha[l]);
            }
        }
    }
    // Both kinds of lanes were met, many times.
    EXPECT_GT(out_of_reach, 5000);
    EXPECT_GT(contributing, 1000);
}

}  // namespace
}  // namespace lumigauss::cpu
