// The losses that keep the sky empty and tie the environment to it: mask erosion, the alpha penalty, the
// sky-pixel loss (finite differences), and the background-explained pixels of scenes without sky masks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/train/sky_losses.h"

namespace lumigauss {
namespace {

TEST(SkyLosses, ErosionShrinksTheMaskButNotAtTheBorder) {
    Image m(8, 6, 1, 0.0f);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 8; ++x) m.at(x, y, 0) = 1.0f;  // the top three rows are sky
    const std::vector<float> e1 = eroded_mask(m, 1);
    EXPECT_EQ(e1[0 * 8 + 0], 1.0f);  // the image border does not erode
    EXPECT_EQ(e1[1 * 8 + 4], 1.0f);
    EXPECT_EQ(e1[2 * 8 + 4], 0.0f);  // next to the horizon
    EXPECT_EQ(e1[4 * 8 + 4], 0.0f);
    const std::vector<float> e2 = eroded_mask(m, 2);
    EXPECT_EQ(e2[0 * 8 + 4], 1.0f);
    EXPECT_EQ(e2[1 * 8 + 4], 0.0f);
    const std::vector<float> e0 = eroded_mask(m, 0);
    EXPECT_EQ(e0[2 * 8 + 4], 1.0f);
}

TEST(SkyLosses, AlphaPenaltyIsTheMeanOverTheMask) {
    const std::vector<float> alpha = {0.5f, 1.0f, 0.2f, 0.9f}, w = {1, 0, 1, 0};
    std::vector<float> g(4, 0.0f);
    EXPECT_NEAR(alpha_penalty(alpha, w, 2.0, g), 0.35, 1e-7);
    EXPECT_FLOAT_EQ(g[0], 1.0f);  // 2 / 2 pixels
    EXPECT_FLOAT_EQ(g[1], 0.0f);
    const std::vector<float> none(4, 0.0f);
    EXPECT_EQ(alpha_penalty(alpha, none, 1.0, g), 0.0);
}

TEST(SkyLosses, SkyColourLossMatchesFiniteDifferences) {
    const std::size_t n = 30;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.05f, 0.95f);
    std::vector<float> sky(3 * n), radiance(3 * n), photo(3 * n), w(n);
    for (float& v : sky) v = u(rng);
    for (float& v : radiance) v = u(rng) - 0.3f;
    for (float& v : photo) v = u(rng);
    for (std::size_t p = 0; p < n; ++p) w[p] = p % 4 == 0 ? 0.0f : 1.0f;
    photo[3 * 5 + 1] = 0.99f;  // saturated: skipped
    std::vector<float> gs(3 * n, 0.0f), gr(3 * n, 0.0f);
    const double l = sky_colour_loss(sky, radiance, photo, w, 1.0, gs, gr);
    EXPECT_GT(l, 0.0);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(gs[3 * 5 + std::size_t(c)], 0.0f);
    EXPECT_EQ(gs[0], 0.0f);  // weight 0
    const auto value = [&] {
        std::vector<float> a(3 * n), b(3 * n);
        return sky_colour_loss(sky, radiance, photo, w, 1.0, a, b);
    };
    const auto check = [&](std::vector<float>& x, const std::vector<float>& g, const char* what) {
        for (std::size_t i = 0; i < x.size(); ++i) {
            const float x0 = x[i];
            const double h = 1e-3;
            x[i] = float(x0 + h);
            const double lp = value();
            x[i] = float(x0 - h);
            const double lm = value();
            x[i] = x0;
            EXPECT_NEAR(g[i], (lp - lm) / (double(float(x0 + h)) - double(float(x0 - h))), 2e-4) << what << i;
        }
    };
    check(sky, gs, "sky");
    check(radiance, gr, "radiance");
}

TEST(SkyLosses, BackgroundMatchNeedsSkyAboveTheHorizonAndTheMask) {
    const int w = 6, h = 4;
    const std::size_t n = std::size_t(w * h);
    std::vector<float> photo(3 * n, 0.6f), sky(3 * n, 0.61f), mask(n, 1.0f);
    std::vector<Vec3f> rays(n, Vec3f{0, 0.8f, 0.6f});
    for (int x = 0; x < w; ++x)
        rays[std::size_t(3 * w + x)] = {0, 0.8f, -0.6f};  // bottom row below the horizon
    mask[std::size_t(1 * w + 2)] = 0.0f;
    for (int c = 0; c < 3; ++c) photo[3 * std::size_t(1 * w + 5) + std::size_t(c)] = 0.0f;  // a dark pixel
    const std::vector<float> m = background_match_mask(photo, sky, mask, rays, {0, 0, 1}, w, h, 0.03);
    EXPECT_EQ(m[0], 1.0f);
    EXPECT_EQ(m[std::size_t(3 * w + 1)], 0.0f);  // below the horizon
    EXPECT_EQ(m[std::size_t(1 * w + 2)], 0.0f);  // masked out
    EXPECT_EQ(m[std::size_t(1 * w + 5)], 0.0f);  // the photo is not the sky there
    EXPECT_EQ(m[std::size_t(0 * w + 4)], 0.0f);  // nor next to it (3x3 mean)
}

}  // namespace
}  // namespace lumigauss
