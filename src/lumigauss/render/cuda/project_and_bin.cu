// The CUDA backend's per-surfel passes: projection, binning into tiles, and the projection's backward.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <bit>

#include "lumigauss/render/cuda/raster_state_cuda.cuh"

namespace lumigauss::cuda {
namespace {

constexpr int kThreads = 256;

unsigned blocks_for(std::size_t n) {
    return unsigned((n + kThreads - 1) / kThreads);
}

// One thread per surfel: the CPU backend's projection (project_surfel in double; what it stores, rounded
// to float by the same store_projected), and the number of tiles its pixel box touches (0: not visible).
__global__ void project_kernel(std::size_t n, const float* __restrict__ means,
                               const float* __restrict__ quats, const float* __restrict__ scales,
                               const float* __restrict__ opacities, raster::PinholeView<double> view,
                               raster::ProjectionVjpInputs<float>* projections,
                               raster::SplatGeometry<float>* splats, SplatFootprint<float>* footprints,
                               std::uint32_t* tiles_touched) {
    const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const raster::SurfelGeometry<double> g{
        {means[3 * i], means[3 * i + 1], means[3 * i + 2]},
        {quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]},
        scales[2 * i],
        scales[2 * i + 1]};
    const double opacity = opacities[i];
    raster::ProjectedSurfel<double> p;
    if (!raster::project_surfel(g, opacity, view, p)) {
        tiles_touched[i] = 0;
        return;
    }
    store_projected(p, opacity, projections[i], splats[i], footprints[i]);
    tiles_touched[i] = tile_span(p.rect).count();
}

// One thread per visible surfel: its emissions, numbered from its offset tile by tile (row-major, as the
// CPU backend numbers them), each keyed by tile and depth. The depth is positive, so its float bits order
// like it.
__global__ void emit_kernel(std::size_t n, int tiles_x, const SplatFootprint<float>* __restrict__ footprints,
                            const std::uint32_t* __restrict__ tiles_touched,
                            const std::uint32_t* __restrict__ offsets, std::uint64_t* keys,
                            std::uint32_t* emissions, std::uint32_t* emission_surfel) {
    const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n || tiles_touched[i] == 0) return;
    const SplatFootprint<float> f = footprints[i];
    const TileSpan span = tile_span(f.rect);
    const std::uint64_t depth_bits = __float_as_uint(f.depth);
    std::uint32_t e = offsets[i];
    for (int ty = span.ty0; ty <= span.ty1; ++ty)
        for (int tx = span.tx0; tx <= span.tx1; ++tx, ++e) {
            keys[e] = (std::uint64_t(ty * tiles_x + tx) << 32) | depth_bits;
            emissions[e] = e;
            emission_surfel[e] = std::uint32_t(i);
        }
}

// One thread per sorted entry: where each tile's run of entries starts (tiles with none start where the
// next one does).
__global__ void tile_ranges_kernel(std::size_t m, int num_tiles, const std::uint64_t* __restrict__ keys,
                                   std::uint32_t* tile_start) {
    const std::size_t k = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (k >= m) return;
    const int tile = int(keys[k] >> 32);
    const int previous = k == 0 ? -1 : int(keys[k - 1] >> 32);
    for (int t = previous + 1; t <= tile; ++t) tile_start[t] = std::uint32_t(k);
    if (k == m - 1)
        for (int t = tile + 1; t <= num_tiles; ++t) tile_start[t] = std::uint32_t(m);
}

// One thread per tile: its list's length and its id (the keys and values of the longest-first sort).
__global__ void tile_lengths_kernel(int num_tiles, const std::uint32_t* __restrict__ tile_start,
                                    std::uint32_t* lengths, std::uint32_t* ids) {
    const int t = int(blockIdx.x * blockDim.x + threadIdx.x);
    if (t >= num_tiles) return;
    lengths[t] = tile_start[t + 1] - tile_start[t];
    ids[t] = std::uint32_t(t);
}

