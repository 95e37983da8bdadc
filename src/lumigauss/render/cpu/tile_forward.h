#pragma once
// Forward blending of one 16x16 tile (internal to the CPU backend), block by block (tile_blocks.h): the
// eight pixels of a block keep their running sums in one pack per map (pixel_blend.h) while the block's
// surfels are evaluated on all eight at once (surfel_kernel.h) and blended, front to back, until every
// pixel of the block is finished. These functions are force-inlined into the per-instruction-set entry
// points of tile_kernels_forward.cpp, so each is compiled for baseline x86-64, AVX2 and AVX-512.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "lumigauss/render/cpu/lane_pack.h"
#include "lumigauss/render/cpu/raster_state.h"
#include "lumigauss/render/cpu/tile_blocks.h"
#include "lumigauss/render/pixel_blend.h"
#include "lumigauss/render/surfel_kernel.h"

#define LG_ALWAYS_INLINE __attribute__((always_inline)) inline

namespace lumigauss::cpu {

// The lanes whose pixels (px, py) lie in r.
template <typename T>
LG_ALWAYS_INLINE Mask8<T> lanes_in(const raster::PixelRect& r, Int8<T> px, Int8<T> py) {
    using I = typename Int8<T>::I;
    return (px >= Int8<T>(I(r.x0))) & (px <= Int8<T>(I(r.x1))) & (py >= Int8<T>(I(r.y0))) &
           (py <= Int8<T>(I(r.y1)));
}

// Writes a block's results into the images and what the backward needs into the state.
template <typename T, int C>
LG_ALWAYS_INLINE void store_block(const raster::BlendPixel<Pack8<T>, C>& s, int x0, int y0,
                                  const raster::PixelRect& tr, int channels, RasterState<T>& st,
                                  RasterImages<T>& img) {
    const int width = st.view.width;
    const std::vector<T>& bg = st.background;
    for (int i = 0; i < kLanes; ++i) {
        const int x = x0 + i % kBlockWidth, y = y0 + i / kBlockWidth;
        if (x > tr.x1 || y > tr.y1) continue;
        const std::size_t pix = std::size_t(y) * width + x;
        const T t_final = s.trans[i];
        st.final_transmittance[pix] = t_final;
        st.contributors[pix] = std::uint32_t(s.contributors[i]);
        st.median_entry[pix] = std::int32_t(s.median_entry[i]);
        st.m1[pix] = s.m1[i];
        st.m2[pix] = s.m2[i];
        img.alpha[pix] = T(1) - t_final;
        for (int c = 0; c < channels; ++c)
            img.color[pix * channels + c] = s.color[c][i] + t_final * (bg.empty() ? T(0) : bg[c]);
        img.depth[pix] = s.depth[i];
        for (int k = 0; k < 3; ++k) img.normal[pix * 3 + k] = s.normal[k][i];
        img.distortion[pix] = s.distortion[i];
        img.median_depth[pix] = s.median[i];
    }
}

// Entries per chunk of a block's forward loops (see render_tile_forward).
inline constexpr std::size_t kEvaluateChunk = 8;

template <typename T, int C>
LG_ALWAYS_INLINE void render_tile_forward(int tile, int channels, RasterState<T>& st, RasterImages<T>& img,
                                          TileScratch<T>& scratch) {
    using P = Pack8<T>;
    using I = Int8<T>;
    const raster::PixelRect tr = tile_pixels(tile, st.tiles_x, st.view.width, st.view.height);
    build_block_lists(st, tile, tr, scratch.lists);
    const std::uint32_t begin = st.tile_start[tile];
    // The entries each block composites, for the backward: at most every overlapping one.
    std::vector<std::uint32_t>& kept = st.block_entries[std::size_t(tile)];
    kept.resize(scratch.lists.total());
    std::uint32_t* const kept_start = &st.block_start[std::size_t(tile) * (kTileBlocks + 1)];
    std::uint32_t num_kept = 0;
    for (int b = 0; b < kTileBlocks; ++b) {
        kept_start[b] = num_kept;
        const int x0 = block_x0(tr, b), y0 = block_y0(tr, b);
        if (x0 > tr.x1 || y0 > tr.y1) continue;                                  // past the image's edge
        const I px = block_lane_x<T>() + I(x0), py = block_lane_y<T>() + I(y0);  // pixel indices
        const P cx = pixel_centres(px), cy = pixel_centres(py);
        raster::BlendPixel<P, C> s{};
        s.live = lanes_in(tr, px, py);
        s.trans = P(1);
        s.median_entry = I(-1);
        const std::span<const std::uint32_t> list = scratch.lists.block(b);
        if (list.empty()) {
            store_block(s, x0, y0, tr, channels, st, img);
            continue;
        }
        // Three loops over chunks of the block's list: the kernels' hits (up to rho), their exponentials
        // and alphas, then the blending. An entry's kernel (pixel -> hit -> rho -> exp -> alpha) is one
        // long chain of dependent operations, but no entry's depends on another's, and the blend's chain
        // from entry to entry is short. In one loop (even with the next entry's kernel evaluated while
        // this one was blended) an iteration filled the processor's reorder window, and the loop waited on
        // the chain; in loops of their own the halves of the kernel are short enough for the processor to
        // overlap several entries. The results go through L1 as plain arrays (packs held in an array of
        // packs were copied through general registers, in halves). A block that finishes inside a chunk
        // has evaluated the rest of the chunk for nothing. No lane tests the entry's pixel box: the kernel
        // reaches kAlphaMin only inside it (raster_forward_test: BoundingBoxHoldsEveryContributingPixel,
        // in double and in float), and the block lists hold only the blocks it overlaps. (The test was 5 %
        // of the forward's and the backward's instructions.)
        alignas(64) T chunk_alpha[kEvaluateChunk * kLanes], chunk_z[kEvaluateChunk * kLanes];
        bool finished = false;
        for (std::size_t chunk = 0; chunk < list.size() && !finished; chunk += kEvaluateChunk) {
            const std::size_t chunk_end = std::min(list.size(), chunk + kEvaluateChunk);
            for (std::size_t n = chunk; n < chunk_end; ++n) {
                if (n + kPrefetchAhead < list.size())
                    prefetch_entry(st, begin + list[n + kPrefetchAhead], channels);
                const std::uint32_t e = begin + list[n];
                raster::SplatSample<P> hit;  // only its depth is kept
                P rho;
                const auto reached = raster::splat_hit(st.entry_splat[e], cx, cy, hit, rho);
                store_pack(&chunk_alpha[(n - chunk) * kLanes], raster::splat_exponent(rho, reached));
                store_pack(&chunk_z[(n - chunk) * kLanes], hit.z);
            }
            for (std::size_t n = chunk; n < chunk_end; ++n) {
                const std::uint32_t e = begin + list[n];
                T* const alpha_at = &chunk_alpha[(n - chunk) * kLanes];
                raster::SplatSample<P> smp;
                const auto contributes =
                    raster::splat_alpha(st.entry_splat[e].opacity, load_pack(alpha_at), smp);
                store_pack(alpha_at, lane_select(contributes, smp.alpha, P(0)));
            }
            for (std::size_t n = chunk; n < chunk_end; ++n) {
                const std::uint32_t k = list[n];
                const std::uint32_t e = begin + k;
                const auto composited = raster::blend_sample(
                    s, load_pack(&chunk_alpha[(n - chunk) * kLanes]),
                    load_pack(&chunk_z[(n - chunk) * kLanes]), &st.entry_color[std::size_t(e) * channels],
                    channels, st.entry_footprint[e].normal, I(typename I::I(e)), I(typename I::I(k + 1)));
                const unsigned flags = any_of_each(composited, s.live);
                kept[num_kept] = k;
                num_kept += flags & 1;
                if (!(flags & 2)) {  // every pixel of the block is finished
                    finished = true;
                    break;
                }
            }
        }
        store_block(s, x0, y0, tr, channels, st, img);
    }
    kept_start[kTileBlocks] = num_kept;
    kept.resize(num_kept);
}

}  // namespace lumigauss::cpu
