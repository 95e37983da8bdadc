#include "lumigauss/render/cpu/rasterizer_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include "lumigauss/render/cpu/tile_backward.h"
#include "lumigauss/render/cpu/tile_binning.h"
#include "lumigauss/render/cpu/tile_kernels.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/huge_pages.h"
#include "lumigauss/util/multiversion.h"

namespace lumigauss {
namespace {

using raster::ProjectedSurfel;

// Stores one projected surfel (store_projected). Returns false (and stores nothing) when it reaches no pixel.
template <typename T>
LG_ALWAYS_INLINE bool store_projection(const ProjectedSurfel<double>& p, double opacity, RasterState<T>& st,
                                       std::size_t i) {
    if (p.rect.empty()) return false;
    store_projected(p, opacity, st.projections[i], st.splats[i], st.footprints[i]);
    return true;
}

// Surfels [begin, end) that may be visible (raster::may_reach_view), into `ids`; returns how many. Four at
// a time: the full projection below is spared most surfels off screen (a third of the benchmark's).
template <typename T>
LG_ALWAYS_INLINE int may_be_visible(const SurfelBatch<T>& surfels, const raster::PinholeView<double>& view,
                                    std::size_t begin, std::size_t end, std::uint32_t* ids) {
    using P = cpu::Pack4d;
    const auto opaque = raster::opaque_reach<double>();
    int count = 0;
    for (std::size_t first = begin; first < end; first += P::kSize) {
        Vec3<P> mean;
        P scale_u, scale_v, opacity;
        for (int l = 0; l < P::kSize; ++l) {
            const std::size_t i = std::min(first + std::size_t(l), end - 1);
            for (int k = 0; k < 3; ++k) mean[k].v[l] = double(surfels.means[3 * i + k]);
            scale_u.v[l] = double(surfels.scales[2 * i]);
            scale_v.v[l] = double(surfels.scales[2 * i + 1]);
            opacity.v[l] = double(surfels.opacities[i]);
        }
        const auto may = raster::may_reach_view(mean, scale_u, scale_v, opacity, view, opaque);
        for (int l = 0; l < P::kSize && first + std::size_t(l) < end; ++l) {
            ids[count] = std::uint32_t(first + std::size_t(l));
            count += may[l] != 0;
        }
    }
    return count;
}

// The per-surfel set-up runs in double whatever T is: it is cheap next to the per-pixel work, and the
// kernel's coefficients (differences of nearly equal products) keep their precision when rounded to float.
// Four surfels of `ids` at a time, one per lane of a pack of doubles (project_surfel_lanes is the scalar
// projection's own code); lanes past `count` repeat the last surfel and are not stored. (The splat geometry
// is set up per surfel from the extracted lanes: done in lanes too, it measured 20 % slower.)
template <typename T>
LG_ALWAYS_INLINE void project_candidates(const SurfelBatch<T>& surfels, RasterState<T>& st,
                                         const raster::PinholeView<double>& view, const std::uint32_t* ids,
                                         int count) {
    using P = cpu::Pack4d;
    for (int first = 0; first < count; first += P::kSize) {
        raster::SurfelGeometry<P> g;
        P opacity, reach;
        for (int l = 0; l < P::kSize; ++l) {
            const std::size_t i = ids[std::min(first + l, count - 1)];
            const auto gi = surfels.geometry(i);
            for (int k = 0; k < 3; ++k) g.mean[k].v[l] = double(gi.mean[k]);
            for (int k = 0; k < 4; ++k) g.quat[k].v[l] = double(gi.quat[k]);
            g.scale_u.v[l] = double(gi.scale_u);
            g.scale_v.v[l] = double(gi.scale_v);
            opacity.v[l] = double(surfels.opacities[i]);
        }
        reach = raster::reach_rho(opacity);
        raster::ProjectionLanes<P> p;
        const auto visible = raster::project_surfel_lanes(g, reach, view, p);
        for (int l = 0; l < P::kSize && first + l < count; ++l) {
            const std::size_t i = ids[first + l];
            bool stored = false;
            if (visible[l]) {
                const Vec2<double> lo{p.lo.x[l], p.lo.y[l]}, hi{p.hi.x[l], p.hi.y[l]};
                const ProjectedSurfel<double> one{
                    {p.tu.x[l], p.tu.y[l], p.tu.z[l]},
                    {p.tv.x[l], p.tv.y[l], p.tv.z[l]},
                    {p.tw.x[l], p.tw.y[l], p.tw.z[l]},
                    {p.center.x[l], p.center.y[l]},
                    {p.normal.x[l], p.normal.y[l], p.normal.z[l]},
                    p.flip[l],
                    p.depth[l],
                    p.reach[l],
                    p.conic_center[l] != 0,
                    raster::reachable_pixels(p.whole_image[l] != 0, lo, hi, view.width, view.height)};
                stored = store_projection(one, opacity[l], st, i);
            }
            st.visible[i] = stored ? 1 : 0;
        }
    }
}

// Surfels [begin, end): culled, then projected, a chunk at a time (their ids stay in L1).
template <typename T>
LG_ALWAYS_INLINE void project_range(const SurfelBatch<T>& surfels, RasterState<T>& st,
                                    const raster::PinholeView<double>& view, std::size_t begin,
                                    std::size_t end) {
    constexpr std::size_t kChunk = 256;
    std::uint32_t ids[kChunk];
    for (std::size_t chunk = begin; chunk < end; chunk += kChunk) {
        const int count = may_be_visible(surfels, view, chunk, std::min(end, chunk + kChunk), ids);
        project_candidates(surfels, st, view, ids, count);
    }
}

// Compiled per instruction set like the tile kernels (FMA, and rounding instructions for the pixel box
// instead of libm calls), with everything it calls inlined into each version.
LG_FLATTEN LG_MULTIVERSION void project_surfels(const SurfelBatch<float>& surfels, RasterState<float>& st,
                                                const raster::PinholeView<double>& view, std::size_t begin,
                                                std::size_t end) {
    project_range(surfels, st, view, begin, end);
}
void project_surfels(const SurfelBatch<double>& surfels, RasterState<double>& st,
                     const raster::PinholeView<double>& view, std::size_t begin, std::size_t end) {
    project_range(surfels, st, view, begin, end);
}

template <typename T>
void project_all(const SurfelBatch<T>& surfels, RasterState<T>& st) {
    const std::size_t n = surfels.size();
    // Each written for the visible surfels only (and read only for them).
    resize_for_overwrite(st.projections, n);
    st.visible.assign(n, 0);
    resize_for_overwrite(st.splats, n);
    resize_for_overwrite(st.footprints, n);
    const raster::PinholeView<double> view = raster::cast_view<double>(st.view);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                      [&](const auto& r) { project_surfels(surfels, st, view, r.begin(), r.end()); });
}

// Copies what the per-pixel loops read into sorted-entry order (see RasterState::entry_splat). The surfels
// of consecutive entries are scattered in memory: those a few entries ahead are asked for early, so that
// the cache misses overlap instead of being waited for one by one. (Scattering instead, each surfel's
// record read once and written into all its entries during binning, measured 1.6x slower: the random
// writes each fetch their cache line.)
constexpr std::size_t kGatherAhead = 8;
template <typename T>
void gather_entries(const SurfelBatch<T>& surfels, RasterState<T>& st) {
    const std::size_t m = st.intersections();
    const int C = surfels.channels;
    resize_for_overwrite(st.entry_splat, m);
    resize_for_overwrite(st.entry_footprint, m);
    resize_for_overwrite(st.entry_color, m * std::size_t(C));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 4096), [&](const auto& r) {
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
            if (e + kGatherAhead < r.end()) {
                const std::uint32_t ahead = st.entry_surfel[e + kGatherAhead];
                __builtin_prefetch(&st.splats[ahead]);
                __builtin_prefetch(&st.footprints[ahead]);
                __builtin_prefetch(&surfels.colors[std::size_t(ahead) * C]);
            }
            const std::uint32_t id = st.entry_surfel[e];
            st.entry_splat[e] = st.splats[id];
            st.entry_footprint[e] = st.footprints[id];
            const T* color = &surfels.colors[std::size_t(id) * C];
            if (C == 3)  // a copy of known length: std::copy_n of C values was a call to memmove per entry
                std::copy_n(color, 3, &st.entry_color[e * 3]);
            else
                std::copy_n(color, C, &st.entry_color[e * C]);
        }
    });
}

