#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_forward.h"
#include "lumigauss/render/cpu/tile_kernels.h"
#include "lumigauss/util/multiversion.h"

namespace lumigauss::cpu {

// Channel counts with their own code: 3 (RGB) and 6 (shadowed and unshadowed RGB in one pass); the rest
// run the kMaxChannels code with the unused channels at zero. (Same in tile_kernels_backward.cpp.)
template <typename T>
LG_ALWAYS_INLINE void forward_any(int tile, const SurfelBatch<T>& s, RasterState<T>& st, RasterImages<T>& img,
                                  TileScratch<T>& scratch) {
    if (s.channels == 3)
        render_tile_forward<T, 3>(tile, 3, st, img, scratch);
    else if (s.channels == 6)
        render_tile_forward<T, 6>(tile, 6, st, img, scratch);
    else
        render_tile_forward<T, kMaxChannels>(tile, s.channels, st, img, scratch);
}

LG_MULTIVERSION void forward_tile(int tile, const SurfelBatch<float>& s, RasterState<float>& st,
                                  RasterImages<float>& img, TileScratch<float>& scratch) {
    forward_any(tile, s, st, img, scratch);
}

void forward_tile(int tile, const SurfelBatch<double>& s, RasterState<double>& st, RasterImages<double>& img,
                  TileScratch<double>& scratch) {
    forward_any(tile, s, st, img, scratch);
}

}  // namespace lumigauss::cpu
