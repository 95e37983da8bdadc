// A per-pixel background composited after the rasterizer: known answers, and its backward through the real
// tiled rasterizer backward against finite differences of every surfel parameter and the background.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/render/background.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::random_surfels;
using testing::test_camera;

TEST(Background, CompositesBehindTheSurfels) {
    RasterImages<double> im;
    im.width = 2, im.height = 1, im.channels = 6;
    im.color = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0, 0, 0, 0, 0, 0};
    im.alpha = {0.75, 0.0};
    const std::vector<double> bg = {1, 2, 3, 0.5, 0.5, 0.5};
    composite_background<double>(im, bg, 3);
    EXPECT_DOUBLE_EQ(im.color[0], 0.1);  // the other colour set is untouched
    EXPECT_DOUBLE_EQ(im.color[3], 0.4 + 0.25 * 1);
    EXPECT_DOUBLE_EQ(im.color[5], 0.6 + 0.25 * 3);
    EXPECT_DOUBLE_EQ(im.color[9], 0.5);  // nothing rendered: the background itself
    EXPECT_THROW(composite_background<double>(im, bg, 4), Error);
}

// L = <w_c, colour after compositing> + <w_a, alpha>, colour = raster colour + (1 - alpha) background.
double loss_of(const Camera& cam, const SurfelBatch<double>& s, const std::vector<double>& bg,
               const std::vector<double>& wc, const std::vector<double>& wa) {
    RasterState<double> st;
    RasterImages<double> im = rasterize_forward_cpu(cam, s, RasterSettings<double>{}, st);
    composite_background<double>(im, bg, 0);
    double l = 0;
    for (std::size_t i = 0; i < wc.size(); ++i) l += wc[i] * im.color[i];
    for (std::size_t i = 0; i < wa.size(); ++i) l += wa[i] * im.alpha[i];
    return l;
}

TEST(Background, GradientsThroughTheRasterizerMatchFiniteDifferences) {
    const Camera cam = test_camera(23, 19);
    const std::size_t pixels = std::size_t(cam.width) * cam.height;
    for (std::uint32_t seed = 3; seed <= 4; ++seed) {
        testing::RandomSceneOptions o;
        o.count = 8;
        SurfelBatch<double> s = random_surfels<double>(cam, seed, o);
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-1, 1);
        std::vector<double> bg(3 * pixels), wc(3 * pixels), wa(pixels);
        for (double& v : bg) v = 0.5 + 0.4 * u(rng);
        for (double& v : wc) v = u(rng);
        for (double& v : wa) v = u(rng);

        RasterState<double> st;
        RasterImages<double> im = rasterize_forward_cpu(cam, s, RasterSettings<double>{}, st);
        composite_background<double>(im, bg, 0);
        RasterImageGrads<double> g;
        g.width = cam.width, g.height = cam.height, g.channels = 3;
        g.color = wc;
        g.alpha = wa;
        std::vector<double> g_bg(3 * pixels, 0.0);
        composite_background_backward<double>(im, bg, 0, g, g_bg);
        const SurfelGrads<double> sg = rasterize_backward_cpu(s, st, g);

        int nonzero = 0;
        const auto check = [&](double& x, double analytic, const char* what) {
            const double h = 1e-6 * std::max(1.0, std::abs(x)), x0 = x;
            x = x0 + h;
            const double lp = loss_of(cam, s, bg, wc, wa);
            x = x0 - h;
            const double lm = loss_of(cam, s, bg, wc, wa);
            x = x0;
            const double numeric = (lp - lm) / (2 * h);
            EXPECT_NEAR(analytic, numeric, 2e-5 * std::max({1.0, std::abs(numeric), std::abs(analytic)}))
                << what;
            nonzero += std::abs(numeric) > 1e-6;
        };
        for (std::size_t i = 0; i < s.size(); ++i) {
            check(s.opacities[i], sg.opacities[i], "opacity");
            for (int k = 0; k < 3; ++k) check(s.means[3 * i + k], sg.means[3 * i + k], "mean");
            for (int k = 0; k < 2; ++k) check(s.scales[2 * i + k], sg.scales[2 * i + k], "scale");
            for (int k = 0; k < 4; ++k) check(s.quats[4 * i + k], sg.quats[4 * i + k], "quat");
        }
        for (std::size_t i = 0; i < bg.size(); i += 7) check(bg[i], g_bg[i], "background");
        EXPECT_GT(nonzero, int(s.size()) * 5);
    }
}

}  // namespace
}  // namespace lumigauss