template <typename T>
void allocate_images(RasterImages<T>& img, int width, int height, int channels) {
    const std::size_t np = std::size_t(width) * height;
    img.width = width, img.height = height, img.channels = channels;
    img.color.resize(np * channels);
    img.alpha.resize(np);
    img.depth.resize(np);
    img.median_depth.resize(np);
    img.normal.resize(np * 3);
    img.distortion.resize(np);
}

// Milliseconds since `start`, and restarts it.
double lap_ms(std::chrono::steady_clock::time_point& start) {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - start).count();
    start = now;
    return ms;
}

// Room for `values` slot values in `buffer`, from a cache line's start (the tiles stream whole lines).
template <typename T>
T* slots_in(std::vector<T>& buffer, std::size_t values) {
    constexpr std::size_t align = cpu::SlotLayout::kAlign;
    resize_for_overwrite(buffer, values + align / sizeof(T));
    void* start = buffer.data();
    std::size_t space = buffer.size() * sizeof(T);
    return static_cast<T*>(std::align(align, values * sizeof(T), start, space));
}

template <typename T>
LG_ALWAYS_INLINE void write_zero_gradients(SurfelGrads<T>& out, std::size_t i, int channels) {
    std::fill_n(&out.means[3 * i], 3, T(0));
    std::fill_n(&out.quats[4 * i], 4, T(0));
    std::fill_n(&out.scales[2 * i], 2, T(0));
    out.opacities[i] = T(0);
    if (channels == 3)  // a fill of known length: of a run-time length it was a call to memset
        std::fill_n(&out.colors[i * 3], 3, T(0));
    else
        std::fill_n(&out.colors[i * channels], channels, T(0));
    std::fill_n(&out.mean2d[2 * i], 2, T(0));
}

