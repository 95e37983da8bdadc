#include "lumigauss/train/sky_losses.h"

#include <algorithm>
#include <cmath>

#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

constexpr double kCosineWeight = 0.1;
constexpr double kNormEps = 1e-6;
constexpr double kLinearWeight = 0.1;
constexpr double kGamma = 2.2;

}  // namespace

std::vector<float> eroded_mask(const Image& mask, int radius) {
    const int w = mask.width, h = mask.height;
    std::vector<float> out(std::size_t(w) * std::size_t(h), 0.0f);
    // Separable: a horizontal then a vertical running minimum of the binarised mask.
    std::vector<float> rows(out.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = 1.0f;
            for (int dx = -radius; dx <= radius && v > 0; ++dx) {
                const int xx = x + dx;
                if (xx >= 0 && xx < w && !(mask.at(xx, y, 0) >= 0.5f)) v = 0.0f;
            }
            rows[std::size_t(y) * std::size_t(w) + std::size_t(x)] = v;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = 1.0f;
            for (int dy = -radius; dy <= radius && v > 0; ++dy) {
                const int yy = y + dy;
                if (yy >= 0 && yy < h && rows[std::size_t(yy) * std::size_t(w) + std::size_t(x)] == 0.0f)
                    v = 0.0f;
            }
            out[std::size_t(y) * std::size_t(w) + std::size_t(x)] = v;
        }
    return out;
}

double alpha_penalty(std::span<const float> alpha, std::span<const float> weights, double weight,
                     std::span<float> g_alpha) {
    if (alpha.size() != weights.size() || g_alpha.size() != alpha.size())
        throw Error("alpha_penalty: the maps differ in size");
    double total = 0, sum = 0;
    for (std::size_t p = 0; p < alpha.size(); ++p) total += weights[p], sum += double(weights[p]) * alpha[p];
    if (!(total > 0)) return 0.0;
    const double scale = weight / total;
    for (std::size_t p = 0; p < alpha.size(); ++p)
        if (weights[p] != 0) g_alpha[p] += float(scale * weights[p]);
    return sum / total;
}

double sky_colour_loss(std::span<const float> sky, std::span<const float> radiance,
                       std::span<const float> photo, std::span<const float> sky_weight, double weight,
                       std::span<float> g_sky, std::span<float> g_radiance) {
    const std::size_t pixels = sky_weight.size();
    if (sky.size() != 3 * pixels || radiance.size() != 3 * pixels || photo.size() != 3 * pixels ||
        g_sky.size() != 3 * pixels || g_radiance.size() != 3 * pixels)
        throw Error("sky_colour_loss: the maps differ in size");
    std::vector<std::size_t> used;
    for (std::size_t p = 0; p < pixels; ++p) {
        if (!(sky_weight[p] > 0)) continue;
        const bool saturated =
            std::max({photo[3 * p], photo[3 * p + 1], photo[3 * p + 2]}) >= float(kSaturatedPhoto);
        if (!saturated) used.push_back(p);
    }
    if (used.empty()) return 0.0;
    const double inv_n = 1.0 / double(used.size());
    double loss = 0;
    for (std::size_t p : used) {
        const Vec3d s{sky[3 * p], sky[3 * p + 1], sky[3 * p + 2]};
        const Vec3d i{photo[3 * p], photo[3 * p + 1], photo[3 * p + 2]};
        const double ns = length(s) + kNormEps, ni = length(i) + kNormEps;
        const double cosine = dot(s, i) / (ns * ni);
        loss += (std::abs(s.x - i.x) + std::abs(s.y - i.y) + std::abs(s.z - i.z)) / 3.0 +
                kCosineWeight * (1.0 - cosine);
        for (int c = 0; c < 3; ++c) {
            const double d = double(radiance[3 * p + std::size_t(c)]) - std::pow(i[c], kGamma);
            loss += kLinearWeight * std::abs(d) / 3.0;
            g_radiance[3 * p + std::size_t(c)] += float(weight * inv_n * kLinearWeight *
                                                        (d > 0   ? 1
                                                         : d < 0 ? -1
                                                                 : 0) /
                                                        3.0);
        }
        // d cos / d s = i / (ns ni) - cos s / (|s| ns), with |s| ~ ns (the epsilon only guards a black sky).
        const Vec3d g_cos = (1.0 / (ns * ni)) * i - (cosine / (ns * std::max(length(s), kNormEps))) * s;
        for (int c = 0; c < 3; ++c) {
            const double d = s[c] - i[c];
            const double g = (d > 0 ? 1.0 : d < 0 ? -1.0 : 0.0) / 3.0 - kCosineWeight * g_cos[c];
            g_sky[3 * p + std::size_t(c)] += float(weight * inv_n * g);
        }
    }
    return loss * inv_n;
}

std::vector<float> background_match_mask(std::span<const float> photo, std::span<const float> sky,
                                         std::span<const float> photometric_mask, std::span<const Vec3f> rays,
                                         Vec3f up, int width, int height, double tolerance) {
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    if (photo.size() != 3 * pixels || sky.size() != 3 * pixels || photometric_mask.size() != pixels ||
        rays.size() != pixels)
        throw Error("background_match_mask: the maps differ in size");
    std::vector<float> diff(pixels);
    for (std::size_t p = 0; p < pixels; ++p)
        diff[p] = (std::abs(photo[3 * p] - sky[3 * p]) + std::abs(photo[3 * p + 1] - sky[3 * p + 1]) +
                   std::abs(photo[3 * p + 2] - sky[3 * p + 2])) /
                  3.0f;
    std::vector<float> out(pixels, 0.0f);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
            if (!(photometric_mask[p] >= 0.5f) || !(dot(up, rays[p]) > 0.0f)) continue;
            double sum = 0;
            int count = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
                    sum += diff[std::size_t(yy) * std::size_t(width) + std::size_t(xx)], ++count;
                }
            if (sum < tolerance * count) out[p] = 1.0f;
        }
    return out;
}

void SkyResidualGradients::reset(const SkyResiduals& residuals) {
    values_.assign(residuals.params().size(), 0.0f);
}

void SkyResidualGradients::add(int image, const Sh4Coeffs<float>& g) {
    float* row = values_.data() + std::size_t(image) * SkyResiduals::kRowWidth;
    for (int k = 0; k < kSh4Count; ++k)
        for (int c = 0; c < 3; ++c) row[3 * k + c] += g.c[k][c];
}

}  // namespace lumigauss
