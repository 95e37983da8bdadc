#include "lumigauss/train/scale_ratio_penalty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Surfels within the ratio cost nothing and get no gradient; beyond it, the excess of the log ratio.
TEST(ScaleRatioPenalty, KnownAnswer) {
    const std::vector<float> scales = {1.0f,  1.0f,   // round
                                       2.0f,  0.5f,   // ratio 4: within 10
                                       10.0f, 0.1f,   // ratio 100: excess log 10
                                       0.2f,  4.0f};  // ratio 20 the other way: excess log 2
    std::vector<float> grads(scales.size(), 0.0f);
    const double penalty = scale_ratio_penalty(scales, 10.0, 1.0, grads);
    EXPECT_NEAR(penalty, (std::log(10.0) + std::log(2.0)) / 4.0, 1e-6);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(grads[std::size_t(k)], 0.0f) << k;
    // The long side is pulled in, the short side out, by weight / n / scale.
    EXPECT_NEAR(grads[4], 0.25 / 10.0, 1e-7);
    EXPECT_NEAR(grads[5], -0.25 / 0.1, 1e-6);
    EXPECT_NEAR(grads[6], -0.25 / 0.2, 1e-6);
    EXPECT_NEAR(grads[7], 0.25 / 4.0, 1e-7);
}

// The gradient is the finite difference of weight x penalty (central differences, away from the hinge).
TEST(ScaleRatioPenalty, GradientMatchesFiniteDifferences) {
    const std::vector<float> scales = {3.0f, 0.05f, 0.4f, 0.5f, 0.02f, 1.5f, 7.0f, 0.3f};
    const double weight = 0.7, max_ratio = 6.0;
    std::vector<float> grads(scales.size(), 0.0f);
    (void)scale_ratio_penalty(scales, max_ratio, weight, grads);
    for (std::size_t k = 0; k < scales.size(); ++k) {
        const float h = scales[k] * 1e-3f;
        std::vector<float> plus = scales, minus = scales, ignored(scales.size());
        plus[k] += h, minus[k] -= h;
        const double fd = weight *
                          (scale_ratio_penalty(plus, max_ratio, 1.0, ignored) -
                           scale_ratio_penalty(minus, max_ratio, 1.0, ignored)) /
                          (double(plus[k]) - double(minus[k]));
        EXPECT_NEAR(grads[k], fd, 1e-3 * std::abs(fd) + 1e-6) << "value " << k;
    }
}

// The pull adds to what the rasterizer's backward pass left in the gradient.
TEST(ScaleRatioPenalty, AddsToTheGradientItIsGiven) {
    const std::vector<float> scales = {5.0f, 0.1f};
    std::vector<float> grads = {1.0f, 2.0f};
    (void)scale_ratio_penalty(scales, 2.0, 1.0, grads);
    EXPECT_NEAR(grads[0], 1.0f + 1.0f / 5.0f, 1e-6);
    EXPECT_NEAR(grads[1], 2.0f - 1.0f / 0.1f, 1e-5);
}

TEST(ScaleRatioPenalty, EmptyModelAndMismatchedSizes) {
    std::vector<float> none;
    EXPECT_EQ(scale_ratio_penalty(none, 10.0, 1.0, none), 0.0);
    std::vector<float> odd = {1.0f}, two(2), scales = {1.0f, 2.0f};
    EXPECT_THROW((void)scale_ratio_penalty(odd, 10.0, 1.0, odd), Error);
    EXPECT_THROW((void)scale_ratio_penalty(scales, 10.0, 1.0, odd), Error);
}

}  // namespace
}  // namespace lumigauss
