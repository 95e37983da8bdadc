#pragma once
// Per-tile entry points of the CPU backend. The float versions are compiled for several instruction sets
// (baseline x86-64, AVX2+FMA, AVX-512) and the best one the processor has is picked at load time, so one
// binary runs everywhere and uses the widest vectors available for its packs of eight pixels. The double
// versions (references and tests) are plain.
#include "lumigauss/render/cpu/raster_state.h"
#include "lumigauss/render/cpu/tile_blocks.h"

namespace lumigauss::cpu {

void forward_tile(int tile, const SurfelBatch<float>& surfels, RasterState<float>& st,
                  RasterImages<float>& img, TileScratch<float>& scratch);
void forward_tile(int tile, const SurfelBatch<double>& surfels, RasterState<double>& st,
                  RasterImages<double>& img, TileScratch<double>& scratch);

// Writes the (surfel, tile) gradient slots of every entry of the tile.
void backward_tile(int tile, const SurfelBatch<float>& surfels, const RasterState<float>& st,
                   const RasterImageGrads<float>& grads, float* slots, TileScratch<float>& scratch);
void backward_tile(int tile, const SurfelBatch<double>& surfels, const RasterState<double>& st,
                   const RasterImageGrads<double>& grads, double* slots, TileScratch<double>& scratch);

}  // namespace lumigauss::cpu