// The backward of the projection for up to eight visible surfels at once, one per lane: sums each one's
// (surfel, tile) slots, then converts the sums to the surfel's gradients. Lanes past `count` repeat the
// last surfel and are not stored. The per-surfel values go through plain arrays, lane by lane, into packs
// and back (written lane by lane into packs, GCC keeps them in memory halves; see tile_backward.h).
// kChannels is the surfels' channel count where it is known at compile time (RGB), else 0: the slot
// loops then have a fixed length.
template <int kChannels, typename T>
LG_ALWAYS_INLINE void reduce_lanes(const SurfelBatch<T>& surfels, const RasterState<T>& st, const T* slots,
                                   SurfelGrads<T>& out, const std::uint32_t* ids, int count) {
    using P = cpu::Pack8<T>;
    using Slot = cpu::SlotLayout;
    constexpr int N = cpu::kLanes;
    const int C = kChannels > 0 ? kChannels : surfels.channels;
    const int stride = Slot::stride(C);  // a multiple of the pack width
    const int line = Slot::line_stride(C);
    alignas(64) T sums[Slot::stride(kMaxChannels)][N];
    alignas(64) T lane_sums[N][Slot::stride(kMaxChannels)];  // the same, lane by lane (transposed below)
    // Per lane: the projection's rows (tu, tv, tw), filter centre, flip; the quaternion and scales.
    enum { kTu = 0, kTv = 3, kTw = 6, kCentre = 9, kFlip = 11, kQuat = 12, kScale = 16, kInputs = 18 };
    alignas(64) T in[kInputs][N];
    alignas(64) typename cpu::Int8<T>::I conic[N];
    for (int l = 0; l < N; ++l) {
        const std::uint32_t i = ids[std::min(l, count - 1)];
        // The sum starts from the first slot: a visible surfel has one in every tile it reaches, so at
        // least one. (Cleared first instead, by packs or `= {}`, the sum was a call to memset per surfel.)
        T* const sum = lane_sums[l];
        const std::uint32_t first = st.emission_offset[i], end = st.emission_offset[i + 1];
        if (first == end) throw Error("rasterizer backward: a visible surfel reaches no tile");
        for (int k = 0; k < stride; k += N)
            cpu::store_pack(sum + k, cpu::load_pack(&slots[std::size_t(first) * line + k]));
        for (std::uint32_t em = first + 1; em < end; ++em) {
            const T* slot = &slots[std::size_t(em) * line];
            for (int k = 0; k < stride; k += N)
                cpu::store_pack(sum + k, cpu::load_pack(sum + k) + cpu::load_pack(slot + k));
        }
        const raster::ProjectionVjpInputs<T>& ps = st.projections[i];
        for (int k = 0; k < 3; ++k)
            in[kTu + k][l] = ps.tu[k], in[kTv + k][l] = ps.tv[k], in[kTw + k][l] = ps.tw[k];
        in[kCentre][l] = ps.center.x, in[kCentre + 1][l] = ps.center.y;
        in[kFlip][l] = ps.flip;
        conic[l] = ps.conic_center ? -1 : 0;
        for (int k = 0; k < 4; ++k) in[kQuat + k][l] = surfels.quats[4 * i + k];
        in[kScale][l] = surfels.scales[2 * i], in[kScale + 1][l] = surfels.scales[2 * i + 1];
    }
    // The lanes' sums into packs of one value each, eight values at a time by shuffles (copied value by
    // value, each pack was then loaded from eight separate stores).
    for (int k = 0; k < stride; k += N) {
        P block[N];
        for (int l = 0; l < N; ++l) block[l] = cpu::load_pack(&lane_sums[l][k]);
        cpu::transpose_packs(block);
        for (int j = 0; j < N; ++j) cpu::store_pack(sums[k + j], block[j]);
    }
    const auto sum_of = [&](int k) LG_LAMBDA_INLINE { return cpu::load_pack(sums[k]); };
    const auto input = [&](int k) LG_LAMBDA_INLINE { return cpu::load_pack(in[k]); };
    const auto vec3 = [&](int k) LG_LAMBDA_INLINE { return Vec3<P>{input(k), input(k + 1), input(k + 2)}; };
    const raster::ProjectionVjpInputs<P> ps{vec3(kTu),    vec3(kTv),
                                            vec3(kTw),    {input(kCentre), input(kCentre + 1)},
                                            input(kFlip), cpu::load_lanes<T>(conic)};
    const raster::SurfelSlotGrad<P> g = raster::surfel_grad_from_slots(
        sum_of, ps, {input(kQuat), input(kQuat + 1), input(kQuat + 2), input(kQuat + 3)}, input(kScale),
        input(kScale + 1), st.view);
    // The results go out lane by lane from a plain array: read from the packs for a run-time lane, each
    // value was a copy of the pack's halves to memory and a load back, for every lane.
    const raster::SurfelGeometryGrad<P>& gg = g.geometry;
    enum { kMean = 0, kQuatOut = 3, kScaleU = 7, kScaleV = 8, kOpacity = 9, kMean2d = 10, kOutputs = 12 };
    alignas(64) T results[kOutputs][N];
    for (int k = 0; k < 3; ++k) cpu::store_pack(results[kMean + k], gg.mean[k]);
    for (int k = 0; k < 4; ++k) cpu::store_pack(results[kQuatOut + k], gg.quat[k]);
    cpu::store_pack(results[kScaleU], gg.scale_u);
    cpu::store_pack(results[kScaleV], gg.scale_v);
    cpu::store_pack(results[kOpacity], g.opacity);
    cpu::store_pack(results[kMean2d], g.mean2d.x);
    cpu::store_pack(results[kMean2d + 1], g.mean2d.y);
    for (int l = 0; l < count; ++l) {
        const std::size_t i = ids[l];
        for (int k = 0; k < 3; ++k) out.means[3 * i + k] = results[kMean + k][l];
        for (int k = 0; k < 4; ++k) out.quats[4 * i + k] = results[kQuatOut + k][l];
        out.scales[2 * i] = results[kScaleU][l];
        out.scales[2 * i + 1] = results[kScaleV][l];
        out.opacities[i] = results[kOpacity][l];
        out.mean2d[2 * i] = results[kMean2d][l];
        out.mean2d[2 * i + 1] = results[kMean2d + 1][l];
        for (int c = 0; c < C; ++c) out.colors[i * C + c] = sums[Slot::kColor + c][l];  // known C for RGB
    }
}

