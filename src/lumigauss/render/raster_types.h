#pragma once
// Inputs and outputs of the surfel rasterizer (any backend), as structures of arrays.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/cpu/radix_sort.h"
#include "lumigauss/render/surfel_kernel.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

// Colour channels per surfel every backend handles (RGB, shadowed + unshadowed RGB, and some room).
inline constexpr int kMaxChannels = 16;

// Activated surfel parameters for one render: linear scales, opacity in [0, 1], any number of colour
// channels (3 for RGB; 6 when shadowed and unshadowed shading are rendered in one pass).
template <typename T>
struct SurfelBatch {
    int channels = 3;
    std::vector<T> means;      // 3 per surfel
    std::vector<T> quats;      // 4 per surfel, w x y z, not necessarily normalised
    std::vector<T> scales;     // 2 per surfel: s_u, s_v
    std::vector<T> opacities;  // 1 per surfel
    std::vector<T> colors;     // `channels` per surfel

    std::size_t size() const { return opacities.size(); }
    void resize(std::size_t n) {
        means.resize(3 * n), quats.resize(4 * n), scales.resize(2 * n), opacities.resize(n);
        colors.resize(std::size_t(channels) * n);
    }
    raster::SurfelGeometry<T> geometry(std::size_t i) const {
        return {{means[3 * i], means[3 * i + 1], means[3 * i + 2]},
                {quats[4 * i], quats[4 * i + 1], quats[4 * i + 2], quats[4 * i + 3]},
                scales[2 * i],
                scales[2 * i + 1]};
    }
};

// Throws Error when a batch has a channel count no backend handles or arrays that disagree with its
// surfel count and channels (a batch assembled by hand): every backend checks before it reads them.
template <typename T>
void check_surfel_batch(const SurfelBatch<T>& s) {
    if (s.channels < 1 || s.channels > kMaxChannels)
        throw Error("the rasterizer supports 1 to " + std::to_string(kMaxChannels) +
                    " colour channels, not " + std::to_string(s.channels));
    const std::size_t n = s.size();
    const auto expect = [&](const std::vector<T>& v, std::size_t per_surfel, const char* what) {
        if (v.size() != per_surfel * n)
            throw Error(std::string("surfel batch: ") + what + " has " + std::to_string(v.size()) +
                        " values for " + std::to_string(n) + " surfels (" + std::to_string(per_surfel) +
                        " each)");
    };
    expect(s.means, 3, "means");
    expect(s.quats, 4, "quats");
    expect(s.scales, 2, "scales");
    expect(s.colors, std::size_t(s.channels), "colors");
}

// Every map the rasterizer writes, row-major, `width * height` pixels.
template <typename T>
struct RasterImages {
    int width = 0, height = 0, channels = 0;
    std::vector<T> color;         // `channels` per pixel, background included
    std::vector<T> alpha;         // 1 - final transmittance
    std::vector<T> depth;         // sum of w_i z_i (divide by alpha for the expected depth)
    std::vector<T> median_depth;  // depth where the transmittance crosses 0.5
    std::vector<T> normal;        // 3 per pixel: sum of w_i n_i, world space, camera-facing
    std::vector<T> distortion;    // sum_{j<i} w_i w_j (m_i - m_j)^2 on mapped depth m
};

// dL/d(map) for each map; an empty vector means zero.
template <typename T>
using RasterImageGrads = RasterImages<T>;

template <typename T>
struct SurfelGrads {
    std::vector<T> means, quats, scales, opacities, colors;
    std::vector<T> mean2d;  // 2 per surfel: dL/d(screen translation of the projected centre), pixels
};

template <typename T>
struct RasterSettings {
    std::vector<T> background;  // `channels` values; empty = black
};

// What the tiles and the binning read of a visible surfel besides its kernel geometry: its pixel box, its
// camera-facing normal and its depth, compact (32 bytes in float) because they read it by surfel id.
template <typename T>
struct SplatFootprint {
    raster::PixelRect rect;
    Vec3<T> normal;
    T depth;
};

// What every backend stores of one projected surfel (`p` from project_surfel, in double), rounded to T: the
// state the projection's backward reads, the per-pixel kernel's geometry, and the footprint. (Written into
// the destinations: returned as one structure, the CPU projection copied it through the stack.)
template <typename T>
LG_HD inline void store_projected(const raster::ProjectedSurfel<double>& p, double opacity,
                                  raster::ProjectionVjpInputs<T>& projection, raster::SplatGeometry<T>& splat,
                                  SplatFootprint<T>& footprint) {
    const raster::SplatGeometry<double> g =
        raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, opacity, p.reach);
    const Vec2<T> center{T(p.center.x), T(p.center.y)};
    projection = {p.tu.cast<T>(), p.tv.cast<T>(), p.tw.cast<T>(), center, T(p.flip), p.conic_center};
    splat = {g.pa.cast<T>(), g.pb.cast<T>(), g.pd.cast<T>(), g.tw.cast<T>(),
             center,         T(g.opacity),   T(g.rho_cutoff)};
    footprint = {p.rect, p.normal.cast<T>(), T(p.depth)};
}

// Tiles a surfel's box touches (inclusive).
struct TileSpan {
    int tx0, ty0, tx1, ty1;
    LG_HD std::uint32_t count() const { return std::uint32_t((tx1 - tx0 + 1) * (ty1 - ty0 + 1)); }
};
LG_HD inline TileSpan tile_span(const raster::PixelRect& r) {
    return {r.x0 / raster::kTileSize, r.y0 / raster::kTileSize, r.x1 / raster::kTileSize,
            r.y1 / raster::kTileSize};
}

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

template <typename T>
raster::PinholeView<T> pinhole_view(const Camera& camera) {
    return {camera.rotation.cast<T>(),
            camera.translation.cast<T>(),
            T(camera.fx),
            T(camera.fy),
            T(camera.cx),
            T(camera.cy),
            camera.width,
            camera.height};
}

}  // namespace lumigauss
