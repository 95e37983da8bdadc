#pragma once
// Backward of one 16x16 tile (internal to the CPU backend): the tile's list walked back to front, each
// surfel evaluated on whole tile rows, and backward_row's per-pixel work done in one branch-free loop over
// the row's 16 pixels. Gradients of the surfel are summed per lane (which vectorises without reordering
// float sums across lanes) and reduced once per surfel into its (surfel, tile) slot.
//
// Rows in which the forward composited no pixel of the surfel are skipped (about 30 % of the rows of the
// 200k-surfel benchmark): with alpha = 0 a row leaves the "behind" blends and the transmittance exactly as
// they are and adds nothing to the gradients. The per-lane sums are not cleared per (surfel, tile) pair
// (1.3 KB of stores, a `rep stos`, for every pair); the first row that does composite assigns them.
#include <cstdint>

#include "lumigauss/render/cpu/tile_forward.h"

namespace lumigauss::cpu {

// Layout of one (surfel, tile) gradient slot, in the kernel's variables (surfel_kernel.h).
struct SlotLayout {
    static constexpr int kPa = 0, kPb = 3, kPd = 6, kTw = 9, kCenter = 12, kNormal = 14, kOpacity = 17,
                         kColor = 18;
    static int stride(int channels) { return kColor + channels; }
};

// Per-pixel state of the back-to-front walk, and the pixel's incoming gradients (zero where a map has none).
template <typename T, int C>
struct TileBackwardState {
    alignas(64) T trans[kTilePixels];  // transmittance behind the splat being processed (T_final at first)
    alignas(64) T acc_color[C][kTilePixels];  // blends of the splats behind
    alignas(64) T acc_normal[3][kTilePixels];
    alignas(64) T acc_z[kTilePixels];
    alignas(64) T acc_alpha[kTilePixels];
    alignas(64) T acc_dist[kTilePixels];
    alignas(64) T g_color[C][kTilePixels];
    alignas(64) T g_normal[3][kTilePixels];
    alignas(64) T g_depth[kTilePixels];
    alignas(64) T g_alpha[kTilePixels];
    alignas(64) T g_dist[kTilePixels];
    alignas(64) T g_median[kTilePixels];
    alignas(64) T bg_term[kTilePixels];  // T_final * (background . dL/dcolor)
    alignas(64) T a_total[kTilePixels];  // 1 - T_final
    alignas(64) T m1[kTilePixels];
    alignas(64) T m2[kTilePixels];
    alignas(64) std::int32_t contributors[kTilePixels];
    alignas(64) std::int32_t median_entry[kTilePixels];
};

// One surfel's gradients, summed per lane of the tile row.
template <typename T, int C>
struct LaneGrads {
    alignas(64) T pa[3][kTileSize], pb[3][kTileSize], pd[3][kTileSize], tw[3][kTileSize];
    alignas(64) T center[2][kTileSize];
    alignas(64) T opacity[kTileSize];
    alignas(64) T normal[3][kTileSize];
    alignas(64) T color[C][kTileSize];
};

// Rows where no lane composited leave everything unchanged (see the top of the file).
template <int W, typename T, int C>
LG_ALWAYS_INLINE bool any_composited(const TileBackwardState<T, C>& s, int row_offset,
                                     const raster::RowSamples<T>& row, std::int32_t rank) {
    int any = 0;  // an integer OR: GCC vectorises it (a float sum would need reassociation)
    for (int i = 0; i < W; ++i) any |= int(rank <= s.contributors[row_offset + i]) & int(row.alpha[i] > T(0));
    return any != 0;
}

// kFirst: the surfel's first composited row in this tile, which assigns the per-lane sums instead of adding.
template <int W, bool kFirst, typename T, int C>
LG_ALWAYS_INLINE void backward_row(TileBackwardState<T, C>& s, LaneGrads<T, C>& lg, int row_offset,
                                   const raster::RowSamples<T>& row, const raster::SplatGeometry<T>& geometry,
                                   T px0, T py, const T* color, int channels, Vec3<T> normal,
                                   std::int32_t entry, std::int32_t rank) {
    const raster::SplatGeometry<T> g = geometry;
    T col[C];
    for (int c = 0; c < C; ++c) col[c] = c < channels ? color[c] : T(0);
    const auto add = [](T& sum, T value) { sum = kFirst ? value : sum + value; };
#pragma omp simd
    for (int i = 0; i < W; ++i) {
        const int p = row_offset + i;
        // Only pairs the forward composited: inside the pixel's contributor range, alpha above threshold.
        const T a = rank <= s.contributors[p] ? row.alpha[i] : T(0);
        const T one_minus_a = T(1) - a;
        const T t_before = s.trans[p] / one_minus_a;
        const T w = a * t_before;

        // dL/dalpha: this splat's value against the blend of those behind it, for every map.
        T g_alpha_inner = 0;
        for (int c = 0; c < C; ++c) {
            add(lg.color[c][i], w * s.g_color[c][p]);
            g_alpha_inner += (col[c] - s.acc_color[c][p]) * s.g_color[c][p];
        }
        for (int k = 0; k < 3; ++k) {
            add(lg.normal[k][i], w * s.g_normal[k][p]);
            g_alpha_inner += (normal[k] - s.acc_normal[k][p]) * s.g_normal[k][p];
        }
        const T z = a > T(0) ? row.z[i] : T(1);
        const T m = raster::distortion_depth(z);
        const T dist_w = (m * m * s.a_total[p] + s.m2[p] - T(2) * m * s.m1[p]) * s.g_dist[p];  // dL/dw
        g_alpha_inner +=
            (z - s.acc_z[p]) * s.g_depth[p] + (T(1) - s.acc_alpha[p]) * s.g_alpha[p] + dist_w - s.acc_dist[p];
        const T g_a = a > T(0) ? t_before * g_alpha_inner - s.bg_term[p] / one_minus_a : T(0);
        const T g_z =
            w * s.g_depth[p] + (s.median_entry[p] == entry ? s.g_median[p] : T(0)) +
            T(2) * w * (m * s.a_total[p] - s.m1[p]) * s.g_dist[p] * raster::distortion_depth_derivative(z);

        const raster::SplatGradTerms<T> t = raster::splat_grad_terms(
            g, px0 + T(i), py, row.u[i], row.v[i], row.gauss[i], row.screen[i] != T(0),
            row.clamped[i] != T(0), g_a, a > T(0) ? g_z : T(0));
        for (int k = 0; k < 3; ++k) {
            add(lg.pa[k][i], t.dx * t.g_p[k]);
            add(lg.pb[k][i], t.dy * t.g_p[k]);
            add(lg.pd[k][i], t.g_p[k]);
            add(lg.tw[k][i], t.g_tw[k]);
        }
        add(lg.center[0][i], t.g_center.x);
        add(lg.center[1][i], t.g_center.y);
        add(lg.opacity[i], t.g_opacity);

        // Fold this splat into the "behind" blends of the splat in front of it (a == 0 changes nothing).
        for (int c = 0; c < C; ++c) s.acc_color[c][p] = a * col[c] + one_minus_a * s.acc_color[c][p];
        for (int k = 0; k < 3; ++k) s.acc_normal[k][p] = a * normal[k] + one_minus_a * s.acc_normal[k][p];
        s.acc_z[p] = a * z + one_minus_a * s.acc_z[p];
        s.acc_alpha[p] = a + one_minus_a * s.acc_alpha[p];
        s.acc_dist[p] = a * dist_w + one_minus_a * s.acc_dist[p];
        s.trans[p] = t_before;
    }
}

template <typename T>
T grad_at(const std::vector<T>& g, std::size_t i) {
    return g.empty() ? T(0) : g[i];
}

template <typename T, int C>
LG_ALWAYS_INLINE void load_tile_backward_state(TileBackwardState<T, C>& s, const raster::PixelRect& tr,
                                               int channels, const RasterState<T>& st,
                                               const RasterImageGrads<T>& g, std::uint32_t& last_rank) {
    std::fill_n(&s.acc_color[0][0], C * kTilePixels, T(0));
    std::fill_n(&s.acc_normal[0][0], 3 * kTilePixels, T(0));
    std::fill_n(&s.g_color[0][0], C * kTilePixels, T(0));
    std::fill_n(&s.g_normal[0][0], 3 * kTilePixels, T(0));
    for (T* a : {s.trans, s.acc_z, s.acc_alpha, s.acc_dist, s.g_depth, s.g_alpha, s.g_dist, s.g_median,
                 s.bg_term, s.a_total, s.m1, s.m2})
        std::fill_n(a, kTilePixels, T(0));
    std::fill_n(s.contributors, kTilePixels, 0);
    std::fill_n(s.median_entry, kTilePixels, -1);
    last_rank = 0;
    const int width = st.view.width;
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) {
            const std::size_t pix = std::size_t(y) * width + x;
            const int p = (y - tr.y0) * kTileSize + (x - tr.x0);
            s.trans[p] = st.final_transmittance[pix];
            s.a_total[p] = T(1) - s.trans[p];
            T dot_bg = 0;
            for (int c = 0; c < channels; ++c) {
                s.g_color[c][p] = grad_at(g.color, pix * channels + c);
                dot_bg += (st.background.empty() ? T(0) : st.background[c]) * s.g_color[c][p];
            }
            s.bg_term[p] = s.trans[p] * dot_bg;
            for (int k = 0; k < 3; ++k) s.g_normal[k][p] = grad_at(g.normal, pix * 3 + k);
            s.g_depth[p] = grad_at(g.depth, pix);
            s.g_alpha[p] = grad_at(g.alpha, pix);
            s.g_dist[p] = grad_at(g.distortion, pix);
            s.g_median[p] = grad_at(g.median_depth, pix);
            s.m1[p] = st.m1[pix];
            s.m2[p] = st.m2[pix];
            s.contributors[p] = std::int32_t(st.contributors[pix]);
            s.median_entry[p] = st.median_entry[pix];
            last_rank = std::max(last_rank, st.contributors[pix]);
        }
}

