#pragma once
// Per-tile entry points of the CPU backend. The float versions are compiled for several instruction sets
// (baseline x86-64, AVX2+FMA, AVX-512) and the best one the processor has is picked at load time, so one
// binary runs everywhere and uses the widest vectors available: a tile row of 16 pixels is one AVX-512
// register. The double versions (references and tests) are plain.
#include "lumigauss/render/raster_types.h"

namespace lumigauss::cpu {

void forward_tile(int tile, const SurfelBatch<float>& surfels, RasterState<float>& st,
                  RasterImages<float>& img);
void forward_tile(int tile, const SurfelBatch<double>& surfels, RasterState<double>& st,
                  RasterImages<double>& img);

// Writes the (surfel, tile) gradient slots of every entry of the tile.
void backward_tile(int tile, const SurfelBatch<float>& surfels, const RasterState<float>& st,
                   const RasterImageGrads<float>& grads, float* slots);
void backward_tile(int tile, const SurfelBatch<double>& surfels, const RasterState<double>& st,
                   const RasterImageGrads<double>& grads, double* slots);

}  // namespace lumigauss::cpu