// Per surfel: the gradients of the visible ones (reduce_lanes, eight at a time), zeros for the others. A
// chunk of surfels at a time is split into the two kinds first, without branches (which kind a surfel is
// follows no pattern the branch predictor could learn), then each kind runs in a loop of its own. What the
// visible surfels kReduceAhead places further need is asked for early: they are scattered among the others,
// and the hardware's stream prefetch did not keep up (the loads of the projection waited).
constexpr int kReduceAhead = 16;
constexpr std::size_t kReduceChunk = 256;
template <typename T>
LG_ALWAYS_INLINE void reduce_range(const SurfelBatch<T>& surfels, const RasterState<T>& st, const T* slots,
                                   SurfelGrads<T>& out, std::size_t begin, std::size_t end) {
    const int line = cpu::SlotLayout::line_stride(surfels.channels);
    const int summed = cpu::SlotLayout::stride(surfels.channels);  // the values reduce_lanes reads
    std::uint32_t visible[kReduceChunk], hidden[kReduceChunk];
    for (std::size_t chunk = begin; chunk < end; chunk += kReduceChunk) {
        int num_visible = 0, num_hidden = 0;
        for (std::size_t i = chunk; i < std::min(end, chunk + kReduceChunk); ++i) {
            visible[num_visible] = hidden[num_hidden] = std::uint32_t(i);
            num_visible += st.visible[i] != 0;
            num_hidden += st.visible[i] == 0;
        }
        for (int j = 0; j < num_hidden; ++j) write_zero_gradients(out, hidden[j], surfels.channels);
        for (int first = 0; first < num_visible; first += cpu::kLanes) {
            const int ahead = first == 0 ? 0 : first + kReduceAhead;  // the chunk's first ones too
            for (int j = ahead; j < std::min(num_visible, first + kReduceAhead + cpu::kLanes); ++j) {
                const char* projection = reinterpret_cast<const char*>(&st.projections[visible[j]]);
                __builtin_prefetch(projection);
                __builtin_prefetch(projection + sizeof(raster::ProjectionVjpInputs<T>) - 1);
                const T* slot = &slots[std::size_t(st.emission_offset[visible[j]]) * line];
                __builtin_prefetch(slot);
                __builtin_prefetch(slot + summed - 1);
            }
            const int lanes = std::min(cpu::kLanes, num_visible - first);
            if (surfels.channels == 3)
                reduce_lanes<3>(surfels, st, slots, out, &visible[first], lanes);
            else
                reduce_lanes<0>(surfels, st, slots, out, &visible[first], lanes);
        }
    }
}

