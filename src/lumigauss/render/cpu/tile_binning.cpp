#include "lumigauss/render/cpu/tile_binning.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>

namespace lumigauss {

using raster::kTileSize;

// Builds the per-tile lists of surfels sorted front to back: emit one (surfel, tile) pair per touched
// tile, counting-sort the pairs by tile, then sort each tile's list by depth (ties by surfel id, so the
// order is deterministic).
template <typename T>
void bin_surfels_to_tiles(RasterState<T>& st) {
    const std::size_t n = st.projected.size();
    const auto tile_span = [&](std::size_t i, int& tx0, int& ty0, int& tx1, int& ty1) {
        const raster::PixelRect& r = st.projected[i].rect;
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

    std::vector<std::uint32_t>& emission_tile = st.emission_tile;
    emission_tile.resize(total);
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

    // Scatter the emissions into tile order as sort keys: the depth's float bits (positive floats order like
    // their bit patterns) above the emission index, which breaks ties deterministically, in surfel order.
    std::vector<std::uint32_t>& emission_surfel = st.emission_surfel;
    emission_surfel.resize(total);
    for (std::size_t i = 0; i < n; ++i)
        std::fill(emission_surfel.begin() + st.emission_offset[i],
                  emission_surfel.begin() + st.emission_offset[i + 1], std::uint32_t(i));
    std::vector<std::uint64_t>& keys = st.sort_keys;
    keys.resize(total);
    {
        std::vector<std::uint32_t> cursor(st.tile_start.begin(), st.tile_start.end() - 1);
        for (std::uint32_t e = 0; e < total; ++e) {
            const auto depth = float(st.projected[emission_surfel[e]].depth);
            keys[cursor[emission_tile[e]]++] = (std::uint64_t(std::bit_cast<std::uint32_t>(depth)) << 32) | e;
        }
    }
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
