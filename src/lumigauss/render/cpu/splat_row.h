#pragma once
// The vectorised pass of the CPU backend: one surfel against one tile row (surfel_kernel.h's
// evaluate_splat_row). The float version is compiled for several instruction sets (baseline x86-64,
// AVX2+FMA, AVX-512) and picked at load time, so one binary runs everywhere and uses the widest vectors the
// processor has.
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::raster {

void splat_row(const SplatGeometry<float>& g, float px0, float py, int lo, int hi, RowSamples<float>& out);
void splat_row(const SplatGeometry<double>& g, double px0, double py, int lo, int hi,
               RowSamples<double>& out);

}  // namespace lumigauss::raster
