#include "lumigauss/render/cpu/blend_weights_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/raster_constants.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss {
namespace {

struct PixelPairs {
    std::vector<std::uint32_t> count;  // per pixel of the row
    std::vector<std::uint32_t> surfel;
    std::vector<float> weight;
};

// One image row: every pixel walks its tile's entries up to its last contributor, as the forward did.
void row_pairs(const RasterState<float>& st, int y, PixelPairs& out) {
    const int width = st.view.width;
    out.count.assign(std::size_t(width), 0);
    for (int x = 0; x < width; ++x) {
        const std::size_t pix = std::size_t(y) * width + x;
        const int tile = (y / raster::kTileSize) * st.tiles_x + x / raster::kTileSize;
        const std::uint32_t begin = st.tile_start[std::size_t(tile)];
        const std::uint32_t end = begin + st.contributors[pix];
        const float px = float(x) + 0.5f, py = float(y) + 0.5f;
        float t = 1.0f;
        for (std::uint32_t e = begin; e < end; ++e) {
            const raster::PixelRect& r = st.entry_footprint[e].rect;
            if (x < r.x0 || x > r.x1 || y < r.y0 || y > r.y1) continue;
            raster::SplatSample<float> s;
            if (!raster::evaluate_splat(st.entry_splat[e], px, py, s)) continue;
            const float t_next = t * (1.0f - s.alpha);
            if (t_next < float(raster::kTransmittanceMin)) break;
            out.surfel.push_back(st.entry_surfel[e]);
            out.weight.push_back(s.alpha * t);
            ++out.count[std::size_t(x)];
            t = t_next;
        }
    }
}

}  // namespace

BlendWeights render_blend_weights(const Camera& camera, const SurfelBatch<float>& surfels,
                                  const RasterSettings<float>& settings, RasterImages<float>& images) {
    RasterState<float> state;
    rasterize_forward_cpu(camera, surfels, settings, state, images);
    return blend_weights(state);
}

BlendWeights blend_weights(const RasterState<float>& st) {
    BlendWeights bw;
    bw.width = st.view.width, bw.height = st.view.height;
    bw.surfels = st.visible.size();
    std::vector<PixelPairs> rows(std::size_t(bw.height));
    tbb::parallel_for(0, bw.height, [&](int y) { row_pairs(st, y, rows[std::size_t(y)]); });

    const std::size_t np = std::size_t(bw.width) * bw.height;
    bw.pixel_start.assign(np + 1, 0);
    for (int y = 0; y < bw.height; ++y)
        for (int x = 0; x < bw.width; ++x) {
            const std::size_t p = std::size_t(y) * bw.width + x;
            bw.pixel_start[p + 1] = bw.pixel_start[p] + rows[std::size_t(y)].count[std::size_t(x)];
        }
    for (const PixelPairs& r : rows) {
        bw.pixel_surfel.insert(bw.pixel_surfel.end(), r.surfel.begin(), r.surfel.end());
        bw.pixel_weight.insert(bw.pixel_weight.end(), r.weight.begin(), r.weight.end());
    }

    return bw;
}

void composite(const BlendWeights& bw, std::span<const float> colors, int channels, std::span<float> out) {
    const std::size_t np = std::size_t(bw.width) * bw.height;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np, 1024), [&](const auto& r) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
            float* o = &out[p * std::size_t(channels)];
            std::fill_n(o, channels, 0.0f);
            for (std::uint32_t k = bw.pixel_start[p]; k < bw.pixel_start[p + 1]; ++k) {
                const float* c = &colors[std::size_t(bw.pixel_surfel[k]) * std::size_t(channels)];
                for (int ch = 0; ch < channels; ++ch) o[ch] += bw.pixel_weight[k] * c[ch];
            }
        }
    });
}

void composite_backward(const BlendWeights& bw, std::span<const float> g_pixels, int channels,
                        std::span<float> g_colors) {
    constexpr std::size_t kChunks = 8;
    const std::size_t np = std::size_t(bw.width) * bw.height, stride = bw.surfels * std::size_t(channels);
    std::vector<float> partial(kChunks * stride, 0.0f);
    tbb::parallel_for(std::size_t(0), kChunks, [&](std::size_t chunk) {
        float* g = &partial[chunk * stride];
        for (std::size_t p = np * chunk / kChunks; p < np * (chunk + 1) / kChunks; ++p) {
            const float* gp = &g_pixels[p * std::size_t(channels)];
            for (std::uint32_t k = bw.pixel_start[p]; k < bw.pixel_start[p + 1]; ++k) {
                float* gs = &g[std::size_t(bw.pixel_surfel[k]) * std::size_t(channels)];
                for (int ch = 0; ch < channels; ++ch) gs[ch] += bw.pixel_weight[k] * gp[ch];
            }
        }
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, stride, 4096), [&](const auto& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            float sum = 0.0f;
            for (std::size_t chunk = 0; chunk < kChunks; ++chunk) sum += partial[chunk * stride + k];
            g_colors[k] = sum;
        }
    });
}

}  // namespace lumigauss
