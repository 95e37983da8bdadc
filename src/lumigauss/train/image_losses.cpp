#include "lumigauss/train/image_losses.h"

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "lumigauss/train/row_parallel.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/multiversion.h"

namespace lumigauss {
namespace {

constexpr int kWindow = 11;
constexpr int kRadius = kWindow / 2;  // torch conv2d padding = window_size // 2
constexpr double kSigma = 1.5;
constexpr double kC1 = 0.01 * 0.01;
constexpr double kC2 = 0.03 * 0.03;
constexpr double kMaskEps = 1e-6;  // the official denominators add 1e-6 to C * sum(mask)

void require(bool ok, const char* what) {
    if (!ok) throw Error(std::string("image loss: ") + what);
}

using train_detail::for_each_row;
using train_detail::sum_in_order;

template <typename T>
void check_inputs(const ImageShape& shape, std::span<const T> rendered, std::span<const T> target,
                  std::span<const T> mask, std::span<T> grad) {
    require(shape.width > 0 && shape.height > 0 && shape.channels > 0, "empty image");
    require(rendered.size() == shape.values() && target.size() == shape.values(),
            "image sizes do not match the shape");
    require(mask.empty() || mask.size() == shape.pixels(), "mask size does not match the image");
    require(grad.empty() || grad.size() == shape.values(), "gradient size does not match the image");
}

// Per-pixel weight of the masked mean: m_p / (C sum m + 1e-6), or 1 / (C H W) without a mask.
template <typename T>
struct MaskedMean {
    std::span<const T> mask;
    T inv_denominator = 0;

    MaskedMean(const ImageShape& shape, std::span<const T> m) : mask(m) {
        if (mask.empty()) {
            inv_denominator = T(1) / T(shape.values());
        } else {
            T sum = 0;
            for (T v : mask) sum += v;
            inv_denominator = T(1) / (T(shape.channels) * sum + T(kMaskEps));
        }
    }
    T mask_at(std::size_t p) const { return mask.empty() ? T(1) : mask[p]; }
    T weight_at(std::size_t p) const { return mask_at(p) * inv_denominator; }
};

// The official window: normalised 1-D Gaussian; the 2-D window is its outer product.
template <typename T>
std::array<T, kWindow> gaussian_window() {
    std::array<double, kWindow> g{};
    double sum = 0;
    for (int i = 0; i < kWindow; ++i) {
        const double d = i - kRadius;
        g[i] = std::exp(-d * d / (2 * kSigma * kSigma));
        sum += g[i];
    }
    std::array<T, kWindow> out{};
    for (int i = 0; i < kWindow; ++i) out[i] = T(g[i] / sum);
    return out;
}

// dst[i] += a * src[i]: the whole inner loop of the blur, compiled for baseline x86-64, AVX2 and AVX-512.
LG_MULTIVERSION void axpy(float* dst, const float* src, float a, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) dst[i] += a * src[i];
}
LG_MULTIVERSION void axpy(double* dst, const double* src, double a, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) dst[i] += a * src[i];
}

// Zero-padded 11x11 Gaussian blur of `k` interleaved values per pixel, as two 1-D passes (exact for a
// separable window with zero padding). The window is symmetric, so this map is its own adjoint: the
// backward of the windowed statistics is the same blur applied to their gradients.
template <typename T>
std::vector<T> blur(const std::vector<T>& in, int width, int height, int k) {
    static const std::array<T, kWindow> g = gaussian_window<T>();
    const std::size_t row = std::size_t(width) * k;
    std::vector<T> tmp(in.size(), T(0)), out(in.size(), T(0));
    for_each_row(height, [&](int y) {
        const T* src = in.data() + y * row;
        T* dst = tmp.data() + y * row;
        // One contiguous axpy per tap over the pixels where it lands inside the row (vectorises).
        for (int t = 0; t < kWindow; ++t) {
            const int x0 = std::max(0, kRadius - t), x1 = std::min(width, width + kRadius - t);
            if (x1 <= x0) continue;
            const std::size_t first = std::size_t(x0) * k;
            axpy(dst + first, src + std::ptrdiff_t(t - kRadius) * k + first, g[t], std::size_t(x1 - x0) * k);
        }
    });
    for_each_row(height, [&](int y) {
        T* dst = out.data() + y * row;
        for (int t = 0; t < kWindow; ++t) {
            const int yy = y + t - kRadius;
            if (yy < 0 || yy >= height) continue;
            axpy(dst, tmp.data() + yy * row, g[t], row);
        }
    });
    return out;
}

// Windowed statistics per pixel and channel, in this order within each channel's block of five.
enum Stat { kMu1, kMu2, kE11, kE22, kE12, kStats };
// Gradients of the three statistics that depend on the rendered image x.
enum StatGrad { kGMu1, kGE11, kGE12, kStatGrads };

// SSIM of one pixel and channel from its windowed moments, and dSSIM/d(mu1, E[x^2], E[xy]).
template <typename T>
struct SsimPixel {
    T value;
    T d_mu1, d_e11, d_e12;
};

