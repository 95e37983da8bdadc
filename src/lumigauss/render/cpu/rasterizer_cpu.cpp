#include "lumigauss/render/cpu/rasterizer_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>
#include <string>

#include "lumigauss/render/cpu/splat_row.h"
#include "lumigauss/render/surfel_kernel.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using raster::kTileSize;
using raster::PixelRect;
using raster::ProjectedSurfel;
using raster::SplatGeometry;

// Pixels of `rect` inside tile (tx, ty).
PixelRect clip_to_tile(const PixelRect& rect, int tx, int ty) {
    return {std::max(rect.x0, tx * kTileSize), std::max(rect.y0, ty * kTileSize),
            std::min(rect.x1, tx * kTileSize + kTileSize - 1),
            std::min(rect.y1, ty * kTileSize + kTileSize - 1)};
}

template <typename T>
T value_or_zero(const std::vector<T>& v, std::size_t i) {
    return v.empty() ? T(0) : v[i];
}

// --- Preprocess and binning -------------------------------------------------------------------------

template <typename T>
Vec3<T> to(Vec3<double> v) {
    return v.cast<T>();
}

// The per-surfel set-up runs in double whatever T is: it is cheap next to the per-pixel work, and the
// kernel's coefficients (differences of nearly equal products) keep their precision when rounded to float.
template <typename T>
void project_all(const SurfelBatch<T>& surfels, RasterState<T>& st) {
    const std::size_t n = surfels.size();
    st.projected.resize(n);
    st.visible.assign(n, 0);
    st.splats.resize(n);
    const raster::PinholeView<double> view{st.view.rotation.template cast<double>(),
                                           st.view.translation.template cast<double>(),
                                           double(st.view.fx),
                                           double(st.view.fy),
                                           double(st.view.cx),
                                           double(st.view.cy),
                                           st.view.width,
                                           st.view.height};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const double opacity = double(surfels.opacities[i]);
            const auto g = surfels.geometry(i);
            const raster::SurfelGeometry<double> gd{
                g.mean.template cast<double>(),
                {double(g.quat.x), double(g.quat.y), double(g.quat.z), double(g.quat.w)},
                double(g.scale_u),
                double(g.scale_v)};
            ProjectedSurfel<double> p;
            const bool ok =
                opacity * raster::kAlphaMax >= raster::kAlphaMin && raster::project_surfel(gd, view, p);
            st.visible[i] = ok ? 1 : 0;
            if (!ok) continue;
            const auto sg = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, opacity);
            st.projected[i] = {to<T>(p.tu),    to<T>(p.tv),     to<T>(p.tw), {T(p.center.x), T(p.center.y)},
                               T(p.radius),    to<T>(p.normal), T(p.flip),   T(p.depth),
                               p.conic_center, p.rect};
            st.splats[i] = {
                to<T>(sg.pa),  to<T>(sg.pb),    to<T>(sg.pd), to<T>(sg.tw), {T(sg.center.x), T(sg.center.y)},
                T(sg.opacity), T(sg.rho_cutoff)};
        }
    });
}

