#pragma once
// The CPU backend of the surfel rasterizer: 16x16 tiles rendered in parallel with oneTBB.
//
// forward:  project every surfel, bin (surfel, tile) pairs, sort each tile front to back, then per tile
//           walk the surfels and blend them into the pixels of their bounding square.
// backward: per tile, the same walk back to front; each (surfel, tile) pair owns one gradient slot, so
//           tiles never write to the same memory; a per-surfel pass then sums its slots and runs the
//           projection backward. Memory is linear in surfels + intersections, independent of threads.
#include "lumigauss/render/cpu/raster_state.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

template <typename T>
RasterImages<T> rasterize_forward_cpu(const Camera& camera, const SurfelBatch<T>& surfels,
                                      const RasterSettings<T>& settings, RasterState<T>& state);

// The same, into caller-owned images whose buffers are reused from call to call (loops over views).
template <typename T>
void rasterize_forward_cpu(const Camera& camera, const SurfelBatch<T>& surfels,
                           const RasterSettings<T>& settings, RasterState<T>& state, RasterImages<T>& images);

template <typename T>
SurfelGrads<T> rasterize_backward_cpu(const SurfelBatch<T>& surfels, const RasterState<T>& state,
                                      const RasterImageGrads<T>& grads);

// The same, into caller-owned gradients, with the state's scratch: no allocation from call to call once
// the buffers have grown (training loops).
template <typename T>
void rasterize_backward_cpu(const SurfelBatch<T>& surfels, RasterState<T>& state,
                            const RasterImageGrads<T>& grads, SurfelGrads<T>& out);

}  // namespace lumigauss
