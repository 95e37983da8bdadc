// Image metrics of the evaluation (io/image_metrics.h) against known answers: identical images, a constant
// offset, closed-form SSIM cases, an independent direct evaluation of the skimage SSIM formula, masks,
// erosion, normal angles and the per-channel scale.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/io/image_metrics.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

Image random_image(int w, int h, int c, unsigned seed, float lo = 0.f, float hi = 1.f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(lo, hi);
    Image im(w, h, c);
    for (float& v : im.pixels) v = u(rng);
    return im;
}

Image ones(int w, int h) {
    return Image(w, h, 1, 1.0f);
}

// ---- MSE / MAE / PSNR -------------------------------------------------------------------------------------

TEST(EvalMetrics, IdenticalImagesGiveZeroErrorPsnrCapAndSsimOne) {
    const Image x = random_image(20, 16, 3, 1);
    const ImageMetrics m = image_metrics(x, x, ones(20, 16));
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_EQ(m.mae, 0.0);
    EXPECT_DOUBLE_EQ(m.psnr, kPsnrCap);
    EXPECT_DOUBLE_EQ(m.psnr, 60.0);  // -10 log10(0 + 1e-6)
    EXPECT_NEAR(m.ssim, 1.0, 1e-12);
}

TEST(EvalMetrics, ConstantOffsetGivesKnownMseMaePsnr) {
    // Dyadic values: the offset is exact in float.
    const int w = 12, h = 10;
    const double d = 1.0 / 16;
    Image x(w, h, 3), y(w, h, 3);
    for (std::size_t i = 0; i < x.pixels.size(); ++i) {
        x.pixels[i] = float(double(i % 32) / 64.0);
        y.pixels[i] = float(double(x.pixels[i]) + d);
    }
    const double n = double(w * h);
    const double mse = 3 * n * d * d / (3 * n + 1e-6);  // the official denominator keeps its 1e-6
    const double mae = 3 * n * d / (3 * n + 1e-6);
    EXPECT_NEAR(masked_mse(x, y, ones(w, h)), mse, 1e-15);
    EXPECT_NEAR(masked_mae(x, y, ones(w, h)), mae, 1e-15);
    EXPECT_NEAR(psnr_from_mse(masked_mse(x, y, ones(w, h))), -10 * std::log10(mse + 1e-6), 1e-12);
    // 20 log10(16) = 24.0824 dB, less the 1e-6 inside the log: 10 log10(1 + 256e-6) = 0.00111 dB.
    EXPECT_NEAR(psnr_from_mse(d * d), 20 * std::log10(16.0) - 10 * std::log10(1 + 256e-6), 1e-12);
    EXPECT_NEAR(psnr_from_mse(d * d), 24.08129, 1e-5);
    // Symmetric in the two images.
    EXPECT_EQ(masked_mse(x, y, ones(w, h)), masked_mse(y, x, ones(w, h)));
}

TEST(EvalMetrics, PsnrFormula) {
    EXPECT_NEAR(psnr_from_mse(1e-2 - 1e-6), 20.0, 1e-12);
    EXPECT_NEAR(psnr_from_mse(1e-3 - 1e-6), 30.0, 1e-12);
}