// Builds the per-tile lists of surfels sorted front to back: emit one (surfel, tile) pair per touched
// tile, counting-sort the pairs by tile, then sort each tile's list by depth (ties by surfel id, so the
// order is deterministic).
template <typename T>
void bin_and_sort(RasterState<T>& st) {
    const std::size_t n = st.projected.size();
    const auto tile_span = [&](std::size_t i, int& tx0, int& ty0, int& tx1, int& ty1) {
        const PixelRect& r = st.projected[i].rect;
        tx0 = r.x0 / kTileSize, ty0 = r.y0 / kTileSize, tx1 = r.x1 / kTileSize, ty1 = r.y1 / kTileSize;
    };
    st.emission_offset.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t count = 0;
        if (st.visible[i]) {
            int tx0, ty0, tx1, ty1;
            tile_span(i, tx0, ty0, tx1, ty1);
            count = std::uint32_t((tx1 - tx0 + 1) * (ty1 - ty0 + 1));
        }
        st.emission_offset[i + 1] = st.emission_offset[i] + count;
    }
    const std::size_t total = st.emission_offset[n];
    const std::size_t num_tiles = std::size_t(st.tiles_x) * st.tiles_y;

    std::vector<std::uint32_t> emission_tile(total);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (!st.visible[i]) continue;
            int tx0, ty0, tx1, ty1;
            tile_span(i, tx0, ty0, tx1, ty1);
            std::uint32_t e = st.emission_offset[i];
            for (int ty = ty0; ty <= ty1; ++ty)
                for (int tx = tx0; tx <= tx1; ++tx) emission_tile[e++] = std::uint32_t(ty * st.tiles_x + tx);
        }
    });

    st.tile_start.assign(num_tiles + 1, 0);
    for (std::uint32_t t : emission_tile) ++st.tile_start[t + 1];
    std::partial_sum(st.tile_start.begin(), st.tile_start.end(), st.tile_start.begin());

    // Scatter emissions into tile order; within a tile they stay in surfel order for now.
    std::vector<std::uint32_t> entry_emission(total);
    {
        std::vector<std::uint32_t> cursor(st.tile_start.begin(), st.tile_start.end() - 1);
        for (std::uint32_t e = 0; e < total; ++e) entry_emission[cursor[emission_tile[e]]++] = e;
    }
    std::vector<std::uint32_t> emission_surfel(total);
    for (std::size_t i = 0; i < n; ++i)
        std::fill(emission_surfel.begin() + st.emission_offset[i],
                  emission_surfel.begin() + st.emission_offset[i + 1], std::uint32_t(i));

    st.entry_surfel.resize(total);
    st.emission_entry.resize(total);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_tiles, 4), [&](const auto& r) {
        for (std::size_t t = r.begin(); t != r.end(); ++t) {
            auto first = entry_emission.begin() + st.tile_start[t];
            auto last = entry_emission.begin() + st.tile_start[t + 1];
            std::sort(first, last, [&](std::uint32_t a, std::uint32_t b) {
                const std::uint32_t sa = emission_surfel[a], sb = emission_surfel[b];
                const T da = st.projected[sa].depth, db = st.projected[sb].depth;
                return da < db || (da == db && sa < sb);
            });
            for (std::uint32_t k = st.tile_start[t]; k < st.tile_start[t + 1]; ++k) {
                st.entry_surfel[k] = emission_surfel[entry_emission[k]];
                st.emission_entry[entry_emission[k]] = k;
            }
        }
    });
}

// --- Forward ---------------------------------------------------------------------------------------

template <typename T>
void allocate_images(RasterImages<T>& img, int width, int height, int channels) {
    const std::size_t np = std::size_t(width) * height;
    img.width = width, img.height = height, img.channels = channels;
    img.color.assign(np * channels, T(0));
    img.alpha.assign(np, T(0));
    img.depth.assign(np, T(0));
    img.median_depth.assign(np, T(0));
    img.normal.assign(np * 3, T(0));
    img.distortion.assign(np, T(0));
}

// Pixels of tile `tile` (inclusive bounds, clipped to the image).
PixelRect tile_pixels(int tile, int tiles_x, int width, int height) {
    const int tx = tile % tiles_x, ty = tile / tiles_x;
    return {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize) - 1,
            std::min(height, (ty + 1) * kTileSize) - 1};
}

template <typename T>
void render_tile_forward(int tile, const SurfelBatch<T>& surfels, RasterState<T>& st, RasterImages<T>& img) {
    const int width = st.view.width, C = surfels.channels;
    const PixelRect tr = tile_pixels(tile, st.tiles_x, width, st.view.height);
    std::vector<T>& trans = st.final_transmittance;
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            trans[pix] = T(1);
            st.contributors[pix] = 0;
            st.median_entry[pix] = -1;
            st.m1[pix] = st.m2[pix] = T(0);
        }
    int alive = (tr.x1 - tr.x0 + 1) * (tr.y1 - tr.y0 + 1);
    bool finished[kTileSize * kTileSize] = {};
    raster::RowSamples<T> row;
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];

    for (std::uint32_t e = begin; e < end && alive > 0; ++e) {
        const std::uint32_t s = st.entry_surfel[e];
        const ProjectedSurfel<T>& ps = st.projected[s];
        const T* color = &surfels.colors[std::size_t(s) * C];
        const PixelRect r = clip_to_tile(ps.rect, tr.x0 / kTileSize, tr.y0 / kTileSize);
        for (int y = r.y0; y <= r.y1; ++y) {
            raster::splat_row(st.splats[s], T(tr.x0) + T(0.5), T(y) + T(0.5), r.x0 - tr.x0, r.x1 - tr.x0,
                              row);
            for (int i = r.x0 - tr.x0; i <= r.x1 - tr.x0; ++i) {
                const T alpha = row.alpha[i];
                bool& done = finished[(y - tr.y0) * kTileSize + i];
                if (alpha == T(0) || done) continue;
                const std::size_t pix = std::size_t(y) * width + tr.x0 + i;
                const T t_before = trans[pix];
                const T t_after = t_before * (T(1) - alpha);
                if (t_after < T(raster::kTransmittanceMin)) {
                    // This splat would make the pixel opaque: the pixel stops here without compositing it.
                    done = true;
                    --alive;
                    continue;
                }
                const T z = row.z[i];
                const T w = alpha * t_before;
                for (int c = 0; c < C; ++c) img.color[pix * C + c] += w * color[c];
                img.depth[pix] += w * z;
                for (int k = 0; k < 3; ++k) img.normal[pix * 3 + k] += w * ps.normal[k];
                const T m = raster::distortion_depth(z);
                img.distortion[pix] += w * (m * m * (T(1) - t_before) + st.m2[pix] - T(2) * m * st.m1[pix]);
                st.m1[pix] += w * m;
                st.m2[pix] += w * m * m;
                if (t_before > T(0.5)) {
                    img.median_depth[pix] = z;
                    st.median_entry[pix] = std::int32_t(e);
                }
                st.contributors[pix] = e - begin + 1;
                trans[pix] = t_after;
            }
        }
    }
    const std::vector<T>& bg = st.background;
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            const T t_final = trans[pix];
            img.alpha[pix] = T(1) - t_final;
            for (int c = 0; c < C; ++c) img.color[pix * C + c] += t_final * value_or_zero(bg, std::size_t(c));
        }
}

