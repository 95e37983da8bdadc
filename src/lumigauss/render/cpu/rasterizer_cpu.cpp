#include "lumigauss/render/cpu/rasterizer_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "lumigauss/render/cpu/multiversion.h"
#include "lumigauss/render/cpu/tile_backward.h"
#include "lumigauss/render/cpu/tile_binning.h"
#include "lumigauss/render/cpu/tile_kernels.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using raster::ProjectedSurfel;

template <typename T>
Vec3<T> to(Vec3<double> v) {
    return v.cast<T>();
}

// Stores one projected surfel: the projection state the backward reads, what the per-pixel kernel reads,
// and the footprint binning reads. Returns false (and stores nothing) when it reaches no pixel.
template <typename T>
LG_ALWAYS_INLINE bool store_projection(const ProjectedSurfel<double>& p, double opacity, RasterState<T>& st,
                                       std::size_t i) {
    if (p.rect.empty()) return false;
    const auto sg = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, opacity, p.reach);
    st.projected[i] = {to<T>(p.tu),     to<T>(p.tv), to<T>(p.tw), {T(p.center.x), T(p.center.y)},
                       to<T>(p.normal), T(p.flip),   T(p.depth),  T(p.reach),
                       p.conic_center,  p.rect};
    st.splats[i] = {
        to<T>(sg.pa),  to<T>(sg.pb),    to<T>(sg.pd), to<T>(sg.tw), {T(sg.center.x), T(sg.center.y)},
        T(sg.opacity), T(sg.rho_cutoff)};
    st.footprints[i] = {p.rect, to<T>(p.normal), T(p.depth)};
    return true;
}

