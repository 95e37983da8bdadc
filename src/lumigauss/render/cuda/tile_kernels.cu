// The CUDA backend's per-tile passes: one block of 16 x 16 threads per tile, one thread per pixel, the
// tile's surfels staged through shared memory in batches. The per-pixel work is the CPU backend's
// (surfel_kernel.h, pixel_blend.h) on scalar lanes.
#include "lumigauss/render/cuda/raster_state_cuda.cuh"
#include "lumigauss/render/pixel_blend.h"

namespace lumigauss::cuda {
namespace {

constexpr int kTileThreads = raster::kTileSize * raster::kTileSize;
constexpr int kWarps = kTileThreads / 32;
constexpr unsigned kFullWarp = 0xffffffffu;

// A batch of a tile's entries in shared memory. Raw storage: shared variables cannot have constructors,
// and the math types initialise their members.
template <int kBatch, int C>
struct StagedEntries {
    float4 splat[kBatch * 4];  // raster::SplatGeometry<float>, 64 bytes each
    int4 rect[kBatch];         // x0, y0, x1, y1
    float normal[kBatch * 3];
    float color[kBatch * C];

    __device__ const raster::SplatGeometry<float>& geometry(int j) const {
        return *reinterpret_cast<const raster::SplatGeometry<float>*>(&splat[4 * j]);
    }
    __device__ bool covers(int j, int x, int y) const {
        const int4 r = rect[j];
        return x >= r.x && x <= r.z && y >= r.y && y <= r.w;
    }
    __device__ Vec3<float> normal_of(int j) const {
        return {normal[3 * j], normal[3 * j + 1], normal[3 * j + 2]};
    }
    // Thread j stages sorted entry k: the surfel's kernel geometry, footprint and colours.
    __device__ void stage(int j, std::uint32_t surfel, int channels,
                          const raster::SplatGeometry<float>* __restrict__ splats,
                          const SplatFootprint<float>* __restrict__ footprints,
                          const float* __restrict__ colors) {
        const float4* from = reinterpret_cast<const float4*>(&splats[surfel]);
#pragma unroll
        for (int q = 0; q < 4; ++q) splat[4 * j + q] = from[q];
        const SplatFootprint<float> f = footprints[surfel];
        rect[j] = make_int4(f.rect.x0, f.rect.y0, f.rect.x1, f.rect.y1);
        for (int k = 0; k < 3; ++k) normal[3 * j + k] = f.normal[k];
        for (int c = 0; c < C; ++c)
            color[C * j + c] = c < channels ? colors[std::size_t(surfel) * channels + c] : 0.0f;
    }
};

struct TileArgs {
    int width, height, tiles_x, channels;
    const std::uint32_t* tile_order;  // block b renders tile tile_order[b]
    const std::uint32_t* tile_start;
    const std::uint32_t* sorted_emissions;
    const std::uint32_t* emission_surfel;
    const raster::SplatGeometry<float>* splats;
    const SplatFootprint<float>* footprints;
    const float* colors;
};

struct Pixel {
    int tile, x, y;
    bool inside;
};
__device__ Pixel tile_pixel(const TileArgs& a) {
    const int tile = int(a.tile_order[blockIdx.x]);
    const int x = (tile % a.tiles_x) * raster::kTileSize + int(threadIdx.x) % raster::kTileSize;
    const int y = (tile / a.tiles_x) * raster::kTileSize + int(threadIdx.x) / raster::kTileSize;
    return {tile, x, y, x < a.width && y < a.height};
}

struct ForwardOutputs {
    float background[kMaxChannels];
    float *color, *alpha, *depth, *median_depth, *normal, *distortion;
    float *final_transmittance, *m1, *m2;
    std::uint32_t* contributors;
    std::int32_t* median_entry;
};

constexpr int kForwardBatch = kTileThreads;

template <int C>
__global__ void __launch_bounds__(kTileThreads) forward_kernel(TileArgs a, ForwardOutputs out) {
    __shared__ StagedEntries<kForwardBatch, C> staged;
    const Pixel p = tile_pixel(a);
    const float px = float(p.x) + 0.5f, py = float(p.y) + 0.5f;
    raster::BlendPixel<float, C> s{};
    s.live = p.inside;
    s.trans = 1.0f;
    s.median_entry = -1;
    const std::uint32_t begin = a.tile_start[p.tile], end = a.tile_start[p.tile + 1];
    for (std::uint32_t batch = begin; batch < end; batch += kForwardBatch) {
        // Also the barrier before the batch is overwritten.
        if (__syncthreads_count(s.live) == 0) break;
        if (batch + threadIdx.x < end) {
            const std::uint32_t surfel = a.emission_surfel[a.sorted_emissions[batch + threadIdx.x]];
            staged.stage(int(threadIdx.x), surfel, a.channels, a.splats, a.footprints, a.colors);
        }
        __syncthreads();
        const int count = int(min(std::uint32_t(kForwardBatch), end - batch));
        for (int j = 0; j < count && s.live; ++j) {
            const raster::SplatGeometry<float>& g = staged.geometry(j);
            raster::SplatSample<float> smp;
            float rho;
            const bool reached = raster::splat_hit(g, px, py, smp, rho) && staged.covers(j, p.x, p.y);
            if (!raster::splat_alpha(g.opacity, raster::splat_exponent(rho, reached), smp)) continue;
            const std::uint32_t entry = batch + std::uint32_t(j);
            raster::blend_sample(s, smp.alpha, smp.z, &staged.color[C * j], a.channels, staged.normal_of(j),
                                 std::int32_t(entry), std::int32_t(entry - begin + 1));
        }
    }
    if (!p.inside) return;
    const std::size_t pix = std::size_t(p.y) * a.width + p.x;
    out.final_transmittance[pix] = s.trans;
    out.contributors[pix] = std::uint32_t(s.contributors);
    out.median_entry[pix] = s.median_entry;
    out.m1[pix] = s.m1;
    out.m2[pix] = s.m2;
    out.alpha[pix] = 1.0f - s.trans;
#pragma unroll
    for (int c = 0; c < C; ++c)  // to C, not channels: a register array takes compile-time indices only
        if (c < a.channels) out.color[pix * a.channels + c] = s.color[c] + s.trans * out.background[c];
    out.depth[pix] = s.depth;
    for (int k = 0; k < 3; ++k) out.normal[pix * 3 + k] = s.normal[k];
    out.distortion[pix] = s.distortion;
    out.median_depth[pix] = s.median;
}

struct BackwardInputs {
    float background[kMaxChannels];
    const float *final_transmittance, *m1, *m2;
    const std::uint32_t* contributors;
    const std::int32_t* median_entry;
    // dL/d(map); null: zero.
    const float *g_color, *g_alpha, *g_depth, *g_median_depth, *g_normal, *g_distortion;
    float* slots;
};

__device__ float value_at(const float* map, std::size_t i) {
    return map ? map[i] : 0.0f;
}

// The walk's starting state of a pixel (the CPU backend's load_block).
template <int C>
__device__ raster::BlendPixelBackward<float, C> load_pixel(const Pixel& p, const TileArgs& a,
                                                           const BackwardInputs& in) {
    raster::BlendPixelBackward<float, C> s{};
    s.trans = 1.0f;
    s.median_entry = -1;
    if (p.inside) {
        const std::size_t pix = std::size_t(p.y) * a.width + p.x;
        s.trans = in.final_transmittance[pix];
        float dot_bg = 0.0f;
#pragma unroll
        for (int c = 0; c < C; ++c) {  // to C: see forward_kernel's colour output
            s.g_color[c] = c < a.channels ? value_at(in.g_color, pix * a.channels + c) : 0.0f;
            dot_bg += in.background[c] * s.g_color[c];
        }
        s.bg_term = s.trans * dot_bg;
        for (int k = 0; k < 3; ++k) s.g_normal[k] = value_at(in.g_normal, pix * 3 + k);
        s.g_depth = value_at(in.g_depth, pix);
        s.g_alpha = value_at(in.g_alpha, pix);
        s.g_dist = value_at(in.g_distortion, pix);
        s.g_median = value_at(in.g_median_depth, pix);
        s.m1 = in.m1[pix];
        s.m2 = in.m2[pix];
        s.contributors = std::int32_t(in.contributors[pix]);
        s.median_entry = in.median_entry[pix];
    }
    s.a_total = 1.0f - s.trans;
    return s;
}

// Sums each of the warp's per-lane values over its 32 lanes into `sums` (shared memory), by halving: at
// each step a lane keeps half of its values and swaps the other half with its partner, so 32 values take
// 16 + 8 + 4 + 2 + 1 shuffles (a butterfly per value would take 5 each: 160) and lane l ends with value
// l's total. Values past a whole 32 are few (C = 16 has 34): each is summed by its own butterfly. The
// order of the additions is fixed, so the sums do not depend on scheduling.
template <int kHalf>  // a compile-time step, so that v stays in registers
__device__ __forceinline__ void halve(float (&v)[32], int lane) {
    const bool upper = lane & kHalf;
#pragma unroll
    for (int i = 0; i < kHalf; ++i) {
        const float send = upper ? v[i] : v[i + kHalf];
        const float keep = upper ? v[i + kHalf] : v[i];
        v[i] = keep + __shfl_xor_sync(kFullWarp, send, kHalf);
    }
}
template <int kValues>
__device__ __forceinline__ void warp_sum_into(float (&q)[kValues], float* sums, int lane) {
    constexpr int kWhole = kValues / 32 * 32, kRest = kValues - kWhole;
    constexpr bool kRestByHalving = kRest > 6;  // 31 shuffles beat 5 per value from 7 values on
#pragma unroll
    for (int base = 0; base < kWhole + (kRestByHalving ? 32 : 0); base += 32) {
        float v[32];
#pragma unroll
        for (int i = 0; i < 32; ++i) v[i] = base + i < kValues ? q[base + i] : 0.0f;
        halve<16>(v, lane), halve<8>(v, lane), halve<4>(v, lane), halve<2>(v, lane), halve<1>(v, lane);
        if (base + lane < kValues) sums[base + lane] = v[0];
    }
    if constexpr (!kRestByHalving) {
#pragma unroll
        for (int i = kWhole; i < kValues; ++i) {
            float x = q[i];
#pragma unroll
            for (int offset = 16; offset > 0; offset /= 2) x += __shfl_xor_sync(kFullWarp, x, offset);
            if (lane == 0) sums[i] = x;
        }
    }
}

// Entries per batch of the backward: each warp's per-entry sums wait in shared memory until the batch
// ends, when they are added up warp by warp in a fixed order.
constexpr int kBackwardBatch = 32;

template <int C>
__global__ void __launch_bounds__(kTileThreads) backward_kernel(TileArgs a, BackwardInputs in) {
    constexpr int kValues = raster::GradSlot::values(C);
    __shared__ StagedEntries<kBackwardBatch, C> staged;
    __shared__ std::uint32_t emission[kBackwardBatch];
    __shared__ float warp_sums[kWarps][kBackwardBatch][kValues];
    __shared__ std::uint32_t most_contributors;
    const Pixel p = tile_pixel(a);
    const float px = float(p.x) + 0.5f, py = float(p.y) + 0.5f;
    const int warp = int(threadIdx.x) / 32, lane = int(threadIdx.x) % 32;
    raster::BlendPixelBackward<float, C> s = load_pixel<C>(p, a, in);
    if (threadIdx.x == 0) most_contributors = 0;
    __syncthreads();
    atomicMax(&most_contributors, std::uint32_t(s.contributors));
    __syncthreads();
    const std::uint32_t begin = a.tile_start[p.tile];
    const int values = raster::GradSlot::values(a.channels);
    // Back to front over the entries up to the last any pixel composited.
    for (std::uint32_t batch_end = begin + most_contributors; batch_end > begin;) {
        const std::uint32_t batch_begin = batch_end - min(std::uint32_t(kBackwardBatch), batch_end - begin);
        const int count = int(batch_end - batch_begin);
        __syncthreads();  // the previous batch's sums are written out
        if (int(threadIdx.x) < count) {
            const std::uint32_t em = a.sorted_emissions[batch_begin + threadIdx.x];
            emission[threadIdx.x] = em;
            staged.stage(int(threadIdx.x), a.emission_surfel[em], a.channels, a.splats, a.footprints,
                         a.colors);
        }
        __syncthreads();
        for (int j = count - 1; j >= 0; --j) {
            const std::uint32_t entry = batch_begin + std::uint32_t(j);
            const raster::SplatGeometry<float>& g = staged.geometry(j);
            raster::SplatSample<float> smp;
            float rho;
            const bool reached = raster::splat_hit(g, px, py, smp, rho) && staged.covers(j, p.x, p.y) &&
                                 std::int32_t(entry - begin + 1) <= s.contributors;
            const bool composited = raster::splat_alpha(g.opacity, raster::splat_exponent(rho, reached), smp);
            float* sums = warp_sums[warp][j];
            if (!__any_sync(kFullWarp, composited)) {  // nothing changes for any pixel of the warp
                for (int v = lane; v < kValues; v += 32) sums[v] = 0.0f;
                continue;
            }
            const float alpha = composited ? smp.alpha : 0.0f;
            const raster::SampleValues<float> sampled = raster::sample_values(
                s, composited, smp.z, &staged.color[C * j], a.channels, staged.normal_of(j));
            const raster::BlendSampleGrad<float> r =
                raster::unblend_sample(s, alpha, sampled, std::int32_t(entry));
            const raster::SplatGradTerms<float> t =
                raster::splat_grad_terms(g, px, py, smp, smp.screen_branch || !composited, r.g_alpha, r.g_z);
            float q[kValues];
            raster::slot_values(t, r, s, q);
            warp_sum_into(q, sums, lane);
        }
        __syncthreads();
        for (int i = int(threadIdx.x); i < count * values; i += kTileThreads) {
            const int j = i / values, v = i % values;
            float sum = 0.0f;
#pragma unroll
            for (int w = 0; w < kWarps; ++w) sum += warp_sums[w][j][v];
            in.slots[std::size_t(emission[j]) * values + v] = sum;
        }
        batch_end = batch_begin;
    }
}

TileArgs tile_args(const RasterStateCuda& st) {
    return {st.width,
            st.height,
            st.tiles_x,
            st.channels,
            st.tile_order.data(),
            st.tile_start.data(),
            st.sorted_emissions.data(),
            st.emission_surfel.data(),
            st.splats.data(),
            st.footprints.data(),
            st.colors.data()};
}

template <typename Kernel, typename Extra>
void launch_tiles(const RasterStateCuda& st, Kernel kernel, const Extra& extra, cudaStream_t stream,
                  const char* name) {
    const unsigned tiles = unsigned(st.tiles_x * st.tiles_y);
    if (tiles == 0) return;
    kernel<<<tiles, kTileThreads, 0, stream>>>(tile_args(st), extra);
    check_launch(name);
}

const float* or_null(const DeviceBuffer<float>& b) {
    return b.size() ? b.data() : nullptr;
}

}  // namespace

void blend_tiles(RasterStateCuda& st, cudaStream_t stream) {
    const std::size_t np = std::size_t(st.width) * st.height;
    st.color.resize(np * st.channels), st.alpha.resize(np), st.depth.resize(np);
    st.median_depth.resize(np), st.normal.resize(3 * np), st.distortion.resize(np);
    st.final_transmittance.resize(np), st.m1.resize(np), st.m2.resize(np);
    st.contributors.resize(np), st.median_entry.resize(np);
    ForwardOutputs out{};
    for (int c = 0; c < kMaxChannels; ++c) out.background[c] = st.background[c];
    out.color = st.color.data(), out.alpha = st.alpha.data(), out.depth = st.depth.data();
    out.median_depth = st.median_depth.data(), out.normal = st.normal.data();
    out.distortion = st.distortion.data();
    out.final_transmittance = st.final_transmittance.data(), out.m1 = st.m1.data(), out.m2 = st.m2.data();
    out.contributors = st.contributors.data(), out.median_entry = st.median_entry.data();
    with_channel_capacity(st.channels, [&](auto c) {
        launch_tiles(st, forward_kernel<decltype(c)::value>, out, stream, "forward_kernel");
    });
}

void backward_tiles(RasterStateCuda& st, cudaStream_t stream) {
    // Slots of entries behind every pixel's last contributor are never written: zero.
    st.slots.resize(st.entries * std::size_t(raster::GradSlot::values(st.channels)));
    st.slots.clear(stream);
    BackwardInputs in{};
    for (int c = 0; c < kMaxChannels; ++c) in.background[c] = st.background[c];
    in.final_transmittance = st.final_transmittance.data(), in.m1 = st.m1.data(), in.m2 = st.m2.data();
    in.contributors = st.contributors.data(), in.median_entry = st.median_entry.data();
    in.g_color = or_null(st.g_color), in.g_alpha = or_null(st.g_alpha), in.g_depth = or_null(st.g_depth);
    in.g_median_depth = or_null(st.g_median_depth), in.g_normal = or_null(st.g_normal);
    in.g_distortion = or_null(st.g_distortion);
    in.slots = st.slots.data();
    with_channel_capacity(st.channels, [&](auto c) {
        launch_tiles(st, backward_kernel<decltype(c)::value>, in, stream, "backward_kernel");
    });
}

}  // namespace lumigauss::cuda
