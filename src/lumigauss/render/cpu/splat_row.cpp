#include "lumigauss/render/cpu/splat_row.h"

namespace lumigauss::raster {

// ifunc-based multiversioning needs GCC on x86-64; sanitizer builds keep the plain version.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#define LG_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define LG_MULTIVERSION
#endif

LG_MULTIVERSION void splat_row(const SplatGeometry<float>& g, float px0, float py, int lo, int hi,
                               RowSamples<float>& out) {
    evaluate_splat_row(g, px0, py, lo, hi, out);
}

void splat_row(const SplatGeometry<double>& g, double px0, double py, int lo, int hi,
               RowSamples<double>& out) {
    evaluate_splat_row(g, px0, py, lo, hi, out);
}

}  // namespace lumigauss::raster