LG_FLATTEN LG_MULTIVERSION void reduce_surfels(const SurfelBatch<float>& surfels,
                                               const RasterState<float>& st, const float* slots,
                                               SurfelGrads<float>& out, std::size_t begin, std::size_t end) {
    reduce_range(surfels, st, slots, out, begin, end);
}
void reduce_surfels(const SurfelBatch<double>& surfels, const RasterState<double>& st, const double* slots,
                    SurfelGrads<double>& out, std::size_t begin, std::size_t end) {
    reduce_range(surfels, st, slots, out, begin, end);
}

template <typename T>
void reduce_surfel_gradients(const SurfelBatch<T>& surfels, const RasterState<T>& st, const T* slots,
                             SurfelGrads<T>& out) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, surfels.size(), 256), [&](const auto& range) {
        reduce_surfels(surfels, st, slots, out, range.begin(), range.end());
    });
}

}  // namespace

template <typename T>
RasterImages<T> rasterize_forward_cpu(const Camera& camera, const SurfelBatch<T>& surfels,
                                      const RasterSettings<T>& settings, RasterState<T>& st) {
    RasterImages<T> img;
    rasterize_forward_cpu(camera, surfels, settings, st, img);
    return img;
}

template <typename T>
void rasterize_forward_cpu(const Camera& camera, const SurfelBatch<T>& surfels,
                           const RasterSettings<T>& settings, RasterState<T>& st, RasterImages<T>& img) {
    st.view = pinhole_view<T>(camera);
    st.tiles_x = (camera.width + cpu::kTileSize - 1) / cpu::kTileSize;
    st.tiles_y = (camera.height + cpu::kTileSize - 1) / cpu::kTileSize;
    st.background = settings.background;
    check_surfel_batch(surfels);
    auto clock = std::chrono::steady_clock::now();
    project_all(surfels, st);
    st.phase_ms.project = lap_ms(clock);
    bin_surfels_to_tiles(st);
    st.phase_ms.bin = lap_ms(clock);
    gather_entries(surfels, st);
    st.phase_ms.gather = lap_ms(clock);

    const std::size_t np = std::size_t(camera.width) * camera.height;
    st.final_transmittance.resize(np);
    st.contributors.resize(np);
    st.median_entry.resize(np);
    st.m1.resize(np);
    st.m2.resize(np);
    allocate_images(img, camera.width, camera.height, surfels.channels);
    const int num_tiles = st.tiles_x * st.tiles_y;
    st.block_entries.resize(std::size_t(num_tiles));
    st.block_start.resize(std::size_t(num_tiles) * (cpu::kTileBlocks + 1));
    tbb::enumerable_thread_specific<cpu::TileScratch<T>> scratch;
    tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 1), [&](const auto& r) {
        cpu::TileScratch<T>& mine = scratch.local();
        for (int t = r.begin(); t != r.end(); ++t) cpu::forward_tile(t, surfels, st, img, mine);
    });
    st.phase_ms.blend = lap_ms(clock);
}

