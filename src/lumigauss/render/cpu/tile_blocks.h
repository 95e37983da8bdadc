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
    std::vector<std::uint32_t> masks;  // per entry of the tile: the blocks it overlaps (block_mask)
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

// The blocks of a tile whose pixels a rectangle (clipped to the tile) covers, as a bit mask: bit
// 4 * by + bx is block (bx, by).
static_assert(kBlocksX == 4 && kTileBlocks == 32, "one bit per block of a 16x16 tile");
LG_HD_INLINE std::uint32_t block_mask(const raster::PixelRect& r, const raster::PixelRect& tile) {
    const unsigned bx0 = unsigned(std::max(r.x0, tile.x0) - tile.x0) / kBlockWidth;
    const unsigned by0 = unsigned(std::max(r.y0, tile.y0) - tile.y0) / kBlockHeight;
    const unsigned bx1 = unsigned(std::min(r.x1, tile.x1) - tile.x0) / kBlockWidth;
    const unsigned by1 = unsigned(std::min(r.y1, tile.y1) - tile.y0) / kBlockHeight;
    const std::uint32_t columns = (2u << bx1) - (1u << bx0);                           // bits bx0..bx1
    const std::uint32_t rows = (0x11111111u >> (4 * (7 - (by1 - by0)))) << (4 * by0);  // bit 4 by per row
    return rows * columns;  // no carries: columns < 16
}

// A counting sort of the tile's entries into its blocks (each entry's block mask computed once).
template <typename T>
LG_HD_INLINE void build_block_lists(const RasterState<T>& st, int tile, const raster::PixelRect& tr,
                                    BlockLists& lists) {
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    lists.masks.resize(end - begin);
    std::uint32_t count[kTileBlocks] = {};
    for (std::uint32_t e = begin; e < end; ++e) {
        const std::uint32_t mask = block_mask(st.entry_footprint[e].rect, tr);
        lists.masks[e - begin] = mask;
        for (std::uint32_t m = mask; m; m &= m - 1) ++count[__builtin_ctz(m)];
    }
    lists.start[0] = 0;
    for (int b = 0; b < kTileBlocks; ++b) lists.start[b + 1] = lists.start[b] + count[b];
    lists.items.resize(lists.start[kTileBlocks]);
    std::uint32_t cursor[kTileBlocks];
    std::copy_n(lists.start, kTileBlocks, cursor);
    for (std::uint32_t k = 0; k < end - begin; ++k)
        for (std::uint32_t m = lists.masks[k]; m; m &= m - 1) lists.items[cursor[__builtin_ctz(m)]++] = k;
}

}  // namespace lumigauss::cpu
