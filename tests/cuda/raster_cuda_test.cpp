// The CUDA backend against the CPU backend: the same maps and the same gradients, within float rounding,
// on random scenes (several tiles, batches longer than a block, every map's gradient at once), and its
// errors. Without a GPU (CI) only the error paths run; the comparisons skip and say why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cuda/rasterizer_cuda.h"
#include "lumigauss/util/error.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::random_surfels;
using testing::RandomSceneOptions;

#define SKIP_WITHOUT_GPU() \
    if (!cuda_backend_available()) GTEST_SKIP() << cuda_backend_description()

// ||a - b|| / ||b|| (0 when both are 0), and the largest |a - b|.
struct Difference {
    double relative_l2 = 0, max_abs = 0;
    std::size_t max_at = 0;
};
template <typename A, typename B>
Difference difference(const std::vector<A>& a, const std::vector<B>& b) {
    EXPECT_EQ(a.size(), b.size());
    double diff = 0, ref = 0;
    Difference d;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
        const double e = double(a[i]) - double(b[i]);
        diff += e * e;
        ref += double(b[i]) * double(b[i]);
        if (std::abs(e) > d.max_abs) d.max_abs = std::abs(e), d.max_at = i;
        EXPECT_TRUE(std::isfinite(a[i])) << "value " << i;
    }
    d.relative_l2 = ref > 0 ? std::sqrt(diff / ref) : std::sqrt(diff);
    return d;
}

void expect_close(const char* what, const std::vector<float>& gpu, const std::vector<float>& cpu,
                  double tolerance) {
    const Difference d = difference(gpu, cpu);
    if (d.relative_l2 <= tolerance) return;
    const bool indexed = d.max_at < gpu.size() && d.max_at < cpu.size();
    ADD_FAILURE() << what << ": relative L2 " << d.relative_l2 << " > " << tolerance << ", max |diff| "
                  << d.max_abs << " at " << d.max_at << " (GPU " << (indexed ? gpu[d.max_at] : 0.0f)
                  << ", CPU " << (indexed ? cpu[d.max_at] : 0.0f) << ")";
}

// The GPU's float gradients are as accurate as the CPU backend's float ones: both against the CPU
// backend in double (proven by finite differences, raster_gradient_test.cpp). Not GPU against CPU float
// directly: a surfel whose filter centre sits near the edge of the conic branch has gradients that float
// rounding moves by a few tenths of a percent (the two float backends round differently).
void expect_as_accurate(const char* what, const std::vector<float>& gpu, const std::vector<float>& cpu,
                        const std::vector<double>& reference) {
    const Difference g = difference(gpu, reference), c = difference(cpu, reference);
    EXPECT_LE(g.relative_l2, 3 * c.relative_l2 + 1e-5)
        << what << ": relative L2 error against double, GPU " << g.relative_l2 << ", CPU float "
        << c.relative_l2 << "; GPU's largest error " << g.max_abs << " at " << g.max_at;
}

Camera wide_camera() {
    return testing::test_camera(70, 52);  // 5 x 4 tiles, the last row and column partial
}

// A crowded scene: hundreds of surfels per tile, so that the forward's batches (a block's worth) and the
// backward's (32) both wrap several times.
RandomSceneOptions crowded(int channels) {
    RandomSceneOptions o;
    o.count = 700;
    o.channels = channels;
    o.min_scale = 0.1, o.max_scale = 0.9;
    o.min_opacity = 0.05, o.max_opacity = 0.6;
    return o;
}

RasterSettings<float> background(int channels) {
    RasterSettings<float> s;
    for (int c = 0; c < channels; ++c) s.background.push_back(0.1f + 0.2f * float(c % 4));
    return s;
}

RasterImageGrads<float> random_map_grads(const RasterImages<float>& img, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    const auto fill = [&](const std::vector<float>& like, float scale) {
        std::vector<float> g(like.size());
        for (float& v : g) v = scale * uni(rng);
        return g;
    };
    RasterImageGrads<float> g;
    g.color = fill(img.color, 1.0f);
    g.alpha = fill(img.alpha, 0.5f);
    g.depth = fill(img.depth, 0.1f);
    g.median_depth = fill(img.median_depth, 0.1f);
    g.normal = fill(img.normal, 0.5f);
    g.distortion = fill(img.distortion, 1.0f);
    return g;
}

