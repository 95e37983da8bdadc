#include "lumigauss/render/cpu/tile_kernels.h"

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_backward.h"
#include "lumigauss/render/cpu/tile_forward.h"

namespace lumigauss::cpu {

// ifunc-based multiversioning needs GCC on x86-64; sanitizer builds keep the baseline version only.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define LG_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define LG_MULTIVERSION
#endif

// Channel counts with their own code: 3 (RGB) and 6 (shadowed and unshadowed RGB in one pass); the rest
// run the kMaxChannels code with the unused channels at zero.
template <typename T>
LG_ALWAYS_INLINE void forward_any(int tile, const SurfelBatch<T>& s, RasterState<T>& st,
                                  RasterImages<T>& img) {
    if (s.channels == 3)
        render_tile_forward<T, 3>(tile, 3, st, img);
    else if (s.channels == 6)
        render_tile_forward<T, 6>(tile, 6, st, img);
    else
        render_tile_forward<T, kMaxChannels>(tile, s.channels, st, img);
}

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

LG_MULTIVERSION void forward_tile(int tile, const SurfelBatch<float>& s, RasterState<float>& st,
                                  RasterImages<float>& img) {
    forward_any(tile, s, st, img);
}

void forward_tile(int tile, const SurfelBatch<double>& s, RasterState<double>& st,
                  RasterImages<double>& img) {
    forward_any(tile, s, st, img);
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
