#pragma once
// A per-pixel background behind the surfels (the sky of the photo, shading/sky_image.h), composited after
// the rasterizer as the rasterizer composites its constant background:
//     colour_c = sum_i w_i c_i + T_final * background_c,   T_final = 1 - alpha,
// and its backward, which needs no change to any rasterizer backend: the background's gradient is
// T_final * dL/dcolour, and the alpha map receives -sum_c background_c dL/dcolour_c, which the backends
// already turn into every surfel's gradient (they differentiate alpha = 1 - T_final).
#include <span>

#include "lumigauss/render/raster_types.h"

namespace lumigauss {

// Adds (1 - alpha) * background (3 values per pixel) to colour channels [first, first + 3).
template <typename T>
void composite_background(RasterImages<T>& images, std::span<const T> background, int first);

// Backward of composite_background for the same images (alpha as the rasterizer wrote it): adds into
// grads.alpha (resized to the pixel count when empty) and into g_background (3 per pixel) what reaches them
// from grads.color's channels [first, first + 3).
template <typename T>
void composite_background_backward(const RasterImages<T>& images, std::span<const T> background, int first,
                                   RasterImageGrads<T>& grads, std::span<T> g_background);

}  // namespace lumigauss
