#pragma once
// What both backends store of one projected surfel: its footprint (pixel box, normal, depth) beside the
// projection's backward state and the per-pixel kernel's geometry, and the tiles its box touches.
#include <cstdint>

#include "lumigauss/render/raster_constants.h"
#include "lumigauss/render/surfel_kernel.h"
#include "lumigauss/render/surfel_projection.h"

namespace lumigauss {

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

}  // namespace lumigauss