// One thread per surfel: the sum of its (surfel, tile) slots in emission order, then their conversion to
// the surfel's gradients (gradient_slot.h, in float as on the CPU).
template <int kValues>
__global__ void reduce_kernel(std::size_t n, int channels, raster::PinholeView<float> view,
                              const float* __restrict__ quats, const float* __restrict__ scales,
                              const raster::ProjectionVjpInputs<float>* __restrict__ projections,
                              const std::uint32_t* __restrict__ tiles_touched,
                              const std::uint32_t* __restrict__ offsets, const float* __restrict__ slots,
                              float* d_means, float* d_quats, float* d_scales, float* d_opacities,
                              float* d_colors, float* d_mean2d) {
    const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    using S = raster::GradSlot;
    const int values = S::values(channels);
    float sum[kValues];
#pragma unroll
    for (int v = 0; v < kValues; ++v) sum[v] = 0.0f;
    const bool visible = tiles_touched[i] != 0;
    if (visible) {
        for (std::uint32_t e = offsets[i]; e < offsets[i + 1]; ++e) {
            const float* slot = &slots[std::size_t(e) * values];
#pragma unroll
            for (int v = 0; v < kValues; ++v)
                if (v < values) sum[v] += slot[v];
        }
    }
    if (!visible) {
        for (int k = 0; k < 3; ++k) d_means[3 * i + k] = 0.0f;
        for (int k = 0; k < 4; ++k) d_quats[4 * i + k] = 0.0f;
        d_scales[2 * i] = d_scales[2 * i + 1] = 0.0f;
        d_opacities[i] = 0.0f;
        for (int c = 0; c < channels; ++c) d_colors[i * channels + c] = 0.0f;
        d_mean2d[2 * i] = d_mean2d[2 * i + 1] = 0.0f;
        return;
    }
    const raster::SurfelSlotGrad<float> g = raster::surfel_grad_from_slots(
        [&](int k) { return sum[k]; }, projections[i],
        Vec4<float>{quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]}, scales[2 * i],
        scales[2 * i + 1], view);
    const raster::SurfelGeometryGrad<float>& gg = g.geometry;
    for (int k = 0; k < 3; ++k) d_means[3 * i + k] = gg.mean[k];
    for (int k = 0; k < 4; ++k) d_quats[4 * i + k] = gg.quat[k];
    d_scales[2 * i] = gg.scale_u;
    d_scales[2 * i + 1] = gg.scale_v;
    d_opacities[i] = g.opacity;
    d_mean2d[2 * i] = g.mean2d.x;
    d_mean2d[2 * i + 1] = g.mean2d.y;
#pragma unroll
    for (int c = 0; c < kValues - S::kColor; ++c)  // compile-time indices keep `sum` in registers
        if (c < channels) d_colors[i * channels + c] = sum[S::kColor + c];
}

int significant_bits(std::uint32_t x) {
    return 32 - std::countl_zero(x);
}

// st.tile_order: the tiles by decreasing list length (ties by tile id: a stable sort).
void order_tiles(RasterStateCuda& st, cudaStream_t stream) {
    const int num_tiles = st.tiles_x * st.tiles_y;
    st.tile_lengths.resize(num_tiles), st.sorted_lengths.resize(num_tiles);
    st.tile_ids.resize(num_tiles), st.tile_order.resize(num_tiles);
    tile_lengths_kernel<<<blocks_for(std::size_t(num_tiles)), kThreads, 0, stream>>>(
        num_tiles, st.tile_start.data(), st.tile_lengths.data(), st.tile_ids.data());
    check_launch("tile_lengths_kernel");
    std::size_t bytes = 0;
    check(cub::DeviceRadixSort::SortPairsDescending(nullptr, bytes, st.tile_lengths.data(),
                                                    st.sorted_lengths.data(), st.tile_ids.data(),
                                                    st.tile_order.data(), num_tiles, 0, 32, stream),
          "tile order size");
    st.sort_scratch.resize(bytes);
    check(cub::DeviceRadixSort::SortPairsDescending(st.sort_scratch.data(), bytes, st.tile_lengths.data(),
                                                    st.sorted_lengths.data(), st.tile_ids.data(),
                                                    st.tile_order.data(), num_tiles, 0, 32, stream),
          "tile order");
}

}  // namespace

