#pragma once
// A 16x16 tile as 32 blocks of 4 x 2 pixels (internal to the CPU backend).
//
// One block is one pack of eight lanes (lane_pack.h). The tile kernels walk each block on its own: its
// pixels' running sums stay in registers while the block's own list of surfels streams past, instead of
// each surfel being blended into tile-sized arrays in memory. A block stops as soon as all its pixels are
// finished, and it visits only the surfels that can reach one of its pixels (their boxes overlap it, and
// their exact reachable region too: splat_reach.h): 4 x 2 blocks fit the small, roughly round splats of
// trained scenes better than tile rows do (on the benchmark scene, 10 % fewer lanes at 200k surfels, 34 %
// fewer at 1M, where early stopping per block pays).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include "lumigauss/math/hd.h"
#include "lumigauss/render/cpu/bit_transpose.h"
#include "lumigauss/render/cpu/vector_shuffle.h"
#include "lumigauss/render/cpu/lane_pack.h"
#include "lumigauss/render/cpu/raster_state.h"
#include "lumigauss/render/splat_reach.h"

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

// Per block of one tile: the tile's entries (as indices from the tile's first entry) that may reach
// the block, front to back. Each block's list has room for every entry of the tile, so that the lists are
// filled in one pass over the entries (a counting sort took two, and its counters were chained through
// memory twice), and for one group of eight more (build_block_lists stores eight at a time). That is
// about 128 bytes of address space per entry of the tile, left uninitialised: only the filled part of
// each list is ever touched, so the memory used stays that of the items themselves.
struct BlockLists {
    std::uint32_t size[kTileBlocks] = {};
    std::size_t capacity = 0;  // per block: the tile's entries + kLanes
    std::unique_ptr<std::uint32_t[]> items;
    std::size_t allocated = 0;

    std::span<const std::uint32_t> block(int b) const { return {items.get() + b * capacity, size[b]}; }
    std::size_t total() const {
        std::size_t n = 0;
        for (std::uint32_t s : size) n += s;
        return n;
    }
    // Room for `entries` per block. The previous lists are not kept.
    std::uint32_t* reserve(std::size_t entries) {
        capacity = entries + kLanes;
        if (allocated < kTileBlocks * capacity) {
            allocated = kTileBlocks * capacity;
            items.reset(new std::uint32_t[allocated]);  // default-initialised: no pages touched here
        }
        return items.get();
    }
};

// Scratch memory of one thread's tiles, reused from tile to tile.
template <typename T>
struct TileScratch {
    BlockLists lists;      // forward: every entry that may reach each block
    std::vector<T> grads;  // backward: per entry of the tile, its gradient sums
};

// The block loops that read an entry's geometry first ask for the data of the entry kPrefetchAhead places
// further down the list: the processor would not run ahead to those loads by itself early enough. (Six,
// since the kernel loops' iterations are short; 2 and 6 measured alike, 6 by 2-5 % ahead in the backward.)
inline constexpr std::size_t kPrefetchAhead = 6;
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