template <typename T>
SsimPixel<T> ssim_pixel(const T* s) {
    const T mu1 = s[kMu1], mu2 = s[kMu2];
    const T var1 = s[kE11] - mu1 * mu1, var2 = s[kE22] - mu2 * mu2, cov = s[kE12] - mu1 * mu2;
    const T a1 = 2 * mu1 * mu2 + T(kC1), a2 = 2 * cov + T(kC2);
    const T b1 = mu1 * mu1 + mu2 * mu2 + T(kC1), b2 = var1 + var2 + T(kC2);
    const T v = (a1 * a2) / (b1 * b2);
    // d log S = da1/a1 + da2/a2 - db1/b1 - db2/b2, with da1/dmu1 = 2 mu2, da2/dmu1 = -2 mu2,
    // db1/dmu1 = 2 mu1, db2/dmu1 = -2 mu1; E11 enters only b2, E12 only a2.
    const T d_mu1 = v * (2 * mu2 / a1 - 2 * mu2 / a2 - 2 * mu1 / b1 + 2 * mu1 / b2);
    return {v, d_mu1, -v / b2, 2 * v / a2};
}

}  // namespace

template <typename T>
T masked_l1_loss(const ImageShape& shape, std::span<const T> rendered, std::span<const T> target,
                 std::span<const T> mask, T weight, std::span<T> grad_rendered) {
    check_inputs(shape, rendered, target, mask, grad_rendered);
    const MaskedMean<T> mean(shape, mask);
    const int w = shape.width, ch = shape.channels;
    std::vector<T> row_sums(shape.height, T(0));
    for_each_row(shape.height, [&](int y) {
        T s = 0;
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * w + x;
            const T m = mean.mask_at(p);
            for (int c = 0; c < ch; ++c) {
                const std::size_t i = p * ch + c;
                const T d = m * rendered[i] - m * target[i];  // as official: |x m - y m|
                s += std::abs(d);
                if (!grad_rendered.empty() && d != 0)
                    grad_rendered[i] += weight * mean.inv_denominator * (d > 0 ? m : -m);
            }
        }
        row_sums[y] = s;
    });
    return sum_in_order(row_sums) * mean.inv_denominator;
}

template <typename T>
T masked_dssim_loss(const ImageShape& shape, std::span<const T> rendered, std::span<const T> target,
                    std::span<const T> mask, T weight, std::span<T> grad_rendered) {
    check_inputs(shape, rendered, target, mask, grad_rendered);
    const MaskedMean<T> mean(shape, mask);
    const int w = shape.width, h = shape.height, ch = shape.channels;
    const std::size_t n = shape.values();

    // Windowed first and second moments of both images, five per channel.
    std::vector<T> moments(n * kStats);
    for_each_row(h, [&](int y) {
        for (std::size_t i = std::size_t(y) * w * ch; i < std::size_t(y + 1) * w * ch; ++i) {
            const T a = rendered[i], b = target[i];
            T* s = moments.data() + i * kStats;
            s[kMu1] = a, s[kMu2] = b, s[kE11] = a * a, s[kE22] = b * b, s[kE12] = a * b;
        }
    });
    moments = blur(moments, w, h, ch * kStats);

    // SSIM map under the mask; dL/d(statistics) = -weight_p dSSIM/d(statistics).
    const bool backward = !grad_rendered.empty();
    std::vector<T> stat_grads(backward ? n * kStatGrads : 0);
    std::vector<T> row_sums(h, T(0));
    for_each_row(h, [&](int y) {
        T s = 0;
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * w + x;
            const T wp = mean.weight_at(p);
            for (int c = 0; c < ch; ++c) {
                const std::size_t i = p * ch + c;
                const SsimPixel<T> px = ssim_pixel(moments.data() + i * kStats);
                s += mean.mask_at(p) * px.value;
                if (!backward) continue;
                T* g = stat_grads.data() + i * kStatGrads;
                g[kGMu1] = -wp * px.d_mu1, g[kGE11] = -wp * px.d_e11, g[kGE12] = -wp * px.d_e12;
            }
        }
        row_sums[y] = s;
    });
    const T loss = T(1) - sum_in_order(row_sums) * mean.inv_denominator;
    if (!backward) return loss;

    // Transposed convolution, then the chain rule through x, x^2 and x y.
    stat_grads = blur(stat_grads, w, h, ch * kStatGrads);
    for_each_row(h, [&](int y) {
        for (std::size_t i = std::size_t(y) * w * ch; i < std::size_t(y + 1) * w * ch; ++i) {
            const T* g = stat_grads.data() + i * kStatGrads;
            grad_rendered[i] += weight * (g[kGMu1] + 2 * rendered[i] * g[kGE11] + target[i] * g[kGE12]);
        }
    });
    return loss;
}

#define LG_INSTANTIATE(T)                                                                      \
    template T masked_l1_loss<T>(const ImageShape&, std::span<const T>, std::span<const T>,    \
                                 std::span<const T>, T, std::span<T>);                         \
    template T masked_dssim_loss<T>(const ImageShape&, std::span<const T>, std::span<const T>, \
                                    std::span<const T>, T, std::span<T>);
LG_INSTANTIATE(float)
LG_INSTANTIATE(double)
#undef LG_INSTANTIATE

}  // namespace lumigauss