void project_surfels(RasterStateCuda& st, cudaStream_t stream) {
    const std::size_t n = st.surfels;
    st.projections.resize(n);
    st.splats.resize(n);
    st.footprints.resize(n);
    st.tiles_touched.resize(n);
    if (n == 0) return;
    project_kernel<<<blocks_for(n), kThreads, 0, stream>>>(
        n, st.means.data(), st.quats.data(), st.scales.data(), st.opacities.data(), st.view,
        st.projections.data(), st.splats.data(), st.footprints.data(), st.tiles_touched.data());
    check_launch("project_kernel");
}

void bin_surfels(RasterStateCuda& st, cudaStream_t stream) {
    const std::size_t n = st.surfels;
    const int num_tiles = st.tiles_x * st.tiles_y;
    st.emission_offset.resize(n + 1);
    st.tile_start.resize(std::size_t(num_tiles) + 1);
    st.emission_offset.clear(stream);
    std::size_t scan_bytes = 0;
    if (n > 0) {
        check(cub::DeviceScan::InclusiveSum(nullptr, scan_bytes, st.tiles_touched.data(),
                                            st.emission_offset.data() + 1, n, stream),
              "scan size");
        st.sort_scratch.resize(scan_bytes);
        check(cub::DeviceScan::InclusiveSum(st.sort_scratch.data(), scan_bytes, st.tiles_touched.data(),
                                            st.emission_offset.data() + 1, n, stream),
              "scan");
    }
    std::uint32_t m = 0;
    check(cudaMemcpyAsync(&m, st.emission_offset.data() + n, sizeof m, cudaMemcpyDeviceToHost, stream),
          "entry count");
    check(cudaStreamSynchronize(stream), "binning");
    st.entries = m;
    st.keys.resize(m), st.sorted_keys.resize(m);
    st.emissions.resize(m), st.sorted_emissions.resize(m), st.emission_surfel.resize(m);
    if (m == 0) {
        st.tile_start.clear(stream);
        order_tiles(st, stream);
        return;
    }
    emit_kernel<<<blocks_for(n), kThreads, 0, stream>>>(
        n, st.tiles_x, st.footprints.data(), st.tiles_touched.data(), st.emission_offset.data(),
        st.keys.data(), st.emissions.data(), st.emission_surfel.data());
    check_launch("emit_kernel");
    const int end_bit = 32 + significant_bits(std::uint32_t(num_tiles));
    std::size_t sort_bytes = 0;
    check(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, st.keys.data(), st.sorted_keys.data(),
                                          st.emissions.data(), st.sorted_emissions.data(), m, 0, end_bit,
                                          stream),
          "sort size");
    st.sort_scratch.resize(sort_bytes);
    check(cub::DeviceRadixSort::SortPairs(st.sort_scratch.data(), sort_bytes, st.keys.data(),
                                          st.sorted_keys.data(), st.emissions.data(),
                                          st.sorted_emissions.data(), m, 0, end_bit, stream),
          "sort");
    tile_ranges_kernel<<<blocks_for(m), kThreads, 0, stream>>>(m, num_tiles, st.sorted_keys.data(),
                                                               st.tile_start.data());
    check_launch("tile_ranges_kernel");
    order_tiles(st, stream);
}

void reduce_surfel_gradients(RasterStateCuda& st, cudaStream_t stream) {
    const std::size_t n = st.surfels;
    const int c = st.channels;
    st.d_means.resize(3 * n), st.d_quats.resize(4 * n), st.d_scales.resize(2 * n);
    st.d_opacities.resize(n), st.d_colors.resize(n * c), st.d_mean2d.resize(2 * n);
    if (n == 0) return;
    with_channel_capacity(c, [&](auto capacity) {
        reduce_kernel<raster::GradSlot::values(decltype(capacity)::value)>
            <<<blocks_for(n), kThreads, 0, stream>>>(
                n, c, st.view_f, st.quats.data(), st.scales.data(), st.projections.data(),
                st.tiles_touched.data(), st.emission_offset.data(), st.slots.data(), st.d_means.data(),
                st.d_quats.data(), st.d_scales.data(), st.d_opacities.data(), st.d_colors.data(),
                st.d_mean2d.data());
    });
    check_launch("reduce_kernel");
}

}  // namespace lumigauss::cuda