// Sums the first W lanes of each accumulator into the slot (8 lanes hold everything for narrow windows).
template <int W, typename T, int C>
LG_ALWAYS_INLINE void store_slot(const LaneGrads<T, C>& lg, int channels, T* slot) {
    const auto lane_sum = [](const T* v) {
        T sum = 0;
        for (int i = 0; i < W; ++i) sum += v[i];
        return sum;
    };
    for (int k = 0; k < 3; ++k) {
        slot[SlotLayout::kPa + k] = lane_sum(lg.pa[k]);
        slot[SlotLayout::kPb + k] = lane_sum(lg.pb[k]);
        slot[SlotLayout::kPd + k] = lane_sum(lg.pd[k]);
        slot[SlotLayout::kTw + k] = lane_sum(lg.tw[k]);
        slot[SlotLayout::kNormal + k] = lane_sum(lg.normal[k]);
    }
    slot[SlotLayout::kCenter] = lane_sum(lg.center[0]);
    slot[SlotLayout::kCenter + 1] = lane_sum(lg.center[1]);
    slot[SlotLayout::kOpacity] = lane_sum(lg.opacity);
    for (int c = 0; c < channels; ++c) slot[SlotLayout::kColor + c] = lane_sum(lg.color[c]);
}

// What backward_entry needs of one sorted entry.
template <typename T>
struct EntryArgs {
    const raster::SplatGeometry<T>& geometry;
    const T* color;
    Vec3<T> normal;
    std::int32_t entry;  // index in the sorted list
    std::int32_t rank;   // position in the tile's list plus one (compared with the contributor counts)
};

