// Masked L1 and D-SSIM: known answers, an independent direct SSIM, and finite differences of the
// hand-written backward in double precision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/train/image_losses.h"

namespace lumigauss {
namespace {

constexpr ImageShape kShape{13, 11, 3};

std::vector<double> random_values(std::size_t n, double lo, double hi, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<double> v(n);
    for (double& x : v) x = u(rng);
    return v;
}

// Soft mask with some exact zeros and ones, as eroded or resized masks have.
std::vector<double> random_mask(std::size_t n, unsigned seed) {
    std::vector<double> m = random_values(n, -0.5, 1.5, seed);
    for (double& x : m) x = std::clamp(x, 0.0, 1.0);
    return m;
}

// SSIM_m written directly from its definition: 2-D 11x11 window over in-bounds neighbours (zero padding),
// population moments, no separable pass, no shared code with the library.
double direct_ssim(const ImageShape& s, const std::vector<double>& a, const std::vector<double>& b,
                   const std::vector<double>& mask) {
    double g[11], gsum = 0;
    for (int i = 0; i < 11; ++i) gsum += g[i] = std::exp(-(i - 5) * (i - 5) / (2 * 1.5 * 1.5));
    for (double& v : g) v /= gsum;
    double num = 0, msum = 0;
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const double m = mask.empty() ? 1.0 : mask[std::size_t(y) * s.width + x];
            msum += m;
            for (int c = 0; c < s.channels; ++c) {
                double mu1 = 0, mu2 = 0, e11 = 0, e22 = 0, e12 = 0;
                for (int dy = -5; dy <= 5; ++dy) {
                    for (int dx = -5; dx <= 5; ++dx) {
                        const int yy = y + dy, xx = x + dx;
                        if (yy < 0 || yy >= s.height || xx < 0 || xx >= s.width) continue;
                        const double wgt = g[dy + 5] * g[dx + 5];
                        const std::size_t i = (std::size_t(yy) * s.width + xx) * s.channels + c;
                        mu1 += wgt * a[i], mu2 += wgt * b[i];
                        e11 += wgt * a[i] * a[i], e22 += wgt * b[i] * b[i], e12 += wgt * a[i] * b[i];
                    }
                }
                const double c1 = 1e-4, c2 = 9e-4;
                const double v1 = e11 - mu1 * mu1, v2 = e22 - mu2 * mu2, cov = e12 - mu1 * mu2;
                const double ssim =
                    (2 * mu1 * mu2 + c1) * (2 * cov + c2) / ((mu1 * mu1 + mu2 * mu2 + c1) * (v1 + v2 + c2));
                num += m * ssim;
            }
        }
    }
    if (mask.empty()) return num / double(s.values());
    return num / (s.channels * msum + 1e-6);
}

using LossFn = double (*)(const ImageShape&, std::span<const double>, std::span<const double>,
                          std::span<const double>, double, std::span<double>);

// Central differences of every input value against the analytic gradient.
void expect_gradient_matches(LossFn loss, const std::vector<double>& x, const std::vector<double>& y,
                             const std::vector<double>& mask, double step, double tol) {
    std::vector<double> grad(x.size(), 0.0);
    const double weight = 0.7;  // the backward must scale by the weight
    loss(kShape, x, y, mask, weight, grad);
    std::vector<double> xp = x;
    for (std::size_t i = 0; i < x.size(); ++i) {
        xp[i] = x[i] + step;
        const double up = loss(kShape, xp, y, mask, 0.0, {});
        xp[i] = x[i] - step;
        const double down = loss(kShape, xp, y, mask, 0.0, {});
        xp[i] = x[i];
        const double fd = weight * (up - down) / (2 * step);
        EXPECT_NEAR(grad[i], fd, tol * (1 + std::abs(fd))) << "value " << i;
    }
}

TEST(TrainLossL1, ConstantOffsetGivesOffset) {
    const auto target = random_values(kShape.values(), 0, 1, 1);
    std::vector<double> rendered = target;
    for (double& v : rendered) v += 0.1;
    EXPECT_NEAR(masked_l1_loss<double>(kShape, rendered, target, {}, 1.0, {}), 0.1, 1e-12);
    // Masked: 0.1 * C * sum(m) / (C * sum(m) + 1e-6).
    const auto mask = random_mask(kShape.pixels(), 2);
    double msum = 0;
    for (double m : mask) msum += m;
    const double expected = 0.1 * 3 * msum / (3 * msum + 1e-6);
    EXPECT_NEAR(masked_l1_loss<double>(kShape, rendered, target, mask, 1.0, {}), expected, 1e-12);
}

TEST(TrainLossL1, MaskedOutPixelsAreIgnored) {
    const auto target = random_values(kShape.values(), 0, 1, 3);
    auto rendered = random_values(kShape.values(), 0, 1, 4);
    std::vector<double> mask(kShape.pixels(), 1.0);
    for (std::size_t p = 0; p < mask.size(); p += 2) mask[p] = 0.0;
    const double before = masked_l1_loss<double>(kShape, rendered, target, mask, 1.0, {});
    std::vector<double> grad(kShape.values(), 0.0);
    for (std::size_t c = 0; c < 3; ++c) rendered[c] += 5.0;  // pixel 0 is masked out
    EXPECT_EQ(masked_l1_loss<double>(kShape, rendered, target, mask, 1.0, grad), before);
    EXPECT_EQ(grad[0], 0.0);
}

