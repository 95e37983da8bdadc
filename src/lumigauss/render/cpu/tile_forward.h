#pragma once
// Forward blending of one 16x16 tile (internal to the CPU backend).
//
// The tile's pixels keep their running sums in structure-of-arrays form; each surfel of the tile's
// front-to-back list is evaluated on whole tile rows (evaluate_splat_row), and blend_row composites a row in
// one branch-free loop over its 16 pixels, which the compiler vectorises. Pixels a surfel does not reach,
// and finished pixels, take part with weight 0. These functions are force-inlined into the per-instruction-
// set entry points of tile_kernels.cpp, so each is compiled for baseline x86-64, AVX2 and AVX-512.
#include <algorithm>
#include <cstdint>

#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/surfel_kernel.h"

#define LG_ALWAYS_INLINE __attribute__((always_inline)) inline

namespace lumigauss::cpu {

using raster::kTileSize;
inline constexpr int kTilePixels = kTileSize * kTileSize;

// Pixels of tile `tile` (inclusive bounds, clipped to the image).
inline raster::PixelRect tile_pixels(int tile, int tiles_x, int width, int height) {
    const int tx = tile % tiles_x, ty = tile / tiles_x;
    return {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize) - 1,
            std::min(height, (ty + 1) * kTileSize) - 1};
}

// The part of `rect` inside the tile whose pixels are `tile`.
inline raster::PixelRect clip_to_tile(const raster::PixelRect& rect, const raster::PixelRect& tile) {
    return {std::max(rect.x0, tile.x0), std::max(rect.y0, tile.y0), std::min(rect.x1, tile.x1),
            std::min(rect.y1, tile.y1)};
}

// The lanes a surfel's box needs in a tile row: an 8-pixel window when the box fits in one (most do), else
// the whole 16-pixel row. lo and hi are the box's first and last pixel relative to the window.
inline constexpr int kNarrow = 8;
struct LaneWindow {
    bool narrow;
    int first;  // first pixel of the window, relative to the tile
    int lo, hi;
};

inline LaneWindow lane_window(const raster::PixelRect& r, const raster::PixelRect& tile) {
    const int x0 = r.x0 - tile.x0, x1 = r.x1 - tile.x0;
    if (x1 - x0 < kNarrow) {
        const int first = std::min(x0, kTileSize - kNarrow);
        return {true, first, x0 - first, x1 - first};
    }
    return {false, 0, x0, x1};
}

template <typename T, int C>
struct TileForwardState {
    alignas(64) T live[kTilePixels];  // 1 while the pixel still blends; 0 once finished or off the image
    alignas(64) T trans[kTilePixels];
    alignas(64) T color[C][kTilePixels];
    alignas(64) T depth[kTilePixels];
    alignas(64) T normal[3][kTilePixels];
    alignas(64) T distortion[kTilePixels];
    alignas(64) T m1[kTilePixels];  // sum w m and sum w m^2 of the distortion map
    alignas(64) T m2[kTilePixels];
    alignas(64) T median[kTilePixels];
    alignas(64) std::int32_t median_entry[kTilePixels];
    alignas(64) std::int32_t contributors[kTilePixels];
};

// Blends one surfel into one tile row. `entry` is its index in the sorted list, `rank` its position in the
// tile's list plus one (what a pixel records as its contributor count).
template <int W, typename T, int C>
LG_ALWAYS_INLINE void blend_row(TileForwardState<T, C>& s, int row_offset, const raster::RowSamples<T>& row,
                                const T* color, int channels, Vec3<T> normal, std::int32_t entry,
                                std::int32_t rank) {
    T col[C];
    for (int c = 0; c < C; ++c) col[c] = c < channels ? color[c] : T(0);
#pragma omp simd
    for (int i = 0; i < W; ++i) {
        const int p = row_offset + i;
        const T a = row.alpha[i] * s.live[p];
        const T t = s.trans[p];
        const T t_next = t * (T(1) - a);
        // A splat that would take T below the threshold finishes the pixel without being composited.
        // (a == 0 leaves t_next = t, which is at or above the threshold.)
        const bool stop = t_next < T(raster::kTransmittanceMin);
        s.live[p] = stop ? T(0) : s.live[p];
        const T w = stop ? T(0) : a * t;
        for (int c = 0; c < C; ++c) s.color[c][p] += w * col[c];
        const T z = w > T(0) ? row.z[i] : T(1);  // z is arbitrary where the pair does not contribute
        s.depth[p] += w * z;
        for (int k = 0; k < 3; ++k) s.normal[k][p] += w * normal[k];
        const T m = raster::distortion_depth(z);
        s.distortion[p] += w * (m * m * (T(1) - t) + s.m2[p] - T(2) * m * s.m1[p]);
        s.m1[p] += w * m;
        s.m2[p] += w * m * m;
        const bool median = (w > T(0) ? t : T(0)) > T(0.5);
        s.median[p] = median ? z : s.median[p];
        s.median_entry[p] = median ? entry : s.median_entry[p];
        s.contributors[p] = w > T(0) ? rank : s.contributors[p];
        s.trans[p] = w > T(0) ? t_next : t;
    }
}