// One (surfel, tile) pair: its rows in the tile state, its gradients into its slot. All rows are evaluated
// first and those with a composited pixel listed; the backward then runs on the listed rows, the first of
// which assigns the per-lane sums. Beware: GCC's vectorisation of backward_row is fragile. A `continue`
// next to the call, for example, made it sink tile-state loads into branches it then could not prove safe to
// if-convert, and the pixel loop silently went scalar (2.3x slower); check with -fopt-info-vec after edits.
template <int W, typename T, int C>
LG_ALWAYS_INLINE void backward_entry(TileBackwardState<T, C>& s, LaneGrads<T, C>& lg,
                                     raster::RowSamples<T>* rows, const raster::PixelRect& tr,
                                     const raster::PixelRect& r, const LaneWindow& win, const EntryArgs<T>& a,
                                     int channels, T* slot) {
    int live[kTileSize], num_live = 0;  // rows with a composited pixel, top to bottom
    for (int y = r.y0; y <= r.y1; ++y) {
        const T px0 = T(tr.x0 + win.first) + T(0.5), py = T(y) + T(0.5);
        const int offset = (y - tr.y0) * kTileSize + win.first;
        raster::evaluate_splat_row<W>(a.geometry, px0, py, win.lo, win.hi, rows[y - r.y0]);
        live[num_live] = y;
        num_live += any_composited<W>(s, offset, rows[y - r.y0], a.rank) ? 1 : 0;
    }
    if (num_live == 0) {
        std::fill_n(slot, SlotLayout::stride(channels), T(0));
        return;
    }
    // Top to bottom, the order in which the per-lane sums were always formed.
    const T px0 = T(tr.x0 + win.first) + T(0.5);
    const auto row_at = [&](int y) -> const raster::RowSamples<T>& { return rows[y - r.y0]; };
    const auto offset_of = [&](int y) { return (y - tr.y0) * kTileSize + win.first; };
    backward_row<W, true>(s, lg, offset_of(live[0]), row_at(live[0]), a.geometry, px0, T(live[0]) + T(0.5),
                          a.color, channels, a.normal, a.entry, a.rank);
    for (int k = 1; k < num_live; ++k)
        backward_row<W, false>(s, lg, offset_of(live[k]), row_at(live[k]), a.geometry, px0,
                               T(live[k]) + T(0.5), a.color, channels, a.normal, a.entry, a.rank);
    store_slot<W>(lg, channels, slot);
}