TEST(TrainLossL1, GradientMatchesFiniteDifferences) {
    const auto x = random_values(kShape.values(), 0, 1, 5);
    const auto y = random_values(kShape.values(), 0, 1, 6);  // |x - y| >> step almost surely
    expect_gradient_matches(&masked_l1_loss<double>, x, y, random_mask(kShape.pixels(), 7), 1e-7, 1e-6);
    expect_gradient_matches(&masked_l1_loss<double>, x, y, {}, 1e-7, 1e-6);
}

TEST(TrainLossSsim, IdenticalImagesGiveZeroLoss) {
    const auto x = random_values(kShape.values(), 0, 1, 8);
    EXPECT_NEAR(masked_dssim_loss<double>(kShape, x, x, {}, 1.0, {}), 0.0, 1e-12);
    // With a mask the official 1e-6 in the denominator leaves 1e-6 / (C sum(m) + 1e-6).
    const auto mask = random_mask(kShape.pixels(), 9);
    EXPECT_NEAR(masked_dssim_loss<double>(kShape, x, x, mask, 1.0, {}), 0.0, 1e-8);
    // And the gradient vanishes at the optimum.
    std::vector<double> grad(kShape.values(), 0.0);
    masked_dssim_loss<double>(kShape, x, x, {}, 1.0, grad);
    for (double g : grad) EXPECT_NEAR(g, 0.0, 1e-12);
}

TEST(TrainLossSsim, MatchesDirectImplementation) {
    for (unsigned seed : {10u, 20u, 30u}) {
        const auto x = random_values(kShape.values(), 0, 1, seed);
        const auto y = random_values(kShape.values(), 0, 1, seed + 1);
        const auto mask = random_mask(kShape.pixels(), seed + 2);
        EXPECT_NEAR(1 - masked_dssim_loss<double>(kShape, x, y, mask, 1.0, {}),
                    direct_ssim(kShape, x, y, mask), 1e-9);
        EXPECT_NEAR(1 - masked_dssim_loss<double>(kShape, x, y, {}, 1.0, {}), direct_ssim(kShape, x, y, {}),
                    1e-9);
    }
}

TEST(TrainLossSsim, SmallerThanWindowAndSingleChannel) {
    const ImageShape s{4, 3, 1};  // every window is clipped by the zero padding
    const auto x = random_values(s.values(), 0, 1, 40);
    const auto y = random_values(s.values(), 0, 1, 41);
    EXPECT_NEAR(1 - masked_dssim_loss<double>(s, x, y, {}, 1.0, {}), direct_ssim(s, x, y, {}), 1e-9);
}

TEST(TrainLossSsim, GradientMatchesFiniteDifferences) {
    // Correlated images, so that SSIM is far from both 0 and 1 and every statistic matters.
    const auto y = random_values(kShape.values(), 0, 1, 11);
    auto x = random_values(kShape.values(), -0.3, 0.3, 12);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += y[i];
    expect_gradient_matches(&masked_dssim_loss<double>, x, y, random_mask(kShape.pixels(), 13), 1e-5, 1e-6);
    expect_gradient_matches(&masked_dssim_loss<double>, x, y, {}, 1e-5, 1e-6);
}

TEST(TrainLossSsim, FloatMatchesDoubleAndIsDeterministic) {
    const ImageShape s{157, 123, 3};  // large enough for TBB to split the rows
    const auto xd = random_values(s.values(), 0, 1, 14);
    const auto yd = random_values(s.values(), 0, 1, 15);
    const auto md = random_mask(s.pixels(), 16);
    const std::vector<float> xf(xd.begin(), xd.end()), yf(yd.begin(), yd.end()), mf(md.begin(), md.end());
    const double ref = masked_dssim_loss<double>(s, xd, yd, md, 1.0, {});
    std::vector<float> g1(s.values(), 0.0f), g2(s.values(), 0.0f);
    const float a = masked_dssim_loss<float>(s, xf, yf, mf, 1.0f, g1);
    const float b = masked_dssim_loss<float>(s, xf, yf, mf, 1.0f, g2);
    EXPECT_NEAR(a, ref, 1e-5);
    EXPECT_EQ(a, b);
    EXPECT_EQ(g1, g2);
    const float l1a = masked_l1_loss<float>(s, xf, yf, mf, 1.0f, g1);
    const float l1b = masked_l1_loss<float>(s, xf, yf, mf, 1.0f, g2);
    EXPECT_EQ(l1a, l1b);
    EXPECT_EQ(g1, g2);
}

TEST(TrainLossSsim, RejectsMismatchedSizes) {
    const auto x = random_values(kShape.values(), 0, 1, 17);
    const std::vector<double> short_mask(3, 1.0);
    EXPECT_ANY_THROW(masked_dssim_loss<double>(kShape, x, x, short_mask, 1.0, {}));
    EXPECT_ANY_THROW(masked_l1_loss<double>(kShape, x, std::span<const double>(x).first(5), {}, 1.0, {}));
}

}  // namespace
}  // namespace lumigauss