// --- Backward --------------------------------------------------------------------------------------

// Layout of one (surfel, tile) gradient slot.
struct SlotLayout {
    static constexpr int kPa = 0, kPb = 3, kPd = 6, kTw = 9, kCenter = 12, kNormal = 14, kOpacity = 17,
                         kColor = 18;
    static int stride(int channels) { return kColor + channels; }
};

// Per-pixel state of the back-to-front walk, and the pixel's incoming gradients (zero where a map has none).
template <typename T, int C>
struct PixelBack {
    T trans;  // transmittance behind the splat being processed
    T acc_color[C], acc_normal[3], acc_z, acc_alpha, acc_dist;  // blended values of the splats behind
    T g_color[C], g_normal[3], g_depth, g_alpha, g_dist, g_median;
    T bg_term;  // T_final * (background . dL/dcolor)
};

template <typename T>
T grad_at(const std::vector<T>& g, std::size_t i) {
    return g.empty() ? T(0) : g[i];
}

// C is a compile-time channel count (3 or 6, else the general kMaxChannels path) so the per-channel loops
// unroll and the state lives in fixed arrays.
template <typename T, int C>
void render_tile_backward(int tile, int channels, const SurfelBatch<T>& surfels, const RasterState<T>& st,
                          const RasterImageGrads<T>& g, std::vector<T>& slots) {
    const int width = st.view.width;
    const int stride = SlotLayout::stride(channels);
    const PixelRect tr = tile_pixels(tile, st.tiles_x, width, st.view.height);
    PixelBack<T, C> px_state[kTileSize * kTileSize];
    std::uint32_t last = 0;  // entries at or past the largest contributor count do not touch any pixel
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            PixelBack<T, C>& p = px_state[(y - tr.y0) * kTileSize + (x - tr.x0)];
            p = {};
            p.trans = st.final_transmittance[pix];
            T dot_bg = 0;
            for (int c = 0; c < channels; ++c) {
                p.g_color[c] = grad_at(g.color, pix * channels + c);
                dot_bg += value_or_zero(st.background, std::size_t(c)) * p.g_color[c];
            }
            p.bg_term = p.trans * dot_bg;
            for (int k = 0; k < 3; ++k) p.g_normal[k] = grad_at(g.normal, pix * 3 + k);
            p.g_depth = grad_at(g.depth, pix);
            p.g_alpha = grad_at(g.alpha, pix);
            p.g_dist = grad_at(g.distortion, pix);
            p.g_median = grad_at(g.median_depth, pix);
            last = std::max(last, st.contributors[pix]);
        }

    raster::RowSamples<T> row;
    const std::uint32_t begin = st.tile_start[tile];
    for (std::uint32_t e = begin + last; e-- > begin;) {
        const std::uint32_t s = st.entry_surfel[e];
        const ProjectedSurfel<T>& ps = st.projected[s];
        const SplatGeometry<T>& geo = st.splats[s];
        const T* color = &surfels.colors[std::size_t(s) * channels];
        const PixelRect r = clip_to_tile(ps.rect, tr.x0 / kTileSize, tr.y0 / kTileSize);
        raster::SplatGrad<T> acc{};
        Vec3<T> g_normal{};
        T g_color[C] = {};
        for (int y = r.y0; y <= r.y1; ++y) {
            const T py = T(y) + T(0.5);
            raster::splat_row(geo, T(tr.x0) + T(0.5), py, r.x0 - tr.x0, r.x1 - tr.x0, row);
            for (int i = r.x0 - tr.x0; i <= r.x1 - tr.x0; ++i) {
                const T alpha = row.alpha[i];
                if (alpha == T(0)) continue;
                const std::size_t pix = std::size_t(y) * width + tr.x0 + i;
                if (e - begin >= st.contributors[pix]) continue;
                PixelBack<T, C>& p = px_state[(y - tr.y0) * kTileSize + i];
                const T z = row.z[i];
                const T one_minus_a = T(1) - alpha;
                const T t_before = p.trans / one_minus_a;
                const T w = alpha * t_before;

                // dL/dalpha: this splat's value against the blend of those behind it, for every map.
                T g_alpha_inner = 0;
                for (int c = 0; c < channels; ++c) {
                    g_color[c] += w * p.g_color[c];
                    g_alpha_inner += (color[c] - p.acc_color[c]) * p.g_color[c];
                }
                for (int k = 0; k < 3; ++k) {
                    g_normal[k] += w * p.g_normal[k];
                    g_alpha_inner += (ps.normal[k] - p.acc_normal[k]) * p.g_normal[k];
                }
                const T m = raster::distortion_depth(z);
                const T a_total = T(1) - st.final_transmittance[pix];
                const T dist_w = (m * m * a_total + st.m2[pix] - T(2) * m * st.m1[pix]) * p.g_dist;  // dL/dw
                g_alpha_inner +=
                    (z - p.acc_z) * p.g_depth + (T(1) - p.acc_alpha) * p.g_alpha + dist_w - p.acc_dist;
                const T g_alpha = t_before * g_alpha_inner - p.bg_term / one_minus_a;

                T g_z = w * p.g_depth;
                if (st.median_entry[pix] == std::int32_t(e)) g_z += p.g_median;
                g_z +=
                    T(2) * w * (m * a_total - st.m1[pix]) * p.g_dist * raster::distortion_depth_derivative(z);

                raster::evaluate_splat_vjp(geo, T(tr.x0 + i) + T(0.5), py, row.sample(i), g_alpha, g_z, acc);

                // Fold this splat into the "behind" accumulators of the splat in front of it.
                for (int c = 0; c < channels; ++c)
                    p.acc_color[c] = alpha * color[c] + one_minus_a * p.acc_color[c];
                for (int k = 0; k < 3; ++k)
                    p.acc_normal[k] = alpha * ps.normal[k] + one_minus_a * p.acc_normal[k];
                p.acc_z = alpha * z + one_minus_a * p.acc_z;
                p.acc_alpha = alpha + one_minus_a * p.acc_alpha;
                p.acc_dist = alpha * dist_w + one_minus_a * p.acc_dist;
                p.trans = t_before;
            }
        }
        T* slot = &slots[std::size_t(e) * stride];
        for (int k = 0; k < 3; ++k) {
            slot[SlotLayout::kPa + k] = acc.pa[k];
            slot[SlotLayout::kPb + k] = acc.pb[k];
            slot[SlotLayout::kPd + k] = acc.pd[k];
            slot[SlotLayout::kTw + k] = acc.tw[k];
            slot[SlotLayout::kNormal + k] = g_normal[k];
        }
        slot[SlotLayout::kCenter] = acc.center.x;
        slot[SlotLayout::kCenter + 1] = acc.center.y;
        slot[SlotLayout::kOpacity] = acc.opacity;
        for (int c = 0; c < channels; ++c) slot[SlotLayout::kColor + c] = g_color[c];
    }
}