TEST(EvalMetrics, MaskSelectsPixelsAndWeighs) {
    const int w = 8, h = 6;
    Image x = random_image(w, h, 3, 2), y = x;
    Image mask(w, h, 1, 0.0f);
    // Garbage outside the mask, an offset of 0.25 on the masked pixels.
    for (int yy = 0; yy < h; ++yy)
        for (int xx = 0; xx < w; ++xx)
            for (int c = 0; c < 3; ++c) {
                if (xx < 3) {
                    mask.at(xx, yy, 0) = 1.0f;
                    y.at(xx, yy, c) = x.at(xx, yy, c) + 0.25f;
                } else {
                    y.at(xx, yy, c) = 1.0f - x.at(xx, yy, c) + 7.0f;
                }
            }
    const double m = 3.0 * h;  // masked pixels
    const double expected = 3 * m * 0.0625 / (3 * m + 1e-6);
    EXPECT_NEAR(masked_mse(x, y, mask), expected, 1e-6);
    EXPECT_NEAR(masked_mae(x, y, mask), 3 * m * 0.25 / (3 * m + 1e-6), 1e-6);
    // Identical inside the mask: no error, whatever is outside.
    Image z = y;
    for (int yy = 0; yy < h; ++yy)
        for (int xx = 0; xx < 3; ++xx)
            for (int c = 0; c < 3; ++c) z.at(xx, yy, c) = x.at(xx, yy, c);
    EXPECT_EQ(masked_mse(x, z, mask), 0.0);
    // Soft weights: sum m (x-y)^2 / (C sum m + 1e-6).
    Image soft(w, h, 1, 0.5f);
    const Image off = random_image(w, h, 3, 3);
    double num = 0;
    for (std::size_t i = 0; i < x.pixels.size(); ++i)
        num += 0.5 * std::pow(double(x.pixels[i]) - double(off.pixels[i]), 2);
    EXPECT_NEAR(masked_mse(x, off, soft), num / (3 * 0.5 * w * h + 1e-6), 1e-12);
    // SSIM: the mean of the map over the masked pixels and channels.
    const Image a = random_image(w, h, 3, 4), b = random_image(w, h, 3, 5);
    const Image s = ssim_map(a, b);
    double sum = 0;
    for (int yy = 0; yy < h; ++yy)
        for (int xx = 0; xx < 3; ++xx)
            for (int c = 0; c < 3; ++c) sum += s.at(xx, yy, c);
    EXPECT_NEAR(masked_ssim(a, b, mask), sum / (3 * m), 1e-7);  // the map is stored in float
    EXPECT_TRUE(std::isnan(masked_ssim(a, b, Image(w, h, 1, 0.0f))));
}

TEST(EvalMetrics, ShapeMismatchThrows) {
    const Image a = random_image(8, 6, 3, 1), b = random_image(8, 7, 3, 2);
    EXPECT_THROW(masked_mse(a, b, ones(8, 6)), Error);
    EXPECT_THROW(masked_mse(a, a, ones(8, 7)), Error);
    EXPECT_THROW(ssim_map(random_image(4, 8, 1, 3), random_image(4, 8, 1, 3)), Error);  // smaller than 5
    SsimOptions even;
    even.win_size = 4;
    EXPECT_THROW(ssim_map(a, a, even), Error);
}

// ---- SSIM -------------------------------------------------------------------------------------------------

TEST(EvalMetrics, SsimOfConstantImagesIsTheLuminanceTerm) {
    // Constant images have zero variance, so S = (2ab + C1) / (a^2 + b^2 + C1) exactly (C2 / C2 = 1).
    const double a = 0.25, b = 0.75, c1 = 0.01 * 0.01;
    const Image x(9, 7, 3, float(a)), y(9, 7, 3, float(b));
    const double expected = (2 * a * b + c1) / (a * a + b * b + c1);
    EXPECT_NEAR(masked_ssim(x, y, ones(9, 7)), expected, 1e-9);
    EXPECT_NEAR(expected, 0.600064, 1e-6);
    // The same offset on a textured image: variances equal and the covariance equals them, so the
    // structure term is 1 and S is the luminance term of the local means (interior pixel: no reflection).
    Image t = random_image(9, 7, 1, 7, 0.2f, 0.4f), u = t;
    for (float& v : u.pixels) v += 0.5f;
    double m = 0;
    for (int yy = 1; yy <= 5; ++yy)
        for (int xx = 2; xx <= 6; ++xx) m += double(t.at(xx, yy, 0)) / 25;
    const double luminance = (2 * m * (m + 0.5) + c1) / (m * m + (m + 0.5) * (m + 0.5) + c1);
    EXPECT_NEAR(ssim_map(t, u).at(4, 3, 0), luminance, 1e-5);
}

// Direct evaluation of skimage's formula, written independently of io/image_metrics.cpp: the window's
// 25 values gathered from a symmetrically padded copy (numpy.pad mode "symmetric" == scipy's "reflect"),
// two-pass sample mean / variance / covariance with the N - 1 denominator.
double reference_ssim_at(const Image& x, const Image& y, int px, int py, int c) {
    const int r = 2;
    auto mirror = [](int i, int n) {
        while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - i - 1;
        return i;
    };
    std::vector<double> a, b;
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
            const int sx = mirror(px + dx, x.width), sy = mirror(py + dy, x.height);
            a.push_back(x.at(sx, sy, c));
            b.push_back(y.at(sx, sy, c));
        }
    const double n = double(a.size());
    double ma = 0, mb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
    double va = 0, vb = 0, cab = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        va += (a[i] - ma) * (a[i] - ma) / (n - 1);
        vb += (b[i] - mb) * (b[i] - mb) / (n - 1);
        cab += (a[i] - ma) * (b[i] - mb) / (n - 1);
    }
    const double c1 = 1e-4, c2 = 9e-4;
    return (2 * ma * mb + c1) * (2 * cab + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
}

