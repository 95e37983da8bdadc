#include "lumigauss/render/raster_maps.h"

#include <cstddef>

namespace lumigauss {

Image raster_channels(const RasterImages<float>& raster, int first, int count) {
    Image out(raster.width, raster.height, count);
    const std::size_t pixels = std::size_t(raster.width) * std::size_t(raster.height);
    const std::size_t src = std::size_t(raster.channels);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < count; ++c)
            out.pixels[p * std::size_t(count) + std::size_t(c)] =
                raster.color[p * src + std::size_t(first + c)];
    return out;
}

namespace {

Image normals(const RasterImages<float>& raster, bool encode) {
    Image out(raster.width, raster.height, 3);
    const std::size_t pixels = out.pixels.size() / 3;
    for (std::size_t p = 0; p < pixels; ++p) {
        const Vec3f n{raster.normal[3 * p], raster.normal[3 * p + 1], raster.normal[3 * p + 2]};
        const float len = length(n);
        if (!(len > 1e-3f)) continue;
        for (int c = 0; c < 3; ++c) {
            const float v = n[c] / len;
            out.pixels[3 * p + std::size_t(c)] = encode ? 0.5f * (v + 1.0f) : v;
        }
    }
    return out;
}

}  // namespace

Image encode_normals(const RasterImages<float>& raster) {
    return normals(raster, true);
}

Image unit_normals(const RasterImages<float>& raster) {
    return normals(raster, false);
}

Image expected_depth(const RasterImages<float>& raster) {
    Image out(raster.width, raster.height, 1);
    for (std::size_t p = 0; p < out.pixels.size(); ++p) {
        const float a = raster.alpha[p];
        out.pixels[p] = a > 1e-6f ? raster.depth[p] / a : 0.0f;
    }
    return out;
}

Image alpha_image(const RasterImages<float>& raster) {
    Image out(raster.width, raster.height, 1);
    out.pixels = raster.alpha;
    return out;
}

}  // namespace lumigauss