// Pixels whose median depth the two backends agree on. Where the transmittance crosses 0.5 within float
// rounding of a sample, the two may pick neighbouring samples (each correctly for its own rounding).
std::vector<bool> median_agrees(const RasterImages<float>& gpu, const RasterImages<float>& cpu) {
    std::vector<bool> agrees(cpu.median_depth.size());
    for (std::size_t i = 0; i < agrees.size(); ++i)
        agrees[i] = std::abs(gpu.median_depth[i] - cpu.median_depth[i]) <=
                    1e-4f * std::max(1.0f, std::abs(cpu.median_depth[i]));
    return agrees;
}

void expect_maps_match(const RasterImages<float>& gpu, const RasterImages<float>& cpu) {
    EXPECT_EQ(gpu.width, cpu.width);
    EXPECT_EQ(gpu.height, cpu.height);
    EXPECT_EQ(gpu.channels, cpu.channels);
    expect_close("colour", gpu.color, cpu.color, 1e-5);
    expect_close("alpha", gpu.alpha, cpu.alpha, 1e-5);
    expect_close("depth", gpu.depth, cpu.depth, 1e-5);
    expect_close("normal", gpu.normal, cpu.normal, 1e-5);
    // Sums of differences of nearly equal products: relative rounding grows where the map is near 0.
    expect_close("distortion", gpu.distortion, cpu.distortion, 1e-3);
    const std::vector<bool> agrees = median_agrees(gpu, cpu);
    const auto disagree = std::count(agrees.begin(), agrees.end(), false);
    EXPECT_LE(double(disagree), 0.002 * double(agrees.size())) << disagree << " pixels' median depths differ";
}

// Renders `s` on the GPU, on the CPU in float and on the CPU in double; compares the maps (GPU against
// CPU float) and the gradients from random gradients on every map (expect_as_accurate).
void compare_with_cpu(CudaRasterizer& gpu, const Camera& cam, const SurfelBatch<float>& s,
                      const RasterSettings<float>& settings, std::uint32_t seed) {
    RasterState<float> st;
    const RasterImages<float> cpu = rasterize_forward_cpu(cam, s, settings, st);
    const SurfelBatch<double> s_double = testing::convert_batch<double>(s);
    RasterSettings<double> settings_double;
    for (float b : settings.background) settings_double.background.push_back(b);
    RasterState<double> st_double;
    const RasterImages<double> reference = rasterize_forward_cpu(cam, s_double, settings_double, st_double);
    RasterImages<float> img;
    gpu.forward(cam, s, settings, img);
    EXPECT_EQ(gpu.intersections(), st.intersections());
    expect_maps_match(img, cpu);

    // The median depth's gradient only where the three picked the same sample.
    RasterImageGrads<float> g = random_map_grads(cpu, seed);
    const std::vector<bool> agrees = median_agrees(img, cpu);
    for (std::size_t i = 0; i < agrees.size(); ++i)
        if (!agrees[i] || std::abs(reference.median_depth[i] - double(cpu.median_depth[i])) >
                              1e-4 * std::max(1.0, std::abs(reference.median_depth[i])))
            g.median_depth[i] = 0.0f;
    const auto to_double = [](const std::vector<float>& v) {
        return std::vector<double>(v.begin(), v.end());
    };
    RasterImageGrads<double> g_double;
    g_double.color = to_double(g.color), g_double.alpha = to_double(g.alpha);
    g_double.depth = to_double(g.depth), g_double.median_depth = to_double(g.median_depth);
    g_double.normal = to_double(g.normal), g_double.distortion = to_double(g.distortion);

    const SurfelGrads<float> c = rasterize_backward_cpu(s, st, g);
    const SurfelGrads<double> r = rasterize_backward_cpu(s_double, st_double, g_double);
    SurfelGrads<float> d;
    gpu.backward(g, d);
    expect_as_accurate("means", d.means, c.means, r.means);
    expect_as_accurate("quats", d.quats, c.quats, r.quats);
    expect_as_accurate("scales", d.scales, c.scales, r.scales);
    expect_as_accurate("opacities", d.opacities, c.opacities, r.opacities);
    expect_as_accurate("colors", d.colors, c.colors, r.colors);
    expect_as_accurate("mean2d", d.mean2d, c.mean2d, r.mean2d);
}

TEST(CudaRasterizer, WithoutGpuSaysWhyAndRefuses) {
    if (cuda_backend_available()) {
        EXPECT_NE(cuda_backend_description().find("multiprocessors"), std::string::npos);
        EXPECT_NO_THROW(CudaRasterizer{});
        return;
    }
    EXPECT_FALSE(cuda_backend_description().empty());
    EXPECT_THROW(CudaRasterizer{}, Error);
}

