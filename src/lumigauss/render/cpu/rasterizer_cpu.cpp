#include "lumigauss/render/cpu/rasterizer_cpu.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss {
namespace {

using raster::kTileSize;
using raster::PixelRect;
using raster::ProjectedSurfel;
using raster::SplatGeometry;
using raster::SplatSample;

// Pixels of `rect` inside tile (tx, ty).
PixelRect clip_to_tile(const PixelRect& rect, int tx, int ty) {
    return {std::max(rect.x0, tx * kTileSize), std::max(rect.y0, ty * kTileSize),
            std::min(rect.x1, tx * kTileSize + kTileSize - 1),
            std::min(rect.y1, ty * kTileSize + kTileSize - 1)};
}

template <typename T>
SplatGeometry<T> splat_geometry(const ProjectedSurfel<T>& p, T opacity) {
    return {p.tu, p.tv, p.tw, p.center, opacity};
}

template <typename T>
T value_or_zero(const std::vector<T>& v, std::size_t i) {
    return v.empty() ? T(0) : v[i];
}

// --- Preprocess and binning -------------------------------------------------------------------------

template <typename T>
void project_all(const SurfelBatch<T>& surfels, RasterState<T>& st) {
    const std::size_t n = surfels.size();
    st.projected.resize(n);
    st.visible.assign(n, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const bool ok = surfels.opacities[i] > T(0) &&
                            raster::project_surfel(surfels.geometry(i), st.view, st.projected[i]);
            st.visible[i] = ok ? 1 : 0;
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

template <typename T>
void render_tile_forward(int tile, const SurfelBatch<T>& surfels, RasterState<T>& st, RasterImages<T>& img) {
    const int tx = tile % st.tiles_x, ty = tile / st.tiles_x;
    const int width = st.view.width, height = st.view.height, C = surfels.channels;
    const PixelRect tile_rect = {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize) - 1,
                                 std::min(height, (ty + 1) * kTileSize) - 1};
    std::vector<T>& trans = st.final_transmittance;
    for (int y = tile_rect.y0; y <= tile_rect.y1; ++y)
        for (int x = tile_rect.x0; x <= tile_rect.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            trans[pix] = T(1);
            st.contributors[pix] = 0;
            st.median_entry[pix] = -1;
            st.m1[pix] = st.m2[pix] = T(0);
        }
    const int tile_w = tile_rect.x1 - tile_rect.x0 + 1;
    int alive = tile_w * (tile_rect.y1 - tile_rect.y0 + 1);
    bool finished[kTileSize * kTileSize] = {};
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];

    for (std::uint32_t e = begin; e < end && alive > 0; ++e) {
        const std::uint32_t s = st.entry_surfel[e];
        const ProjectedSurfel<T>& ps = st.projected[s];
        const SplatGeometry<T> geo = splat_geometry(ps, surfels.opacities[s]);
        const T* color = &surfels.colors[std::size_t(s) * C];
        const PixelRect r = clip_to_tile(ps.rect, tx, ty);
        for (int y = r.y0; y <= r.y1; ++y) {
            for (int x = r.x0; x <= r.x1; ++x) {
                const std::size_t pix = std::size_t(y) * width + x;
                bool& done = finished[(y - tile_rect.y0) * tile_w + (x - tile_rect.x0)];
                if (done) continue;
                SplatSample<T> smp;
                if (!raster::evaluate_splat(geo, T(x) + T(0.5), T(y) + T(0.5), smp)) continue;
                const T t_before = trans[pix];
                const T t_after = t_before * (T(1) - smp.alpha);
                if (t_after < T(raster::kTransmittanceMin)) {
                    // This splat would make the pixel opaque: the pixel stops here without compositing it.
                    done = true;
                    --alive;
                    continue;
                }
                const T w = smp.alpha * t_before;
                for (int c = 0; c < C; ++c) img.color[pix * C + c] += w * color[c];
                img.depth[pix] += w * smp.z;
                for (int k = 0; k < 3; ++k) img.normal[pix * 3 + k] += w * ps.normal[k];
                const T m = raster::distortion_depth(smp.z);
                img.distortion[pix] += w * (m * m * (T(1) - t_before) + st.m2[pix] - T(2) * m * st.m1[pix]);
                st.m1[pix] += w * m;
                st.m2[pix] += w * m * m;
                if (t_before > T(0.5)) {
                    img.median_depth[pix] = smp.z;
                    st.median_entry[pix] = std::int32_t(e);
                }
                st.contributors[pix] = e - begin + 1;
                trans[pix] = t_after;
            }
        }
    }
    const std::vector<T>& bg = st.background;
    for (int y = tile_rect.y0; y <= tile_rect.y1; ++y)
        for (int x = tile_rect.x0; x <= tile_rect.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            const T t_final = trans[pix];
            img.alpha[pix] = T(1) - t_final;
            for (int c = 0; c < C; ++c) img.color[pix * C + c] += t_final * value_or_zero(bg, std::size_t(c));
        }
}

// --- Backward --------------------------------------------------------------------------------------

// Layout of one (surfel, tile) gradient slot.
struct SlotLayout {
    static constexpr int kTu = 0, kTv = 3, kTw = 6, kCenter = 9, kNormal = 11, kOpacity = 14, kColor = 15;
    static int stride(int channels) { return kColor + channels; }
};

// Per-pixel state of the back-to-front walk.
template <typename T>
struct PixelBackState {
    T trans;  // transmittance after the current splat
    T acc_z, acc_alpha, acc_dist;
    T acc_normal[3];
};

template <typename T>
void render_tile_backward(int tile, const SurfelBatch<T>& surfels, const RasterState<T>& st,
                          const RasterImageGrads<T>& g, std::vector<T>& slots) {
    const int tx = tile % st.tiles_x, ty = tile / st.tiles_x;
    const int width = st.view.width, height = st.view.height, C = surfels.channels;
    const int stride = SlotLayout::stride(C);
    const PixelRect tile_rect = {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize) - 1,
                                 std::min(height, (ty + 1) * kTileSize) - 1};
    const int tw = tile_rect.x1 - tile_rect.x0 + 1;
    const int th = tile_rect.y1 - tile_rect.y0 + 1;
    std::vector<PixelBackState<T>> px_state(std::size_t(tw) * th);
    std::vector<T> acc_color(std::size_t(tw) * th * C, T(0));
    std::vector<T> bg_term(std::size_t(tw) * th, T(0));  // T_final * (bg . dL/dC)
    for (int y = tile_rect.y0; y <= tile_rect.y1; ++y)
        for (int x = tile_rect.x0; x <= tile_rect.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            const std::size_t lp = std::size_t(y - tile_rect.y0) * tw + (x - tile_rect.x0);
            px_state[lp] = {st.final_transmittance[pix], T(0), T(0), T(0), {T(0), T(0), T(0)}};
            T dot_bg = 0;
            for (int c = 0; c < C; ++c)
                dot_bg += value_or_zero(st.background, std::size_t(c)) * value_or_zero(g.color, pix * C + c);
            bg_term[lp] = st.final_transmittance[pix] * dot_bg;
        }

    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    for (std::uint32_t e = end; e-- > begin;) {
        const std::uint32_t s = st.entry_surfel[e];
        const ProjectedSurfel<T>& ps = st.projected[s];
        const SplatGeometry<T> geo = splat_geometry(ps, surfels.opacities[s]);
        const T* color = &surfels.colors[std::size_t(s) * C];
        const PixelRect r = clip_to_tile(ps.rect, tx, ty);
        raster::ProjectedSurfelGrad<T> acc{};
        T g_opacity = 0;
        T* slot = &slots[std::size_t(e) * stride];
        T* g_color = slot + SlotLayout::kColor;
        for (int y = r.y0; y <= r.y1; ++y) {
            for (int x = r.x0; x <= r.x1; ++x) {
                const std::size_t pix = std::size_t(y) * width + x;
                if (e - begin >= st.contributors[pix]) continue;
                SplatSample<T> smp;
                const T px = T(x) + T(0.5), py = T(y) + T(0.5);
                if (!raster::evaluate_splat(geo, px, py, smp)) continue;
                const std::size_t lp = std::size_t(y - tile_rect.y0) * tw + (x - tile_rect.x0);
                PixelBackState<T>& ps_ = px_state[lp];
                T* acc_c = &acc_color[lp * C];
                const T one_minus_a = T(1) - smp.alpha;
                const T t_before = ps_.trans / one_minus_a;
                const T w = smp.alpha * t_before;

                // dL/dw-weighted terms (colour, normal) and dL/dalpha.
                T g_alpha_inner = 0;
                for (int c = 0; c < C; ++c) {
                    const T gc = value_or_zero(g.color, pix * C + c);
                    g_color[c] += w * gc;
                    g_alpha_inner += (color[c] - acc_c[c]) * gc;
                }
                for (int k = 0; k < 3; ++k) {
                    const T gn = value_or_zero(g.normal, pix * 3 + k);
                    acc.normal[k] += w * gn;
                    g_alpha_inner += (ps.normal[k] - ps_.acc_normal[k]) * gn;
                }
                const T g_depth = value_or_zero(g.depth, pix);
                const T g_alpha_map = value_or_zero(g.alpha, pix);
                const T g_dist = value_or_zero(g.distortion, pix);
                const T m = raster::distortion_depth(smp.z);
                const T a_total = T(1) - st.final_transmittance[pix];
                const T dist_w = (m * m * a_total + st.m2[pix] - T(2) * m * st.m1[pix]) * g_dist;  // dL/dw_i
                g_alpha_inner += (smp.z - ps_.acc_z) * g_depth + (T(1) - ps_.acc_alpha) * g_alpha_map +
                                 dist_w - ps_.acc_dist;
                const T g_alpha = t_before * g_alpha_inner - bg_term[lp] / one_minus_a;

                T g_z = w * g_depth;
                if (st.median_entry[pix] == std::int32_t(e)) g_z += value_or_zero(g.median_depth, pix);
                g_z += T(2) * w * (m * a_total - st.m1[pix]) * g_dist *
                       raster::distortion_depth_derivative(smp.z);

                raster::evaluate_splat_vjp(geo, px, py, smp, g_alpha, g_z, acc, g_opacity);

                // Fold this splat into the "behind" accumulators of the splat in front of it.
                for (int c = 0; c < C; ++c) acc_c[c] = smp.alpha * color[c] + one_minus_a * acc_c[c];
                for (int k = 0; k < 3; ++k)
                    ps_.acc_normal[k] = smp.alpha * ps.normal[k] + one_minus_a * ps_.acc_normal[k];
                ps_.acc_z = smp.alpha * smp.z + one_minus_a * ps_.acc_z;
                ps_.acc_alpha = smp.alpha + one_minus_a * ps_.acc_alpha;
                ps_.acc_dist = smp.alpha * dist_w + one_minus_a * ps_.acc_dist;
                ps_.trans = t_before;
            }
        }
        for (int k = 0; k < 3; ++k) {
            slot[SlotLayout::kTu + k] = acc.tu[k];
            slot[SlotLayout::kTv + k] = acc.tv[k];
            slot[SlotLayout::kTw + k] = acc.tw[k];
            slot[SlotLayout::kNormal + k] = acc.normal[k];
        }
        slot[SlotLayout::kCenter] = acc.center.x;
        slot[SlotLayout::kCenter + 1] = acc.center.y;
        slot[SlotLayout::kOpacity] = g_opacity;
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
            raster::ProjectedSurfelGrad<T> pg;
            for (int k = 0; k < 3; ++k) {
                pg.tu[k] = sum[SlotLayout::kTu + k];
                pg.tv[k] = sum[SlotLayout::kTv + k];
                pg.tw[k] = sum[SlotLayout::kTw + k];
                pg.normal[k] = sum[SlotLayout::kNormal + k];
            }
            pg.center = {sum[SlotLayout::kCenter], sum[SlotLayout::kCenter + 1]};
            const ProjectedSurfel<T>& ps = st.projected[i];
            // Screen-space gradient for densification: a translation by delta pixels adds delta * tw.z to
            // the third column of rows tu and tv. Like the reference, it leaves out the low-pass branch.
            out.mean2d[2 * i] = pg.tu.z * ps.tw.z;
            out.mean2d[2 * i + 1] = pg.tv.z * ps.tw.z;
            const auto gg = raster::project_surfel_vjp(surfels.geometry(i), st.view, ps, pg);
            for (int k = 0; k < 3; ++k) out.means[3 * i + k] = gg.mean[k];
            for (int k = 0; k < 4; ++k) out.quats[4 * i + k] = gg.quat[k];
            out.scales[2 * i] = gg.scale_u;
            out.scales[2 * i + 1] = gg.scale_v;
            out.opacities[i] = sum[SlotLayout::kOpacity];
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
    tbb::parallel_for(tbb::blocked_range<int>(0, num_tiles, 1), [&](const auto& r) {
        for (int t = r.begin(); t != r.end(); ++t) render_tile_backward(t, surfels, st, grads, slots);
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
