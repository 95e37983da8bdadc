// The frozen-geometry compositor (render/blend_weights.h): its weights reproduce the rasterizer's colour
// image for any colours, its backward is the rasterizer's colour gradient, and the pairs stop where the
// forward stopped (alpha clamp, 1/255 skip, transmittance stop).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/render/cpu/blend_weights_cpu.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::random_surfels;
using testing::RandomSceneOptions;
using testing::test_camera;

std::vector<float> random_values(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    std::vector<float> v(n);
    for (float& x : v) x = uni(rng);
    return v;
}

struct Scene {
    Camera cam;
    SurfelBatch<float> surfels;
};

// A dense scene (many pixels reach the transmittance stop) with 6 channels.
Scene dense_scene(std::uint32_t seed) {
    Scene s{test_camera(48, 40), {}};
    RandomSceneOptions o;
    o.count = 400, o.channels = 6, o.min_opacity = 0.5, o.max_opacity = 0.999;
    s.surfels = random_surfels<float>(s.cam, seed, o);
    return s;
}

TEST(RasterBlendWeights, CompositeEqualsTheRasterizerForOtherColours) {
    for (std::uint32_t seed : {1u, 2u, 3u}) {
        Scene s = dense_scene(seed);
        RasterState<float> st;
        rasterize_forward_cpu(s.cam, s.surfels, {}, st);
        const BlendWeights bw = blend_weights(st);
        ASSERT_GT(bw.pairs(), 0u);

        // New colours, same geometry: the rasterizer and the weights agree.
        s.surfels.colors = random_values(s.surfels.colors.size(), seed + 10);
        RasterState<float> st2;
        const RasterImages<float> img = rasterize_forward_cpu(s.cam, s.surfels, {}, st2);
        std::vector<float> out(img.color.size());
        composite(bw, s.surfels.colors, 6, out);
        double max_err = 0;
        for (std::size_t k = 0; k < out.size(); ++k)
            max_err = std::max(max_err, double(std::abs(out[k] - img.color[k])));
        EXPECT_LT(max_err, 1e-5) << "seed " << seed;

        // The weights of each pixel sum to its alpha, and it stopped where the forward did.
        int stopped = 0;
        for (std::size_t p = 0; p + 1 < bw.pixel_start.size(); ++p) {
            double sum = 0;
            for (std::uint32_t k = bw.pixel_start[p]; k < bw.pixel_start[p + 1]; ++k)
                sum += bw.pixel_weight[k];
            EXPECT_NEAR(sum, img.alpha[p], 1e-5) << "pixel " << p;
            stopped += img.alpha[p] > 0.999f ? 1 : 0;
        }
        EXPECT_GT(stopped, 10) << "the scene should saturate some pixels";
    }
}

TEST(RasterBlendWeights, BackwardIsTheRasterizersColourGradient) {
    Scene s = dense_scene(7);
    RasterState<float> st;
    const RasterImages<float> img = rasterize_forward_cpu(s.cam, s.surfels, {}, st);
    const BlendWeights bw = blend_weights(st);
    RasterImageGrads<float> g;
    g.width = img.width, g.height = img.height, g.channels = 6;
    g.color = random_values(img.color.size(), 99);
    const SurfelGrads<float> reference = rasterize_backward_cpu(s.surfels, st, g);
    std::vector<float> g_colors(s.surfels.colors.size(), 123.0f);  // overwritten
    composite_backward(bw, g.color, 6, g_colors);
    double max_err = 0, max_ref = 0;
    for (std::size_t k = 0; k < g_colors.size(); ++k) {
        max_err = std::max(max_err, double(std::abs(g_colors[k] - reference.colors[k])));
        max_ref = std::max(max_ref, double(std::abs(reference.colors[k])));
    }
    EXPECT_GT(max_ref, 0.1);
    EXPECT_LT(max_err, 1e-4 * max_ref);

    // <composite(c), g> == <c, composite_backward(g)>: the two are transposes.
    const std::vector<float> c = random_values(s.surfels.colors.size(), 5);
    std::vector<float> pix(img.color.size());
    composite(bw, c, 6, pix);
    double lhs = 0, rhs = 0;
    for (std::size_t k = 0; k < pix.size(); ++k) lhs += double(pix[k]) * g.color[k];
    for (std::size_t k = 0; k < c.size(); ++k) rhs += double(c[k]) * g_colors[k];
    EXPECT_NEAR(lhs, rhs, 1e-4 * std::abs(lhs));
}

TEST(RasterBlendWeights, EmptySceneHasNoPairs) {
    Scene s{test_camera(20, 20), {}};
    s.surfels.channels = 3;
    RasterState<float> st;
    rasterize_forward_cpu(s.cam, s.surfels, {}, st);
    const BlendWeights bw = blend_weights(st);
    EXPECT_EQ(bw.pairs(), 0u);
    std::vector<float> out(20 * 20 * 3, 5.0f);
    composite(bw, {}, 3, out);
    EXPECT_TRUE(std::all_of(out.begin(), out.end(), [](float v) { return v == 0.0f; }));
}

}  // namespace
}  // namespace lumigauss