// The blocks of a tile whose pixel centres the splat's exact reachable region (splat_reach.h) may touch:
// the eight block rows of the tile at once, one per lane. Only for a definite region (reach.definite).
template <typename T>
LG_HD_INLINE std::uint32_t reach_block_mask(const raster::SplatReach<T>& reach, Vec2<T> centre,
                                            const raster::PixelRect& tile) {
    static_assert(kBlocksY == kLanes, "one lane per block row");
    using P = Pack8<T>;
    using IV = typename Int8<T>::V;
    const IV rows{0, 1, 2, 3, 4, 5, 6, 7};
    // Offsets of each row pair's pixel centres from the splat's filter centre.
    const P dy0 = P(T(tile.y0) + T(0.5) - centre.y) +
                  P{__builtin_convertvector(rows, typename P::V)} * P(T(kBlockHeight));
    const P dy1 = dy0 + P(T(kBlockHeight - 1));
    P lo, hi;
    const auto reached = raster::reach_in_band(reach, dy0, dy1, lo, hi);
    // Pixels x whose centres x + 0.5 lie in [centre.x + lo, centre.x + hi], clamped near the tile first so
    // that the conversions to integers cannot overflow: first = ceil, last = floor.
    const P x_min(T(tile.x0 - 1)), x_max(T(tile.x1 + 1));
    const P a = lane_min(lane_max(P(centre.x - T(0.5)) + lo, x_min), x_max);
    const P b = lane_min(lane_max(P(centre.x - T(0.5)) + hi, x_min), x_max);
    const IV a_trunc = __builtin_convertvector(a.v, IV), b_trunc = __builtin_convertvector(b.v, IV);
    IV first = a_trunc - (__builtin_convertvector(a_trunc, typename P::V) < a.v);  // a true compare is -1
    IV last = b_trunc + (__builtin_convertvector(b_trunc, typename P::V) > b.v);
    first = first < IV{} + tile.x0 ? IV{} + tile.x0 : first;
    last = last > IV{} + tile.x1 ? IV{} + tile.x1 : last;
    const IV valid = reached.v & (first <= last) & (rows * kBlockHeight + tile.y0 <= IV{} + tile.y1);
    // Block columns, clamped to 0..3 so that the shifts stay in range where the row is not valid.
    IV c0 = (first - tile.x0) / kBlockWidth, c1 = (last - tile.x0) / kBlockWidth;
    c0 = c0 < 0 ? IV{} : (c0 > kBlocksX - 1 ? IV{} + (kBlocksX - 1) : c0);
    c1 = c1 < 0 ? IV{} : (c1 > kBlocksX - 1 ? IV{} + (kBlocksX - 1) : c1);
    const IV bits = (((IV{} + 2) << c1) - ((IV{} + 1) << c0)) << (rows * kBlocksX);
    const IV row_masks = valid ? bits : IV{};
    std::uint32_t mask = 0;
    for (int i = 0; i < kLanes; ++i) mask |= std::uint32_t(row_masks[i]);
    return mask;
}

// Entries whose bounding box spans more blocks of a tile than this have their exact reachable region
// checked block by block (build_block_lists). For smaller ones the check (~100 instructions per entry)
// costs more than the few blocks it could drop, each of which takes a block loop a few tens of cycles.
// Forward tiles with 2 here / with 8 (bench/raster_bench, 1 thread, fastest of 3-6 rounds): 25.2 / 23.5 ms
// at 200k surfels, 72.2 / 56.2 ms at 1M (small splats), 184 / 172 ms at 1280x720; the trained demo
// model's forward (bench/train_bench) did not change beyond noise.
inline constexpr int kRefineAboveBlocks = 8;

// Appends a group of eight consecutive entries, k0 + l in lane l (masks[l]: the blocks it reaches, 0 for
// none), to the lists of the blocks they reach. Per block, one store of eight indices: the group's
// entries reaching the block, in order, then whatever positions fill the rest (the next store overwrites
// them; the list's size counts only the first). An entry at a time, each set bit of its mask one append,
// was a loop whose length the branch predictor could not guess and whose counters were chained through
// memory: a tenth of the forward's tiles.
LG_HD_INLINE void append_group(const std::uint32_t (&masks)[kLanes], std::uint32_t k0, std::uint32_t* items,
                               std::size_t capacity, std::uint32_t* size) {
    using Bytes = unsigned char __attribute__((vector_size(32)));
    using Indices = std::uint32_t __attribute__((vector_size(32)));
    static_assert(sizeof(masks) == sizeof(Bytes) && std::endian::native == std::endian::little);
    // reaching[b], bit l: entry l reaches block b. The masks' bytes regrouped so that each 64-bit word
    // holds one byte of every mask, then each word's 8x8 bit matrix transposed.
    Bytes mask_bytes;
    std::memcpy(&mask_bytes, masks, sizeof(mask_bytes));
    const Bytes by_word =
        LG_SHUFFLE(mask_bytes, Bytes{0, 4, 8,  12, 16, 20, 24, 28, 1, 5, 9,  13, 17, 21, 25, 29,
                                            2, 6, 10, 14, 18, 22, 26, 30, 3, 7, 11, 15, 19, 23, 27, 31});
    std::uint64_t words[kTileBlocks / 8];
    std::memcpy(words, &by_word, sizeof(words));
    for (std::uint64_t& word : words) word = transpose_bits_8x8(word);
    unsigned char reaching[kTileBlocks];  // little-endian words: byte b is block b
    std::memcpy(reaching, words, sizeof(reaching));
    const Indices kNibbles{0, 4, 8, 12, 16, 20, 24, 28};
    std::uint32_t blocks = 0;
    for (std::uint32_t m : masks) blocks |= m;
    for (; blocks; blocks &= blocks - 1) {
        const int b = std::countr_zero(blocks);
        const unsigned entries = reaching[b];
        const Indices positions = (Indices{} + kSetBitPositions[entries]) >> kNibbles & 0xfu;
        const Indices k = positions + k0;
        std::memcpy(&items[std::size_t(b) * capacity + size[b]], &k, sizeof(k));
        size[b] += std::uint32_t(std::popcount(entries));
    }
}

