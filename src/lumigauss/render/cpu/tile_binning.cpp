#include "lumigauss/render/cpu/tile_binning.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "lumigauss/render/cpu/radix_sort.h"

namespace lumigauss {
namespace {

// Parallel passes run over fixed chunks of surfels, each with its own per-tile counters, so that the result
// is the serial one. At most kMaxChunks chunks bound the counters at kMaxChunks x tiles.
constexpr std::size_t kMinChunk = 16384, kMaxChunks = 32;

struct Chunks {
    std::size_t size, count;
    Chunks(std::size_t n)
        : size(std::max(kMinChunk, (n + kMaxChunks - 1) / kMaxChunks)), count((n + size - 1) / size) {}
};

}  // namespace

// Builds the per-tile lists of surfels sorted front to back. The visible surfels are sorted once by depth
// (a stable radix sort of the float bits of their depths, which order like the depths since they are
// positive; ties keep surfel order) and then scattered into their tiles in that order, so every tile's
// list comes out sorted, deterministically, without sorting each tile. Each (surfel, tile) pair is an
// emission, numbered surfel by surfel: the backward's gradient slots.
//
// Every pass reads its input in order: the visible surfels are compacted in surfel order, and gathered
// once into depth order after the sort, so that the two passes over the depth order do not jump around
// memory (with the records read through the sorted indices, they were a tenth of the forward).
template <typename T>
void bin_surfels_to_tiles(RasterState<T>& st) {
    const std::size_t n = st.footprints.size();
    const std::size_t num_tiles = std::size_t(st.tiles_x) * st.tiles_y;

    // Visible surfels in surfel order, compacted chunk by chunk: their depth keys, and what the passes
    // below need of them (compact: the full projection state would be read at random after the sort).
    // Then each surfel's first emission (prefix sums of the tile counts).
    const Chunks surfel_chunks(n);
    std::vector<std::uint32_t> chunk_visible(surfel_chunks.count + 1, 0),
        chunk_emissions(surfel_chunks.count + 1, 0);
    tbb::parallel_for(std::size_t(0), surfel_chunks.count, [&](std::size_t c) {
        std::uint32_t visible = 0, emissions = 0;
        for (std::size_t i = c * surfel_chunks.size; i < std::min(n, (c + 1) * surfel_chunks.size); ++i) {
            if (!st.visible[i]) continue;
            ++visible;
            emissions += tile_span(st.footprints[i].rect).count();
        }
        chunk_visible[c + 1] = visible, chunk_emissions[c + 1] = emissions;
    });
    for (std::size_t c = 0; c < surfel_chunks.count; ++c) {
        chunk_visible[c + 1] += chunk_visible[c];
        chunk_emissions[c + 1] += chunk_emissions[c];
    }
    const std::size_t m = chunk_visible[surfel_chunks.count];
    std::vector<std::uint32_t>& keys = st.depth_keys;
    std::vector<std::uint32_t>& order = st.depth_order;  // indices into `visible`
    std::vector<VisibleSurfel>& visible = st.visible_surfels;
    keys.resize(m), order.resize(m), visible.resize(m);
    st.emission_offset.resize(n + 1);
    st.emission_offset[n] = chunk_emissions[surfel_chunks.count];
    tbb::parallel_for(std::size_t(0), surfel_chunks.count, [&](std::size_t c) {
        std::uint32_t k = chunk_visible[c], emission = chunk_emissions[c];
        for (std::size_t i = c * surfel_chunks.size; i < std::min(n, (c + 1) * surfel_chunks.size); ++i) {
            st.emission_offset[i] = emission;
            if (!st.visible[i]) continue;
            const TileSpan span = tile_span(st.footprints[i].rect);
            keys[k] = std::bit_cast<std::uint32_t>(float(st.footprints[i].depth));
            order[k] = k;
            visible[k] = {span, std::uint32_t(i), emission};
            emission += span.count();
            ++k;
        }
    });
    radix_sort_pairs(keys, order, st.sort_scratch);
    std::vector<VisibleSurfel>& sorted = st.sorted_surfels;
    sorted.resize(m);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 4096), [&](const auto& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) sorted[k] = visible[order[k]];
    });

    // Per chunk of the depth order and per tile: how many emissions; then where each chunk's go.
    const Chunks chunks(m);
    std::vector<std::uint32_t> cursor(chunks.count * num_tiles, 0);
    const auto for_each_chunk = [&](auto&& body) {
        tbb::parallel_for(std::size_t(0), chunks.count, [&](std::size_t c) {
            body(&cursor[c * num_tiles], c * chunks.size, std::min(m, (c + 1) * chunks.size));
        });
    };
    for_each_chunk([&](std::uint32_t* counts, std::size_t first, std::size_t last) {
        for (std::size_t k = first; k < last; ++k) {
            const TileSpan& s = sorted[k].span;
            for (int ty = s.ty0; ty <= s.ty1; ++ty)
                for (int tx = s.tx0; tx <= s.tx1; ++tx) ++counts[std::size_t(ty) * st.tiles_x + tx];
        }
    });
    st.tile_start.resize(num_tiles + 1);
    std::uint32_t next = 0;
    for (std::size_t t = 0; t < num_tiles; ++t) {
        st.tile_start[t] = next;
        for (std::size_t c = 0; c < chunks.count; ++c) {
            const std::uint32_t count = cursor[c * num_tiles + t];
            cursor[c * num_tiles + t] = next;
            next += count;
        }
    }
    st.tile_start[num_tiles] = next;

    // Scatter: within a tile, chunk c's entries follow chunk c - 1's, each chunk in depth order.
    st.entry_surfel.resize(next);
    st.entry_emission.resize(next);
    for_each_chunk([&](std::uint32_t* slot, std::size_t first, std::size_t last) {
        for (std::size_t k = first; k < last; ++k) {
            const VisibleSurfel& v = sorted[k];
            std::uint32_t e = v.first_emission;
            for (int ty = v.span.ty0; ty <= v.span.ty1; ++ty)
                for (int tx = v.span.tx0; tx <= v.span.tx1; ++tx, ++e) {
                    const std::uint32_t at = slot[std::size_t(ty) * st.tiles_x + tx]++;
                    st.entry_surfel[at] = v.surfel;
                    st.entry_emission[at] = e;
                }
        }
    });
}

template void bin_surfels_to_tiles(RasterState<float>&);
template void bin_surfels_to_tiles(RasterState<double>&);

}  // namespace lumigauss