// The per-surfel set-up runs in double whatever T is: it is cheap next to the per-pixel work, and the
// kernel's coefficients (differences of nearly equal products) keep their precision when rounded to float.
// Four surfels at a time, one per lane of a pack of doubles (project_surfel_lanes is the scalar
// projection's own code); lanes past `end` repeat the last surfel and are not stored. (The splat geometry
// is set up per surfel from the extracted lanes: done in lanes too, it measured 20 % slower.)
template <typename T>
LG_ALWAYS_INLINE void project_range(const SurfelBatch<T>& surfels, RasterState<T>& st,
                                    const raster::PinholeView<double>& view, std::size_t begin,
                                    std::size_t end) {
    using P = cpu::Pack4d;
    for (std::size_t first = begin; first < end; first += P::kSize) {
        raster::SurfelGeometry<P> g;
        P opacity, reach;
        for (int l = 0; l < P::kSize; ++l) {
            const std::size_t i = std::min(first + std::size_t(l), end - 1);
            const auto gi = surfels.geometry(i);
            for (int k = 0; k < 3; ++k) g.mean[k].v[l] = double(gi.mean[k]);
            for (int k = 0; k < 4; ++k) g.quat[k].v[l] = double(gi.quat[k]);
            g.scale_u.v[l] = double(gi.scale_u);
            g.scale_v.v[l] = double(gi.scale_v);
            opacity.v[l] = double(surfels.opacities[i]);
            reach.v[l] = raster::reach_rho(opacity.v[l]);
        }
        raster::ProjectionLanes<P> p;
        const auto visible = raster::project_surfel_lanes(g, reach, view, p);
        for (int l = 0; l < P::kSize && first + std::size_t(l) < end; ++l) {
            const std::size_t i = first + std::size_t(l);
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
    st.projected.resize(n);
    st.visible.assign(n, 0);
    st.splats.resize(n);
    st.footprints.resize(n);
    const raster::PinholeView<double> view{st.view.rotation.template cast<double>(),
                                           st.view.translation.template cast<double>(),
                                           double(st.view.fx),
                                           double(st.view.fy),
                                           double(st.view.cx),
                                           double(st.view.cy),
                                           st.view.width,
                                           st.view.height};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                      [&](const auto& r) { project_surfels(surfels, st, view, r.begin(), r.end()); });
}

// Copies what the per-pixel loops read into sorted-entry order (see RasterState::entry_splat). The surfels
// of consecutive entries are scattered in memory: those a few entries ahead are asked for early, so that
// the cache misses overlap instead of being waited for one by one.
constexpr std::size_t kGatherAhead = 8;
template <typename T>
void gather_entries(const SurfelBatch<T>& surfels, RasterState<T>& st) {
    const std::size_t m = st.intersections();
    const int C = surfels.channels;
    st.entry_splat.resize(m);
    st.entry_footprint.resize(m);
    st.entry_color.resize(m * std::size_t(C));
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
            std::copy_n(&surfels.colors[std::size_t(id) * C], C, &st.entry_color[e * C]);
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

void check_channels(int channels) {
    if (channels < 1 || channels > kMaxChannels)
        throw Error("the rasterizer supports 1 to " + std::to_string(kMaxChannels) +
                    " colour channels, not " + std::to_string(channels));
}

template <typename T>
LG_ALWAYS_INLINE void write_zero_gradients(SurfelGrads<T>& out, std::size_t i, int channels) {
    std::fill_n(&out.means[3 * i], 3, T(0));
    std::fill_n(&out.quats[4 * i], 4, T(0));
    std::fill_n(&out.scales[2 * i], 2, T(0));
    out.opacities[i] = T(0);
    std::fill_n(&out.colors[i * channels], channels, T(0));
    std::fill_n(&out.mean2d[2 * i], 2, T(0));
}

// Per surfel: sums its (surfel, tile) slots and runs the projection backward (zeros for the invisible).
template <typename T>
LG_ALWAYS_INLINE void reduce_range(const SurfelBatch<T>& surfels, const RasterState<T>& st, const T* slots,
                                   SurfelGrads<T>& out, std::size_t begin, std::size_t end) {
    const int C = surfels.channels;
    const int stride = cpu::SlotLayout::stride(C);  // a multiple of the pack width
    alignas(64) T sum[cpu::SlotLayout::stride(kMaxChannels)];
    for (std::size_t i = begin; i != end; ++i) {
        if (!st.visible[i]) {
            write_zero_gradients(out, i, C);
            continue;
        }
        std::fill_n(sum, stride, T(0));
        for (std::uint32_t em = st.emission_offset[i]; em < st.emission_offset[i + 1]; ++em) {
            const T* slot = &slots[std::size_t(em) * stride];
            for (int k = 0; k < stride; ++k) sum[k] += slot[k];
        }
        raster::SplatGrad<T> sg;
        raster::ProjectedSurfelGrad<T> pg{};
        for (int k = 0; k < 3; ++k) {
            sg.pa[k] = sum[cpu::SlotLayout::kPa + k];
            sg.pb[k] = sum[cpu::SlotLayout::kPb + k];
            sg.pd[k] = sum[cpu::SlotLayout::kPd + k];
            sg.tw[k] = sum[cpu::SlotLayout::kTw + k];
            pg.normal[k] = sum[cpu::SlotLayout::kNormal + k];
        }
        sg.center = {sum[cpu::SlotLayout::kCenter], sum[cpu::SlotLayout::kCenter + 1]};
        sg.opacity = sum[cpu::SlotLayout::kOpacity];
        const ProjectedSurfel<T>& ps = st.projected[i];
        T g_opacity = 0;
        raster::to_ray_transform_grad(ps.tu, ps.tv, ps.tw, ps.center, sg, pg, g_opacity);
        // Screen-space gradient for densification: a translation by delta pixels adds delta * tw.z to
        // the third column of rows tu and tv. Like the reference, it leaves out the low-pass branch.
        out.mean2d[2 * i] = pg.tu.z * ps.tw.z;
        out.mean2d[2 * i + 1] = pg.tv.z * ps.tw.z;
        const auto gg = raster::project_surfel_vjp(surfels.geometry(i), st.view, ps, pg);
        for (int k = 0; k < 3; ++k) out.means[3 * i + k] = gg.mean[k];
        for (int k = 0; k < 4; ++k) out.quats[4 * i + k] = gg.quat[k];
        out.scales[2 * i] = gg.scale_u;
        out.scales[2 * i + 1] = gg.scale_v;
        out.opacities[i] = g_opacity;
        for (int c = 0; c < C; ++c) out.colors[i * C + c] = sum[cpu::SlotLayout::kColor + c];
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
    check_channels(surfels.channels);
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
    check_channels(surfels.channels);
    auto clock = std::chrono::steady_clock::now();
    const std::size_t n = surfels.size();
    const int stride = cpu::SlotLayout::stride(surfels.channels);
    // Every slot is written by its tile (zeros for entries no pixel reached), so no clearing here.
    slot_buffer.resize(st.intersections() * std::size_t(stride));
    T* slots = slot_buffer.data();
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
