#pragma once
// The blending weights of a finished forward pass, for fitting colours with the geometry frozen.
//
// A pixel's colour is sum_i w_i c_i over the surfels it composited (w_i = alpha_i T_i), plus the
// background times the final transmittance; with the geometry fixed the w_i do not change, so a loop that
// only changes colours (fit-light: 27 SH coefficients per step) can composite and back-propagate with one
// sparse product each way instead of a rasterisation and its full backward. Memory: 8 bytes per composited
// (pixel, surfel) pair, e.g. 60 MB for a 320x240 view of a trained plaza model (~100 pairs per pixel).
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

struct BlendWeights {
    int width = 0, height = 0;
    std::size_t surfels = 0;
    // Pixel-major: pixel p composited surfel pixel_surfel[k] with weight pixel_weight[k] for
    // k in [pixel_start[p], pixel_start[p + 1]), front to back.
    std::vector<std::uint32_t> pixel_start, pixel_surfel;
    std::vector<float> pixel_weight;

    std::size_t pairs() const { return pixel_surfel.size(); }
};

// Rasterizes `surfels` from `camera` into `images` and returns that forward's weights, by its own rules:
// the shared per-pixel kernel, the alpha clamp, the 1/255 skip and the transmittance stop, in each tile's
// front-to-back order. (Runs on the CPU backend, whose tile lists the weights are read from.)
BlendWeights render_blend_weights(const Camera& camera, const SurfelBatch<float>& surfels,
                                  const RasterSettings<float>& settings, RasterImages<float>& images);

// colors (channels per surfel) -> channels per pixel: sum_i w_i c_i (no background).
void composite(const BlendWeights& weights, std::span<const float> colors, int channels,
               std::span<float> out);

// The transpose: dL/d(pixel colours) -> dL/d(surfel colours) (overwrites g_colors). Fixed pixel chunks
// accumulate into their own buffers, summed in chunk order: the result does not depend on the threads.
void composite_backward(const BlendWeights& weights, std::span<const float> g_pixels, int channels,
                        std::span<float> g_colors);

}  // namespace lumigauss
