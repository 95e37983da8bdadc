#pragma once
// The 2DGS geometric regularisers as LumiGauss applies them (`gaussian_renderer/__init__.py:render`,
// `utils/point_utils.py:depth_to_normal`, `train.py`): expected depth, the normal derived from depth, the
// masked normal-consistency loss and the masked distortion loss, each with its backward.
//
// Maps are row-major, `width * height` pixels, one value per pixel (three for normals), as RasterImages.
// Backward functions *accumulate* into their gradient outputs; an empty mask means "no mask".
#include <span>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

// Expected depth D / alpha, with torch.nan_to_num(x, 0, 0): pixels where the quotient is not finite
// (alpha == 0) get 0 and pass no gradient.
template <typename T>
void expected_depth(std::span<const T> depth, std::span<const T> alpha, std::span<T> out);
template <typename T>
void expected_depth_backward(std::span<const T> depth, std::span<const T> alpha,
                             std::span<const T> grad_expected, std::span<T> grad_depth,
                             std::span<T> grad_alpha);

// World-space normal from a z-depth map: every pixel centre (x + 0.5, y + 0.5) is back-projected along its
// unnormalised camera ray (z = 1), rotated to world; N = normalize((P[y+1,x] - P[y-1,x]) x
// (P[y,x+1] - P[y,x-1])), which faces the camera. The one-pixel border is 0. `normal` holds 3 per pixel.
template <typename T>
void depth_to_normal(const Camera& camera, std::span<const T> depth, std::span<T> normal);
template <typename T>
void depth_to_normal_backward(const Camera& camera, std::span<const T> depth, std::span<const T> grad_normal,
                              std::span<T> grad_depth);

// Normal consistency as LumiGauss: mean over all pixels of 1 - sum_c (m N_rend)_c (m N_d alpha)_c, where
// N_rend = images.normal (world space, unnormalised), N_d = depth_to_normal(expected depth) and alpha is
// detached in that product (it still receives gradient through the expected depth). Masked-out pixels
// contribute the constant 1. Adds weight * dL/d(depth, alpha, normal) into `grads` (resized from empty).
template <typename T>
T normal_consistency_loss(const Camera& camera, const RasterImages<T>& images, std::span<const T> mask,
                          T weight, RasterImageGrads<T>* grads);

// Distortion loss mean_p(m_p dist_p) over all pixels; adds weight * dL/d(distortion) into `grads`.
template <typename T>
T distortion_loss(const RasterImages<T>& images, std::span<const T> mask, T weight,
                  RasterImageGrads<T>* grads);

}  // namespace lumigauss
