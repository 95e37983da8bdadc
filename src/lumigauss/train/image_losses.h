#pragma once
// Photometric losses of LumiGauss (`utils/loss_utils.py:l1_loss`, `ssim` with a mask), with hand-written
// backward passes so that dL/d(rendered image) chains into the rasterizer backward.
//
// Images are row-major with `channels` interleaved values per pixel (as RasterImages::color); a mask has
// one value per pixel (soft values allowed) and an empty mask means "no mask" (the official unmasked path).
// Gradients are *accumulated*: each loss adds weight * dL/d(rendered) into `grad_rendered`, so several
// weighted losses can share one buffer. An empty `grad_rendered` skips the backward.
#include <cstddef>
#include <span>

namespace lumigauss {

struct ImageShape {
    int width = 0, height = 0, channels = 1;
    std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
    std::size_t values() const { return pixels() * std::size_t(channels); }
};

// Masked L1 as official: sum_{p,c} |m_p x - m_p y| / (C * sum_p m_p + 1e-6); without a mask, the plain mean
// of |x - y| over pixels and channels. The subgradient at x == y is 0, as torch's sign.
template <typename T>
T masked_l1_loss(const ImageShape& shape, std::span<const T> rendered, std::span<const T> target,
                 std::span<const T> mask, T weight, std::span<T> grad_rendered);

// Masked D-SSIM: 1 - SSIM_m. The SSIM map is computed per channel on the whole (unmasked) images with an
// 11x11 Gaussian window (sigma 1.5), zero padding 5 (torch conv2d), C1 = 0.01^2, C2 = 0.03^2; then
// SSIM_m = sum_{p,c} m_p ssim_{p,c} / (C * sum_p m_p + 1e-6), or the plain mean without a mask.
// Only the rendered image (the first argument of the official ssim) receives a gradient.
template <typename T>
T masked_dssim_loss(const ImageShape& shape, std::span<const T> rendered, std::span<const T> target,
                    std::span<const T> mask, T weight, std::span<T> grad_rendered);

}  // namespace lumigauss