namespace {

template <typename T>
void backward_into(const SurfelBatch<T>& surfels, const RasterState<T>& st, const RasterImageGrads<T>& grads,
                   std::vector<T>& slot_buffer, SurfelGrads<T>& out) {
    check_surfel_batch(surfels);
    if (surfels.size() != st.visible.size())
        throw Error("rasterizer backward: " + std::to_string(surfels.size()) + " surfels, the forward had " +
                    std::to_string(st.visible.size()));
    auto clock = std::chrono::steady_clock::now();
    const std::size_t n = surfels.size();
    // Every slot is written by its tile (zeros for entries no pixel reached), so no clearing here.
    T* const slots =
        slots_in(slot_buffer, st.intersections() * cpu::SlotLayout::line_stride(surfels.channels));
    const int num_tiles = st.tiles_x * st.tiles_y;
    tbb::enumerable_thread_specific<cpu::TileScratch<T>> scratch;
    tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 1), [&](const auto& r) {
        cpu::TileScratch<T>& mine = scratch.local();
        for (int t = r.begin(); t != r.end(); ++t) cpu::backward_tile(t, surfels, st, grads, slots, mine);
    });
    st.phase_ms.backward_tiles = lap_ms(clock);
    // Every entry is written by the reduction (zeros for invisible surfels).
    out.means.resize(3 * n);
    out.quats.resize(4 * n);
    out.scales.resize(2 * n);
    out.opacities.resize(n);
    out.colors.resize(n * surfels.channels);
    out.mean2d.resize(2 * n);
    reduce_surfel_gradients(surfels, st, slots, out);
    st.phase_ms.reduce = lap_ms(clock);
}

}  // namespace

template <typename T>
SurfelGrads<T> rasterize_backward_cpu(const SurfelBatch<T>& surfels, const RasterState<T>& st,
                                      const RasterImageGrads<T>& grads) {
    std::vector<T> slots;
    SurfelGrads<T> out;
    backward_into(surfels, st, grads, slots, out);
    return out;
}

template <typename T>
void rasterize_backward_cpu(const SurfelBatch<T>& surfels, RasterState<T>& st,
                            const RasterImageGrads<T>& grads, SurfelGrads<T>& out) {
    backward_into(surfels, st, grads, st.gradient_slots, out);
}

template RasterImages<float> rasterize_forward_cpu(const Camera&, const SurfelBatch<float>&,
                                                   const RasterSettings<float>&, RasterState<float>&);
template RasterImages<double> rasterize_forward_cpu(const Camera&, const SurfelBatch<double>&,
                                                    const RasterSettings<double>&, RasterState<double>&);
template void rasterize_forward_cpu(const Camera&, const SurfelBatch<float>&, const RasterSettings<float>&,
                                    RasterState<float>&, RasterImages<float>&);
template void rasterize_forward_cpu(const Camera&, const SurfelBatch<double>&, const RasterSettings<double>&,
                                    RasterState<double>&, RasterImages<double>&);
template SurfelGrads<float> rasterize_backward_cpu(const SurfelBatch<float>&, const RasterState<float>&,
                                                   const RasterImageGrads<float>&);
template SurfelGrads<double> rasterize_backward_cpu(const SurfelBatch<double>&, const RasterState<double>&,
                                                    const RasterImageGrads<double>&);
template void rasterize_backward_cpu(const SurfelBatch<float>&, RasterState<float>&,
                                     const RasterImageGrads<float>&, SurfelGrads<float>&);
template void rasterize_backward_cpu(const SurfelBatch<double>&, RasterState<double>&,
                                     const RasterImageGrads<double>&, SurfelGrads<double>&);

}  // namespace lumigauss
