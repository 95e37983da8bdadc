#include "lumigauss/render/cpu/multiversion.h"
#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_backward.h"
#include "lumigauss/render/cpu/tile_kernels.h"

namespace lumigauss::cpu {

template <typename T>
LG_ALWAYS_INLINE void backward_any(int tile, const SurfelBatch<T>& s, const RasterState<T>& st,
                                   const RasterImageGrads<T>& g, T* slots) {
    if (s.channels == 3)
        render_tile_backward<T, 3>(tile, 3, st, g, slots);
    else if (s.channels == 6)
        render_tile_backward<T, 6>(tile, 6, st, g, slots);
    else
        render_tile_backward<T, kMaxChannels>(tile, s.channels, st, g, slots);
}

LG_MULTIVERSION void backward_tile(int tile, const SurfelBatch<float>& s, const RasterState<float>& st,
                                   const RasterImageGrads<float>& g, float* slots) {
    backward_any(tile, s, st, g, slots);
}

void backward_tile(int tile, const SurfelBatch<double>& s, const RasterState<double>& st,
                   const RasterImageGrads<double>& g, double* slots) {
    backward_any(tile, s, st, g, slots);
}

}  // namespace lumigauss::cpu