// Sorts the tile's entries into its blocks' lists, in one pass (each entry's block mask computed once). An
// entry spanning more than kRefineAboveBlocks blocks keeps only those its exact reachable region touches:
// for thin, tilted splats most of the blocks of its bounding box.
template <typename T>
LG_HD_INLINE void build_block_lists(const RasterState<T>& st, int tile, const raster::PixelRect& tr,
                                    BlockLists& lists) {
    const std::uint32_t begin = st.tile_start[tile], end = st.tile_start[tile + 1];
    std::uint32_t* const items = lists.reserve(end - begin);
    // Counted here and copied into lists.size at the end: stores through `items` could alias the
    // member array, which would make the compiler reload a counter after every store.
    std::uint32_t size[kTileBlocks] = {};
    // Eight entries at a time: their reachable regions are set up in one pack, one entry per lane.
    using P = Pack8<T>;
    for (std::uint32_t first = begin; first < end; first += kLanes) {
        std::uint32_t masks[kLanes];
        bool refine = false;
        for (int l = 0; l < kLanes; ++l) {
            const std::uint32_t e = std::min(first + std::uint32_t(l), end - 1);
            masks[l] = block_mask(st.entry_footprint[e].rect, tr);
            refine = refine || std::popcount(masks[l]) > kRefineAboveBlocks;
        }
        if (refine) {
            // The lanes are gathered in plain arrays (packs declared here were cleared with `rep stos`
            // every eight entries, refined or not).
            alignas(64) T rows[10][kLanes];  // pa, pb, pd (3 each), rho
            for (int l = 0; l < kLanes; ++l) {
                const raster::SplatGeometry<T>& g =
                    st.entry_splat[std::min(first + std::uint32_t(l), end - 1)];
                for (int k = 0; k < 3; ++k)
                    rows[k][l] = g.pa[k], rows[3 + k][l] = g.pb[k], rows[6 + k][l] = g.pd[k];
                rows[9][l] = g.rho_cutoff;
            }
            const auto row = [&](int r) LG_LAMBDA_INLINE { return load_pack(rows[r]); };
            const Vec3<P> pa{row(0), row(1), row(2)}, pb{row(3), row(4), row(5)}, pd{row(6), row(7), row(8)};
            const raster::SplatReach<P> reach = raster::make_splat_reach(pa, pb, pd, row(9));
            for (int l = 0; l < kLanes && first + std::uint32_t(l) < end; ++l) {
                if (std::popcount(masks[l]) <= kRefineAboveBlocks || !reach.definite[l]) continue;
                const raster::SplatReach<T> one{reach.x[l],
                                                reach.y[l],
                                                reach.half_x[l],
                                                reach.half_y[l],
                                                reach.slope[l],
                                                reach.half_width0[l],
                                                reach.t_right[l],
                                                reach.filter_radius[l],
                                                true};
                masks[l] &= reach_block_mask(one, st.entry_splat[first + std::uint32_t(l)].center, tr);
            }
        }
        for (int l = 0; l < kLanes; ++l)
            if (first + std::uint32_t(l) >= end) masks[l] = 0;  // past the tile's last entry
        append_group(masks, first - begin, items, lists.capacity, size);
    }
    std::copy_n(size, kTileBlocks, lists.size);
}

}  // namespace lumigauss::cpu