template <typename T, int C>
LG_ALWAYS_INLINE bool any_live(const TileForwardState<T, C>& s) {
    T sum = 0;
    for (int p = 0; p < kTilePixels; ++p) sum += s.live[p];
    return sum > T(0);
}

template <typename T, int C>
LG_ALWAYS_INLINE void render_tile_forward(int tile, int channels, RasterState<T>& st, RasterImages<T>& img) {
    const int width = st.view.width;
    const raster::PixelRect tr = tile_pixels(tile, st.tiles_x, width, st.view.height);
    TileForwardState<T, C> s;
    std::fill_n(&s.trans[0], kTilePixels, T(1));
    std::fill_n(&s.live[0], kTilePixels, T(0));
    std::fill_n(&s.color[0][0], C * kTilePixels, T(0));
    std::fill_n(&s.normal[0][0], 3 * kTilePixels, T(0));
    for (T* a : {s.depth, s.distortion, s.m1, s.m2, s.median}) std::fill_n(a, kTilePixels, T(0));
    std::fill_n(s.median_entry, kTilePixels, -1);
    std::fill_n(s.contributors, kTilePixels, 0);
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) s.live[(y - tr.y0) * kTileSize + (x - tr.x0)] = T(1);

    raster::RowSamples<T> row;
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    for (std::uint32_t e = begin; e < end; ++e) {
        // Finished tiles stop early; checking every few entries keeps the check off the hot path.
        if ((e - begin) % 8 == 7 && !any_live(s)) break;
        const raster::PixelRect r = clip_to_tile(st.entry_rect[e], tr);
        const T* color = &st.entry_color[std::size_t(e) * channels];
        const LaneWindow win = lane_window(r, tr);
        for (int y = r.y0; y <= r.y1; ++y) {
            const T px0 = T(tr.x0 + win.first) + T(0.5), py = T(y) + T(0.5);
            const int offset = (y - tr.y0) * kTileSize + win.first;
            const auto rank = std::int32_t(e - begin + 1);
            if (win.narrow) {
                raster::evaluate_splat_row<kNarrow>(st.entry_splat[e], px0, py, win.lo, win.hi, row);
                blend_row<kNarrow>(s, offset, row, color, channels, st.entry_normal[e], std::int32_t(e),
                                   rank);
            } else {
                raster::evaluate_splat_row<kTileSize>(st.entry_splat[e], px0, py, win.lo, win.hi, row);
                blend_row<kTileSize>(s, offset, row, color, channels, st.entry_normal[e], std::int32_t(e),
                                     rank);
            }
        }
    }

    const std::vector<T>& bg = st.background;
    for (int y = tr.y0; y <= tr.y1; ++y)
        for (int x = tr.x0; x <= tr.x1; ++x) {
            const int p = (y - tr.y0) * kTileSize + (x - tr.x0);
            const std::size_t pix = std::size_t(y) * width + x;
            const T t_final = s.trans[p];
            st.final_transmittance[pix] = t_final;
            st.contributors[pix] = std::uint32_t(s.contributors[p]);
            st.median_entry[pix] = s.median_entry[p];
            st.m1[pix] = s.m1[p];
            st.m2[pix] = s.m2[p];
            img.alpha[pix] = T(1) - t_final;
            for (int c = 0; c < channels; ++c)
                img.color[pix * channels + c] = s.color[c][p] + t_final * (bg.empty() ? T(0) : bg[c]);
            img.depth[pix] = s.depth[p];
            for (int k = 0; k < 3; ++k) img.normal[pix * 3 + k] = s.normal[k][p];
            img.distortion[pix] = s.distortion[p];
            img.median_depth[pix] = s.median[p];
        }
}

}  // namespace lumigauss::cpu
