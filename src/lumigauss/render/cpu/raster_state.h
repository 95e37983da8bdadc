#pragma once
// The CPU backend's state: what its forward keeps for the backward, and the scratch it reuses from call to
// call.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lumigauss/render/cpu/radix_sort.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/splat_footprint.h"

namespace lumigauss {

// What binning needs of a visible surfel, compact.
struct VisibleSurfel {
    TileSpan span;
    std::uint32_t surfel, first_emission;
};

// Wall time of each phase of the last forward and backward, in milliseconds (for benchmarks and profiling).
struct RasterPhaseTimes {
    double project = 0, bin = 0, gather = 0, blend = 0;  // forward
    double backward_tiles = 0, reduce = 0;               // backward
};

// What the forward keeps for the backward.
template <typename T>
struct RasterState {
    raster::PinholeView<T> view{};
    int tiles_x = 0, tiles_y = 0;
    std::vector<raster::ProjectionVjpInputs<T>>
        projections;                               // per surfel: what the projection's backward reads
    std::vector<raster::SplatGeometry<T>> splats;  // per surfel: what the per-pixel kernel reads
    std::vector<SplatFootprint<T>> footprints;     // per surfel: box, normal, depth
    std::vector<std::uint8_t> visible;
    std::vector<std::uint32_t> emission_offset;  // per surfel: first (surfel, tile) emission; size N + 1
    std::vector<std::uint32_t> tile_start;       // per tile: first sorted entry; size tiles + 1
    std::vector<std::uint32_t> entry_surfel;     // sorted entries: surfel id (per tile, front to back)
    std::vector<std::uint32_t> entry_emission;   // sorted entry -> its emission (slot of the backward)
    // What the per-pixel loops read, gathered per sorted entry so that a tile's blocks stream through
    // memory instead of jumping between surfels: kernel geometry, footprint, `channels` colours.
    std::vector<raster::SplatGeometry<T>> entry_splat;
    std::vector<SplatFootprint<T>> entry_footprint;
    std::vector<T> entry_color;
    // Per tile, per block of 4 x 2 pixels (the CPU backend's unit of work, render/cpu/tile_blocks.h): the
    // tile's entries, as indices from its first, that the forward composited into at least one of the
    // block's pixels, front to back. The backward walks exactly these.
    std::vector<std::vector<std::uint32_t>> block_entries;  // per tile
    std::vector<std::uint32_t> block_start;                 // per tile: blocks + 1 offsets into its list
    std::vector<T> final_transmittance;                     // per pixel
    std::vector<std::uint32_t> contributors;  // per pixel: entries up to the last composited, in its tile
    std::vector<std::int32_t> median_entry;   // per pixel: sorted entry giving the median depth, or -1
    std::vector<T> m1, m2;                    // per pixel: sum w m, sum w m^2 (distortion)
    std::vector<T> background;

    // The backward's (surfel, tile) gradient slots, kept like the binning scratch below.
    std::vector<T> gradient_slots;

    // Binning scratch, kept so that a loop reusing one RasterState does not allocate it again per call.
    std::vector<VisibleSurfel> visible_surfels;          // in surfel order
    std::vector<std::uint32_t> depth_keys, depth_order;  // visible_surfels indices, sorted front to back
    std::vector<VisibleSurfel> sorted_surfels;           // visible_surfels in that order
    RadixSortScratch sort_scratch;

    mutable RasterPhaseTimes phase_ms;  // diagnostics only; the backward (const state) records its own

    std::size_t intersections() const { return entry_surfel.size(); }
};

}  // namespace lumigauss