TEST(EvalMetrics, SsimMatchesDirectEvaluationOfTheSkimageFormula) {
    for (auto [w, h] : {std::pair{9, 7}, std::pair{5, 5}, std::pair{6, 11}}) {
        const Image x = random_image(w, h, 3, unsigned(w * 100 + h));
        Image y = x;
        std::mt19937 rng(unsigned(w + h));
        std::normal_distribution<float> noise(0.f, 0.15f);
        for (float& v : y.pixels) v = std::clamp(0.8f * v + 0.1f + noise(rng), 0.f, 1.f);
        const Image s = ssim_map(x, y);
        double mean = 0;
        for (int py = 0; py < h; ++py)
            for (int px = 0; px < w; ++px)
                for (int c = 0; c < 3; ++c) {
                    const double ref = reference_ssim_at(x, y, px, py, c);
                    EXPECT_NEAR(s.at(px, py, c), ref, 2e-6) << w << "x" << h << " at " << px << "," << py;
                    mean += ref / (3.0 * w * h);
                }
        EXPECT_NEAR(masked_ssim(x, y, ones(w, h)), mean, 1e-6);
    }
}

TEST(EvalMetrics, SsimHandComputedFiveByFive) {
    // 5x5 images: at the centre pixel the window is the whole image, no reflection. x = 0..24 / 24 in
    // reading order, y = 1 - x (perfectly anti-correlated). mu_x = mu_y = 0.5; sample variance (N - 1
    // denominator) sum (i - 12)^2 / 24 / 24^2 = 1300 / 24 / 576 = 0.0940394 = v_x = v_y, v_xy = -v_x. So
    // S = (2 * 0.25 + C1)(-2v + C2) / ((0.5 + C1)(2v + C2)) = (-0.187179) / (0.188979) = -0.990475.
    Image x(5, 5, 1), y(5, 5, 1);
    for (int i = 0; i < 25; ++i)
        x.pixels[std::size_t(i)] = float(i) / 24.f, y.pixels[std::size_t(i)] = 1.f - float(i) / 24.f;
    const double v = 1300.0 / 24.0 / 576.0, c1 = 1e-4, c2 = 9e-4;
    const double expected = (2 * 0.25 + c1) * (-2 * v + c2) / ((0.5 + c1) * (2 * v + c2));
    EXPECT_NEAR(expected, -0.990475, 2e-6);
    EXPECT_NEAR(ssim_map(x, y).at(2, 2, 0), expected, 1e-6);
}

// ---- Masks ----------------------------------------------------------------------------------------------

TEST(EvalMetrics, ErosionIsAFiveByFiveMinimumIgnoringTheBorder) {
    Image m = ones(20, 16);
    m.at(10, 8, 0) = 0.0f;
    m.at(0, 0, 0) = 0.5f;
    const Image e = erode_mask(m, 5, 1);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 20; ++x) {
            float expected = 1.0f;
            if (std::abs(x - 10) <= 2 && std::abs(y - 8) <= 2)
                expected = 0.0f;
            else if (x <= 2 && y <= 2)
                expected = 0.5f;
            EXPECT_EQ(e.at(x, y, 0), expected) << x << "," << y;
        }
    // The image border itself does not erode (cv2.erode's default border value).
    EXPECT_EQ(erode_mask(ones(7, 7)).pixels, ones(7, 7).pixels);
    // Twice = a 9x9 minimum.
    const Image e2 = erode_mask(m, 5, 2);
    EXPECT_EQ(e2.at(14, 8, 0), 0.0f);
    EXPECT_EQ(e2.at(15, 8, 0), 1.0f);
}