template <typename T, int C>
LG_ALWAYS_INLINE void render_tile_backward(int tile, int channels, const RasterState<T>& st,
                                           const RasterImageGrads<T>& g, T* slots) {
    const int stride = SlotLayout::stride(channels);
    const raster::PixelRect tr = tile_pixels(tile, st.tiles_x, st.view.width, st.view.height);
    TileBackwardState<T, C> s;
    std::uint32_t last_rank = 0;  // entries past the largest contributor count touch no pixel
    load_tile_backward_state(s, tr, channels, st, g, last_rank);

    raster::RowSamples<T> rows[kTileSize];  // one per row of a surfel's box in the tile
    LaneGrads<T, C> lg;
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    // Slots are indexed by emission (contiguous per surfel) so the per-surfel reduction streams.
    for (std::uint32_t e = begin + last_rank; e < end; ++e)  // never visited: zero slots
        std::fill_n(&slots[std::size_t(st.entry_emission[e]) * stride], stride, T(0));
    for (std::uint32_t e = begin + last_rank; e-- > begin;) {
        const raster::PixelRect r = clip_to_tile(st.entry_rect[e], tr);
        const LaneWindow win = lane_window(r, tr);
        T* slot = &slots[std::size_t(st.entry_emission[e]) * stride];
        const EntryArgs<T> args{st.entry_splat[e], &st.entry_color[std::size_t(e) * channels],
                                st.entry_normal[e], std::int32_t(e), std::int32_t(e - begin + 1)};
        if (win.narrow)
            backward_entry<kNarrow>(s, lg, rows, tr, r, win, args, channels, slot);
        else
            backward_entry<kTileSize>(s, lg, rows, tr, r, win, args, channels, slot);
    }
}

}  // namespace lumigauss::cpu
