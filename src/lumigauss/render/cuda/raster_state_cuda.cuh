#pragma once
// What the CUDA backend keeps on the device between a forward and its backward, and the launchers of its
// kernels (internal to render/cuda).
#include <cstdint>
#include <type_traits>

#include "lumigauss/render/cuda/device_buffer.cuh"
#include "lumigauss/render/cuda/rasterizer_cuda.h"
#include "lumigauss/render/gradient_slot.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/splat_footprint.h"

namespace lumigauss::cuda {

struct RasterStateCuda {
    int width = 0, height = 0, tiles_x = 0, tiles_y = 0, channels = 3;
    std::size_t surfels = 0, entries = 0;
    raster::PinholeView<double> view{};   // the projection runs in double, as on the CPU
    raster::PinholeView<float> view_f{};  // its backward in float, as on the CPU
    float background[kMaxChannels] = {};

    // The surfels, as uploaded.
    DeviceBuffer<float> means, quats, scales, opacities, colors;
    // Per surfel: the projection (RasterState's fields of the same names) and its tile count.
    DeviceBuffer<raster::ProjectionVjpInputs<float>> projections;
    DeviceBuffer<raster::SplatGeometry<float>> splats;
    DeviceBuffer<SplatFootprint<float>> footprints;
    DeviceBuffer<std::uint32_t> tiles_touched;
    DeviceBuffer<std::uint32_t> emission_offset;  // size surfels + 1
    // Per emission (surfel by surfel, tile by tile): sort key (tile << 32 | depth bits) and surfel; then
    // the keys and emissions sorted (tile, then front to back, ties in surfel order).
    DeviceBuffer<std::uint64_t> keys, sorted_keys;
    DeviceBuffer<std::uint32_t> emissions, sorted_emissions, emission_surfel;
    DeviceBuffer<unsigned char> sort_scratch;
    DeviceBuffer<std::uint32_t> tile_start;  // per tile: first sorted entry; size tiles + 1
    // The tiles, longest list first: the order in which the tile kernels' blocks take them, so that the
    // longest lists start first instead of leaving a tail behind the others.
    DeviceBuffer<std::uint32_t> tile_lengths, sorted_lengths, tile_ids, tile_order;

    // Maps and what the backward needs per pixel.
    DeviceBuffer<float> color, alpha, depth, median_depth, normal, distortion;
    DeviceBuffer<float> final_transmittance, m1, m2;
    DeviceBuffer<std::uint32_t> contributors;
    DeviceBuffer<std::int32_t> median_entry;

    // Backward: incoming map gradients, the (surfel, tile) slots (gradient_slot.h, unpadded), the surfels'
    // gradients.
    DeviceBuffer<float> g_color, g_alpha, g_depth, g_median_depth, g_normal, g_distortion;
    DeviceBuffer<float> slots;
    DeviceBuffer<float> d_means, d_quats, d_scales, d_opacities, d_colors, d_mean2d;
};

// The kernels are compiled for 3, 6 and kMaxChannels colour channels (register arrays need a compile-time
// size): calls f(std::integral_constant<int, C>{}) with the smallest of those that holds `channels`.
template <typename F>
void with_channel_capacity(int channels, F&& f) {
    if (channels <= 3)
        f(std::integral_constant<int, 3>{});
    else if (channels <= 6)
        f(std::integral_constant<int, 6>{});
    else
        f(std::integral_constant<int, kMaxChannels>{});
}

// project_and_bin.cu
void project_surfels(RasterStateCuda& st, cudaStream_t stream);
void bin_surfels(RasterStateCuda& st, cudaStream_t stream);  // syncs once: the entry count
void reduce_surfel_gradients(RasterStateCuda& st, cudaStream_t stream);
// tile_kernels.cu
void blend_tiles(RasterStateCuda& st, cudaStream_t stream);
void backward_tiles(RasterStateCuda& st, cudaStream_t stream);

}  // namespace lumigauss::cuda