template <typename T>
void reduce_surfel_gradients(const SurfelBatch<T>& surfels, const RasterState<T>& st,
                             const std::vector<T>& slots, SurfelGrads<T>& out) {
    const int C = surfels.channels;
    const int stride = SlotLayout::stride(C);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, surfels.size(), 256), [&](const auto& range) {
        std::vector<T> sum(stride);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            if (!st.visible[i]) continue;
            std::fill(sum.begin(), sum.end(), T(0));
            for (std::uint32_t em = st.emission_offset[i]; em < st.emission_offset[i + 1]; ++em) {
                const T* slot = &slots[std::size_t(st.emission_entry[em]) * stride];
                for (int k = 0; k < stride; ++k) sum[k] += slot[k];
            }
            raster::SplatGrad<T> sg;
            raster::ProjectedSurfelGrad<T> pg{};
            for (int k = 0; k < 3; ++k) {
                sg.pa[k] = sum[SlotLayout::kPa + k];
                sg.pb[k] = sum[SlotLayout::kPb + k];
                sg.pd[k] = sum[SlotLayout::kPd + k];
                sg.tw[k] = sum[SlotLayout::kTw + k];
                pg.normal[k] = sum[SlotLayout::kNormal + k];
            }
            sg.center = {sum[SlotLayout::kCenter], sum[SlotLayout::kCenter + 1]};
            sg.opacity = sum[SlotLayout::kOpacity];
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
            for (int c = 0; c < C; ++c) out.colors[i * C + c] = sum[SlotLayout::kColor + c];
        }
    });
}

}  // namespace

