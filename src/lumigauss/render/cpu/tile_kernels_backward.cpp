#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_backward.h"
#include "lumigauss/render/cpu/tile_kernels.h"
#include "lumigauss/util/multiversion.h"

namespace lumigauss::cpu {

template <typename T>
LG_ALWAYS_INLINE void backward_any(int tile, const SurfelBatch<T>& s, const RasterState<T>& st,
                                   const RasterImageGrads<T>& g, T* slots, TileScratch<T>& scratch) {
    if (s.channels == 3)
        render_tile_backward<T, 3>(tile, 3, st, g, slots, scratch);
    else if (s.channels == 6)
        render_tile_backward<T, 6>(tile, 6, st, g, slots, scratch);
    else
        render_tile_backward<T, kMaxChannels>(tile, s.channels, st, g, slots, scratch);
}

LG_MULTIVERSION void backward_tile(int tile, const SurfelBatch<float>& s, const RasterState<float>& st,
                                   const RasterImageGrads<float>& g, float* slots,
                                   TileScratch<float>& scratch) {
    backward_any(tile, s, st, g, slots, scratch);
}

void backward_tile(int tile, const SurfelBatch<double>& s, const RasterState<double>& st,
                   const RasterImageGrads<double>& g, double* slots, TileScratch<double>& scratch) {
    backward_any(tile, s, st, g, slots, scratch);
}

}  // namespace lumigauss::cpu
