// The backend-neutral rasterizer (render/rasterizer.h): the CPU backend behind it gives exactly what the CPU
// functions give (maps, gradients), its footprints are the forward's pixel boxes and depths, and choosing a
// backend by name says clearly what cannot run here.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cuda/rasterizer_cuda.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/util/error.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::random_surfels;
using testing::RandomSceneOptions;

SurfelBatch<float> crowded_scene(const Camera& cam, std::uint32_t seed) {
    RandomSceneOptions o;
    o.count = 300;
    o.min_scale = 0.1, o.max_scale = 0.9;
    return random_surfels<float>(cam, seed, o);
}

RasterImageGrads<float> random_map_grads(const RasterImages<float>& img, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    const auto fill = [&](const std::vector<float>& like) {
        std::vector<float> g(like.size());
        for (float& v : g) v = uni(rng);
        return g;
    };
    RasterImageGrads<float> g;
    g.color = fill(img.color), g.alpha = fill(img.alpha), g.depth = fill(img.depth);
    g.normal = fill(img.normal), g.distortion = fill(img.distortion);
    return g;
}

TEST(Rasterizer, CpuBackendIsTheCpuFunctionsBitForBit) {
    const Camera cam = testing::test_camera(70, 52);
    const SurfelBatch<float> s = crowded_scene(cam, 3);
    RasterState<float> state;
    const RasterImages<float> direct = rasterize_forward_cpu(cam, s, RasterSettings<float>{}, state);
    const auto rasterizer = make_rasterizer(RasterBackend::Cpu);
    EXPECT_EQ(rasterizer->backend(), RasterBackend::Cpu);
    RasterImages<float> via;
    rasterizer->forward(cam, s, RasterSettings<float>{}, via);
    EXPECT_EQ(via.color, direct.color);
    EXPECT_EQ(via.alpha, direct.alpha);
    EXPECT_EQ(via.depth, direct.depth);
    EXPECT_EQ(via.normal, direct.normal);
    EXPECT_EQ(via.distortion, direct.distortion);
    EXPECT_EQ(rasterizer->intersections(), state.intersections());
    ASSERT_GT(state.intersections(), 0u);

    const RasterImageGrads<float> g = random_map_grads(direct, 11);
    const SurfelGrads<float> direct_grads = rasterize_backward_cpu(s, state, g);
    SurfelGrads<float> via_grads;
    rasterizer->backward(s, g, via_grads);
    EXPECT_EQ(via_grads.means, direct_grads.means);
    EXPECT_EQ(via_grads.quats, direct_grads.quats);
    EXPECT_EQ(via_grads.scales, direct_grads.scales);
    EXPECT_EQ(via_grads.opacities, direct_grads.opacities);
    EXPECT_EQ(via_grads.colors, direct_grads.colors);
    EXPECT_EQ(via_grads.mean2d, direct_grads.mean2d);
}

TEST(Rasterizer, FootprintsAreTheForwardsPixelBoxesAndDepths) {
    const Camera cam = testing::test_camera(70, 52);
    SurfelBatch<float> s = crowded_scene(cam, 5);
    // One surfel 5 units behind the camera: never visible, so radius and depth 0.
    const Vec3d behind =
        cam.center() - 5.0 * Vec3d{cam.rotation.m[2][0], cam.rotation.m[2][1], cam.rotation.m[2][2]};
    for (int a = 0; a < 3; ++a) s.means[std::size_t(a)] = float(behind[a]);
    RasterState<float> state;
    rasterize_forward_cpu(cam, s, RasterSettings<float>{}, state);
    const auto rasterizer = make_rasterizer(RasterBackend::Cpu);
    rasterizer->render(cam, s);
    SurfelFootprints f;
    rasterizer->footprints(f);
    ASSERT_EQ(f.visible.size(), s.size());
    ASSERT_EQ(f.radius.size(), s.size());
    ASSERT_EQ(f.depth.size(), s.size());
    EXPECT_EQ(f.visible[0], 0);
    EXPECT_EQ(f.radius[0], 0.0f);
    std::size_t visible = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(f.visible[i], state.visible[i]) << i;
        if (!f.visible[i]) {
            EXPECT_EQ(f.radius[i], 0.0f) << i;
            EXPECT_EQ(f.depth[i], 0.0f) << i;
            continue;
        }
        ++visible;
        const raster::PixelRect& r = state.footprints[i].rect;
        EXPECT_EQ(f.radius[i], 0.5f * float(std::max(r.x1 - r.x0 + 1, r.y1 - r.y0 + 1))) << i;
        EXPECT_EQ(f.depth[i], state.footprints[i].depth) << i;
        EXPECT_GT(f.depth[i], 0.0f) << i;
    }
    EXPECT_GT(visible, s.size() / 4);
}

TEST(Rasterizer, BackendsAreChosenByName) {
    EXPECT_EQ(choose_backend("cpu"), RasterBackend::Cpu);
    EXPECT_STREQ(backend_name(RasterBackend::Cpu), "cpu");
    EXPECT_STREQ(backend_name(RasterBackend::Cuda), "cuda");
    EXPECT_EQ(choose_backend("auto"), cuda_backend_available() ? RasterBackend::Cuda : RasterBackend::Cpu);
    try {
        choose_backend("vulkan");
        ADD_FAILURE() << "an unknown backend was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("use cpu, cuda or auto"), std::string::npos) << e.what();
    }
    if (cuda_backend_available()) GTEST_SKIP() << "this machine has the CUDA backend";
    // Without it, asking for CUDA says why instead of quietly rendering on the CPU.
    try {
        choose_backend("cuda");
        ADD_FAILURE() << "--backend cuda was accepted without the CUDA backend";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--backend cuda"), std::string::npos) << e.what();
    }
    EXPECT_THROW(make_rasterizer(RasterBackend::Cuda), Error);
}

}  // namespace
}  // namespace lumigauss
