#pragma once
// A 16x16 tile as 32 blocks of 4 x 2 pixels (internal to the CPU backend).
//
// One block is one pack of eight lanes (lane_pack.h). The tile kernels walk each block on its own: its
// pixels' running sums stay in registers while the block's own list of surfels streams past, instead of
// each surfel being blended into tile-sized arrays in memory. A block stops as soon as all its pixels are
// finished, and it visits only the surfels whose boxes overlap it: 4 x 2 blocks fit the small, roughly
// round boxes of trained scenes better than tile rows do (on the benchmark scene, 10 % fewer lanes at
// 200k surfels, 34 % fewer at 1M, where early stopping per block pays).
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/math/hd.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss::cpu {

using raster::kTileSize;
inline constexpr int kBlockWidth = 4, kBlockHeight = 2;
inline constexpr int kBlocksX = kTileSize / kBlockWidth, kBlocksY = kTileSize / kBlockHeight;
inline constexpr int kTileBlocks = kBlocksX * kBlocksY;

// Pixels of tile `tile` (inclusive bounds, clipped to the image).
inline raster::PixelRect tile_pixels(int tile, int tiles_x, int width, int height) {
    const int tx = tile % tiles_x, ty = tile / tiles_x;
    return {tx * kTileSize, ty * kTileSize, std::min(width, (tx + 1) * kTileSize) - 1,
            std::min(height, (ty + 1) * kTileSize) - 1};
}

// First pixel of block b of the tile whose first pixel is (tile.x0, tile.y0).
inline int block_x0(const raster::PixelRect& tile, int b) {
    return tile.x0 + (b % kBlocksX) * kBlockWidth;
}
inline int block_y0(const raster::PixelRect& tile, int b) {
    return tile.y0 + (b / kBlocksX) * kBlockHeight;
}

// Per block of one tile: the tile's entries (as indices from the tile's first entry) whose boxes overlap
// the block, front to back.
struct BlockLists {
    std::uint32_t start[kTileBlocks + 1] = {};
    std::vector<std::uint32_t> items;
    std::span<const std::uint32_t> block(int b) const {
        return {items.data() + start[b], items.data() + start[b + 1]};
    }
};

// Scratch memory of one thread's tiles, reused from tile to tile.
template <typename T>
struct TileScratch {
    BlockLists lists;      // forward: every entry overlapping each block
    std::vector<T> grads;  // backward: per entry of the tile, its gradient sums
};

// A block's loop does too much work per entry for the processor to run ahead to the next entry's loads on
// its own (the next iteration does not fit in its reorder window), so each iteration first asks for the
// data of the entry kPrefetchAhead places further down its list.
inline constexpr std::size_t kPrefetchAhead = 2;
template <typename T>
LG_HD_INLINE void prefetch_entry(const RasterState<T>& st, std::uint32_t e, int channels) {
    __builtin_prefetch(&st.entry_splat[e]);
    __builtin_prefetch(&st.entry_footprint[e]);
    __builtin_prefetch(&st.entry_color[std::size_t(e) * channels]);
}

template <typename T>
void build_block_lists(const RasterState<T>& st, int tile, const raster::PixelRect& tr, BlockLists& lists) {
    struct Span {
        int bx0, by0, bx1, by1;
    };
    const auto span_of = [&](const raster::PixelRect& r) {
        return Span{
            (std::max(r.x0, tr.x0) - tr.x0) / kBlockWidth, (std::max(r.y0, tr.y0) - tr.y0) / kBlockHeight,
            (std::min(r.x1, tr.x1) - tr.x0) / kBlockWidth, (std::min(r.y1, tr.y1) - tr.y0) / kBlockHeight};
    };
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    std::uint32_t count[kTileBlocks] = {};
    for (std::uint32_t e = begin; e < end; ++e) {
        const Span s = span_of(st.entry_footprint[e].rect);
        for (int by = s.by0; by <= s.by1; ++by)
            for (int bx = s.bx0; bx <= s.bx1; ++bx) ++count[by * kBlocksX + bx];
    }
    lists.start[0] = 0;
    for (int b = 0; b < kTileBlocks; ++b) lists.start[b + 1] = lists.start[b] + count[b];
    lists.items.resize(lists.start[kTileBlocks]);
    std::uint32_t cursor[kTileBlocks];
    std::copy_n(lists.start, kTileBlocks, cursor);
    for (std::uint32_t e = begin; e < end; ++e) {
        const Span s = span_of(st.entry_footprint[e].rect);
        for (int by = s.by0; by <= s.by1; ++by)
            for (int bx = s.bx0; bx <= s.bx1; ++bx) lists.items[cursor[by * kBlocksX + bx]++] = e - begin;
    }
}

}  // namespace lumigauss::cpu