TEST(CudaRasterizer, ForwardAndBackwardMatchCpu) {
    SKIP_WITHOUT_GPU();
    const Camera cam = wide_camera();
    CudaRasterizer gpu;
    for (int channels : {3, 6, 16}) {
        for (std::uint32_t seed : {1u, 2u}) {
            SCOPED_TRACE("channels " + std::to_string(channels) + ", seed " + std::to_string(seed));
            const SurfelBatch<float> s =
                random_surfels<float>(cam, seed * 31 + std::uint32_t(channels), crowded(channels));
            compare_with_cpu(gpu, cam, s, background(channels), seed);
        }
    }
}

TEST(CudaRasterizer, EdgeCasesMatchCpu) {
    SKIP_WITHOUT_GPU();
    const Camera cam = wide_camera();
    CudaRasterizer gpu;
    // Behind the camera and across the near plane, huge, tiny, nearly transparent, off-screen.
    RandomSceneOptions o;
    o.count = 300;
    o.min_depth = -1.0, o.max_depth = 3.0;
    o.min_scale = 0.001, o.max_scale = 4.0;
    o.min_opacity = 0.0, o.max_opacity = 1.0;
    SurfelBatch<float> s = random_surfels<float>(cam, 7, o);
    for (std::size_t i = 0; i < s.size(); i += 17) s.opacities[i] = 0.0f;
    for (std::size_t i = 5; i < s.size(); i += 23) s.scales[2 * i + 1] = 1e-7f;  // edge-on needles
    compare_with_cpu(gpu, cam, s, RasterSettings<float>{}, 3);
}

TEST(CudaRasterizer, EmptySceneIsBackgroundWithZeroGradients) {
    SKIP_WITHOUT_GPU();
    const Camera cam = wide_camera();
    SurfelBatch<float> none;
    none.channels = 3;
    CudaRasterizer gpu;
    RasterImages<float> img;
    gpu.forward(cam, none, background(3), img);
    ASSERT_EQ(img.color.size(), std::size_t(cam.width) * cam.height * 3);
    for (std::size_t i = 0; i < img.color.size(); ++i)
        EXPECT_FLOAT_EQ(img.color[i], background(3).background[i % 3]);
    for (float a : img.alpha) EXPECT_EQ(a, 0.0f);
    SurfelGrads<float> grads;
    gpu.backward(random_map_grads(img, 1), grads);
    EXPECT_TRUE(grads.means.empty());
}

TEST(CudaRasterizer, BackwardIsDeterministic) {
    SKIP_WITHOUT_GPU();
    const Camera cam = wide_camera();
    const SurfelBatch<float> s = random_surfels<float>(cam, 11, crowded(3));
    CudaRasterizer gpu;
    RasterImages<float> img;
    gpu.forward(cam, s, RasterSettings<float>{}, img);
    const RasterImageGrads<float> g = random_map_grads(img, 5);
    SurfelGrads<float> first, second;
    gpu.backward(g, first);
    gpu.backward(g, second);
    EXPECT_EQ(first.means, second.means);
    EXPECT_EQ(first.quats, second.quats);
    EXPECT_EQ(first.opacities, second.opacities);
    EXPECT_EQ(first.colors, second.colors);
}

TEST(CudaRasterizer, BadInputIsAnError) {
    SKIP_WITHOUT_GPU();
    const Camera cam = wide_camera();
    CudaRasterizer gpu;
    SurfelGrads<float> grads;
    EXPECT_THROW(gpu.backward(RasterImageGrads<float>{}, grads), Error);  // no forward yet
    RandomSceneOptions o;
    o.channels = kMaxChannels + 1;
    RasterImages<float> img;
    EXPECT_THROW(gpu.forward(cam, random_surfels<float>(cam, 1, o), RasterSettings<float>{}, img), Error);
    SurfelBatch<float> s = random_surfels<float>(cam, 1);
    EXPECT_THROW(gpu.forward(cam, s, background(4), img), Error);  // 4 background values, 3 channels
    s.scales.pop_back();
    EXPECT_THROW(gpu.forward(cam, s, RasterSettings<float>{}, img), Error);  // arrays of the wrong size
    s = random_surfels<float>(cam, 1);
    gpu.forward(cam, s, RasterSettings<float>{}, img);
    RasterImageGrads<float> g;
    g.alpha.assign(5, 1.0f);
    EXPECT_THROW(gpu.backward(g, grads), Error);
}

}  // namespace
}  // namespace lumigauss