template <typename T>
RasterImages<T> rasterize_forward_cpu(const Camera& camera, const SurfelBatch<T>& surfels,
                                      const RasterSettings<T>& settings, RasterState<T>& st) {
    st.view = pinhole_view<T>(camera);
    st.tiles_x = (camera.width + kTileSize - 1) / kTileSize;
    st.tiles_y = (camera.height + kTileSize - 1) / kTileSize;
    st.background = settings.background;
    project_all(surfels, st);
    bin_and_sort(st);

    const std::size_t np = std::size_t(camera.width) * camera.height;
    st.final_transmittance.assign(np, T(1));
    st.contributors.assign(np, 0);
    st.median_entry.assign(np, -1);
    st.m1.assign(np, T(0));
    st.m2.assign(np, T(0));
    if (surfels.channels > kMaxChannels)
        throw Error("the rasterizer supports at most " + std::to_string(kMaxChannels) + " channels");
    RasterImages<T> img;
    allocate_images(img, camera.width, camera.height, surfels.channels);
    const int num_tiles = st.tiles_x * st.tiles_y;
    tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 1), [&](const auto& r) {
        for (int t = r.begin(); t != r.end(); ++t) render_tile_forward(t, surfels, st, img);
    });
    return img;
}

template <typename T>
SurfelGrads<T> rasterize_backward_cpu(const SurfelBatch<T>& surfels, const RasterState<T>& st,
                                      const RasterImageGrads<T>& grads) {
    const std::size_t n = surfels.size();
    const int stride = SlotLayout::stride(surfels.channels);
    std::vector<T> slots(st.intersections() * std::size_t(stride), T(0));
    const int num_tiles = st.tiles_x * st.tiles_y;
    const int C = surfels.channels;
    if (C > kMaxChannels)
        throw Error("the rasterizer supports at most " + std::to_string(kMaxChannels) + " channels");
    tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 1), [&](const auto& r) {
        for (int t = r.begin(); t != r.end(); ++t) {
            if (C == 3)
                render_tile_backward<T, 3>(t, C, surfels, st, grads, slots);
            else if (C == 6)
                render_tile_backward<T, 6>(t, C, surfels, st, grads, slots);
            else
                render_tile_backward<T, kMaxChannels>(t, C, surfels, st, grads, slots);
        }
    });
    SurfelGrads<T> out;
    out.means.assign(3 * n, T(0));
    out.quats.assign(4 * n, T(0));
    out.scales.assign(2 * n, T(0));
    out.opacities.assign(n, T(0));
    out.colors.assign(n * surfels.channels, T(0));
    out.mean2d.assign(2 * n, T(0));
    reduce_surfel_gradients(surfels, st, slots, out);
    return out;
}

template RasterImages<float> rasterize_forward_cpu(const Camera&, const SurfelBatch<float>&,
                                                   const RasterSettings<float>&, RasterState<float>&);
template RasterImages<double> rasterize_forward_cpu(const Camera&, const SurfelBatch<double>&,
                                                    const RasterSettings<double>&, RasterState<double>&);
template SurfelGrads<float> rasterize_backward_cpu(const SurfelBatch<float>&, const RasterState<float>&,
                                                   const RasterImageGrads<float>&);
template SurfelGrads<double> rasterize_backward_cpu(const SurfelBatch<double>&, const RasterState<double>&,
                                                    const RasterImageGrads<double>&);

}  // namespace lumigauss