TEST(EvalMetrics, OfficialMaskKeepsOnlyFullCoverage) {
    Image grey = ones(12, 12);
    grey.at(11, 0, 0) = 254.f / 255.f;  // anti-aliased edge pixel
    const Image m = official_eval_mask(grey);
    EXPECT_EQ(m.at(11, 0, 0), 0.0f);
    EXPECT_EQ(m.at(9, 2, 0), 0.0f);  // within 2 of it
    EXPECT_EQ(m.at(8, 0, 0), 1.0f);
    EXPECT_EQ(m.at(5, 5, 0), 1.0f);
    EXPECT_EQ(mask_pixels(m), std::size_t(144 - 9));
}

// ---- Normals and scales -----------------------------------------------------------------------------------

TEST(EvalMetrics, NormalAnglesMeanMedianAndMissing) {
    EXPECT_NEAR(angle_deg({1, 0, 0}, {1, 0, 0}), 0.0, 1e-12);
    EXPECT_NEAR(angle_deg({1, 0, 0}, {0, 2, 0}), 90.0, 1e-12);
    EXPECT_NEAR(angle_deg({1, 0, 0}, {-3, 0, 0}), 180.0, 1e-12);
    EXPECT_TRUE(std::isnan(angle_deg({0, 0, 0}, {1, 0, 0})));

    // Five pixels: angles 10, 20, 30, 40 degrees about z (lengths vary), one with no prediction, one
    // masked out, one with no ground truth.
    const int w = 8;
    Image pred(w, 1, 3), truth(w, 1, 3), mask(w, 1, 1, 1.0f);
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < 4; ++i) {
        const double a = (10.0 * (i + 1)) * pi / 180;
        truth.at(i, 0, 0) = 1.0f;
        pred.at(i, 0, 0) = float(2 * std::cos(a)), pred.at(i, 0, 1) = float(2 * std::sin(a));
    }
    truth.at(4, 0, 2) = 1.0f;  // pred (0,0,0): missing -> 90
    truth.at(5, 0, 0) = 1.0f, pred.at(5, 0, 0) = -1.0f, mask.at(5, 0, 0) = 0.0f;  // masked out
    pred.at(6, 0, 1) = 1.0f;                                                      // no ground truth
    pred.at(7, 0, 1) = 1.0f, truth.at(7, 0, 1) = 1.0f, mask.at(7, 0, 0) = 0.0f;
    std::vector<double> pooled;
    const AngularErrorStats s = normal_angular_error(pred, truth, mask, 1e-3, &pooled);
    EXPECT_EQ(s.pixels, 5u);
    EXPECT_EQ(s.missing, 1u);
    EXPECT_NEAR(s.mean_deg, (10 + 20 + 30 + 40 + 90) / 5.0, 1e-5);
    EXPECT_NEAR(s.median_deg, 30.0, 1e-5);
    EXPECT_EQ(pooled.size(), 5u);
    const AngularErrorStats even = angle_stats({40, 10, 30, 20});
    EXPECT_DOUBLE_EQ(even.median_deg, 25.0);
    EXPECT_DOUBLE_EQ(even.mean_deg, 25.0);
    EXPECT_TRUE(std::isnan(angle_stats({}).mean_deg));
}

TEST(EvalMetrics, PerChannelScaleIsRecoveredExactly) {
    const Image x = random_image(10, 8, 3, 9, 0.1f, 0.9f);
    Image y = x;
    const double k[3] = {2.0, 0.5, 0.25};
    for (std::size_t i = 0; i < y.pixels.size(); ++i) y.pixels[i] = float(x.pixels[i] * k[i % 3]);
    Image mask = ones(10, 8);
    mask.at(0, 0, 0) = 0.0f;
    ScaleFitTerms terms;
    add_scale_terms(x, y, mask, terms);
    add_scale_terms(x, y, mask, terms);  // pooling the same pair twice changes nothing
    const auto s = scale_from_terms(terms);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[std::size_t(c)], k[c], 1e-6);
    EXPECT_NEAR(masked_mse(scale_channels(x, s), y, mask), 0.0, 1e-12);
    EXPECT_EQ(scale_from_terms(ScaleFitTerms{})[0], 1.0);  // nothing to fit: 1
}

TEST(EvalMetrics, Clamp01) {
    Image x(2, 1, 2);
    x.pixels = {-0.5f, 0.25f, 1.5f, std::nanf("")};
    EXPECT_EQ(clamp01(x).pixels, (std::vector<float>{0.f, 0.25f, 1.f, 0.f}));
}

}  // namespace
}  // namespace lumigauss
