#pragma once
// The rasterizer's maps as images, for writing and scoring: colour channels, world normals, expected depth,
// alpha. Shared by `render`, `eval`, the training previews and the relighting tool.
#include "lumigauss/io/image.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

// Channels [first, first + count) of an interleaved raster colour buffer, as an Image.
Image raster_channels(const RasterImages<float>& raster, int first, int count);

// World normals encoded (n / |n| + 1) / 2; 0 where |n| <= 1e-3 (nothing rendered).
Image encode_normals(const RasterImages<float>& raster);
// World normals n / |n| in [-1, 1]; 0 where |n| <= 1e-3.
Image unit_normals(const RasterImages<float>& raster);

// Expected depth depth / alpha where alpha > 1e-6, else 0 (1 channel).
Image expected_depth(const RasterImages<float>& raster);
Image alpha_image(const RasterImages<float>& raster);

}  // namespace lumigauss
