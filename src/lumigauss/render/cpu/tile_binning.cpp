#include "lumigauss/render/cpu/tile_binning.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

namespace lumigauss {
namespace {

using raster::kTileSize;

struct TileSpan {
    int tx0, ty0, tx1, ty1;  // inclusive
    std::uint32_t count() const { return std::uint32_t((tx1 - tx0 + 1) * (ty1 - ty0 + 1)); }
};

TileSpan tile_span(const raster::PixelRect& r) {
    return {r.x0 / kTileSize, r.y0 / kTileSize, r.x1 / kTileSize, r.y1 / kTileSize};
}

// Surfels are binned in chunks of consecutive ids, each with its own per-tile counters, so that every pass is
// parallel and the result is still the serial one: within a tile, chunk k's entries precede chunk k + 1's.
// At most kMaxChunks chunks bound the counters at kMaxChunks x tiles.
constexpr std::size_t kMinChunk = 16384, kMaxChunks = 32;

}  // namespace

// Builds the per-tile lists of surfels sorted front to back: one (surfel, tile) emission per touched tile,
// numbered surfel by surfel (the backward's gradient slots); a counting sort of the emissions by tile; then
// each tile's list sorted by depth, ties by emission (that is, surfel) order, so the order is deterministic.
template <typename T>
void bin_surfels_to_tiles(RasterState<T>& st) {
    const std::size_t n = st.projected.size();
    const std::size_t num_tiles = std::size_t(st.tiles_x) * st.tiles_y;
    const std::size_t chunk = std::max(kMinChunk, (n + kMaxChunks - 1) / kMaxChunks);
    const std::size_t num_chunks = (n + chunk - 1) / chunk;
    const auto chunk_range = [&](std::size_t c) {
        return tbb::blocked_range<std::size_t>(c * chunk, std::min(n, (c + 1) * chunk));
    };

    // Per surfel: how many tiles it touches (emission_offset[i + 1], prefix-summed below); per chunk and
    // tile: how many of the chunk's surfels touch the tile.
    st.emission_offset.resize(n + 1);
    st.emission_offset[0] = 0;
    std::vector<std::uint32_t> cursor(num_chunks * num_tiles, 0);
    tbb::parallel_for(std::size_t(0), num_chunks, [&](std::size_t c) {
        std::uint32_t* counts = &cursor[c * num_tiles];
        const auto r = chunk_range(c);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (!st.visible[i]) {
                st.emission_offset[i + 1] = 0;
                continue;
            }
            const TileSpan s = tile_span(st.projected[i].rect);
            st.emission_offset[i + 1] = s.count();
            for (int ty = s.ty0; ty <= s.ty1; ++ty)
                for (int tx = s.tx0; tx <= s.tx1; ++tx) ++counts[std::size_t(ty) * st.tiles_x + tx];
        }
    });
    for (std::size_t i = 0; i < n; ++i) st.emission_offset[i + 1] += st.emission_offset[i];
    const std::size_t total = st.emission_offset[n];

    // Tile starts, and each chunk's first slot in every tile.
    st.tile_start.resize(num_tiles + 1);
    std::uint32_t next = 0;
    for (std::size_t t = 0; t < num_tiles; ++t) {
        st.tile_start[t] = next;
        for (std::size_t c = 0; c < num_chunks; ++c) {
            const std::uint32_t count = cursor[c * num_tiles + t];
            cursor[c * num_tiles + t] = next;
            next += count;
        }
    }
    st.tile_start[num_tiles] = next;

    // Scatter sort keys into tile order: the depth's float bits (positive floats order like their bit
    // patterns) above the emission index, which breaks ties deterministically, in surfel order. Each
    // emission also records its surfel (a small array: the per-tile pass below reads it at random).
    std::vector<std::uint64_t>& keys = st.sort_keys;
    keys.resize(total);
    std::vector<std::uint32_t>& emission_surfel = st.emission_surfel;
    emission_surfel.resize(total);
    tbb::parallel_for(std::size_t(0), num_chunks, [&](std::size_t c) {
        std::uint32_t* slot = &cursor[c * num_tiles];
        const auto r = chunk_range(c);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (!st.visible[i]) continue;
            const auto depth_bits = std::uint64_t(std::bit_cast<std::uint32_t>(float(st.projected[i].depth)));
            const TileSpan s = tile_span(st.projected[i].rect);
            std::uint32_t e = st.emission_offset[i];
            for (int ty = s.ty0; ty <= s.ty1; ++ty)
                for (int tx = s.tx0; tx <= s.tx1; ++tx, ++e) {
                    keys[slot[std::size_t(ty) * st.tiles_x + tx]++] = (depth_bits << 32) | e;
                    emission_surfel[e] = std::uint32_t(i);
                }
        }
    });

    st.entry_surfel.resize(total);
    st.entry_emission.resize(total);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_tiles, 4), [&](const auto& r) {
        for (std::size_t t = r.begin(); t != r.end(); ++t) {
            std::sort(keys.begin() + st.tile_start[t], keys.begin() + st.tile_start[t + 1]);
            for (std::uint32_t k = st.tile_start[t]; k < st.tile_start[t + 1]; ++k) {
                const auto e = std::uint32_t(keys[k] & 0xffffffffu);
                st.entry_surfel[k] = emission_surfel[e];
                st.entry_emission[k] = e;
            }
        }
    });
}

template void bin_surfels_to_tiles(RasterState<float>&);
template void bin_surfels_to_tiles(RasterState<double>&);

}  // namespace lumigauss
