#pragma once
// The CUDA backend of the surfel rasterizer: the same per-surfel and per-pixel functions as the CPU backend
// (surfel_projection.h, surfel_kernel.h, pixel_blend.h), launched over the GPU's threads.
//
// forward:  one thread per surfel projects it (in double, as the CPU does) and counts its tiles; a prefix
//           sum numbers the (surfel, tile) emissions, a stable radix sort on (tile, depth) orders them
//           front to back within each tile; one block of 16x16 threads per tile (longest lists first)
//           then blends its pixels, one thread per pixel, the surfels staged through shared memory in
//           batches.
// backward: per tile the same walk back to front; each entry's per-pixel gradients are summed over the
//           block (warp shuffles, then the warps in a fixed order) into its (surfel, tile) slot, and a
//           thread per surfel sums its slots and runs the projection's backward. No atomics: the result
//           does not depend on scheduling, like the CPU backend's.
//
// Built only when CMake finds a CUDA compiler and a GPU (cmake/CudaOption.cmake); otherwise these functions
// exist and say so (cuda_backend_available() is false and a CudaRasterizer cannot be made).
#include <memory>
#include <string>
#include <vector>

#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/splat_footprint.h"

namespace lumigauss {

// True when this build has the CUDA backend and a GPU is usable.
bool cuda_backend_available();
// The GPU the backend uses ("NVIDIA H200, compute capability 9.0, 132 multiprocessors"), or why there is
// none.
std::string cuda_backend_description();

// Device time of each phase of the last forward and backward (CUDA events), in milliseconds. Transfers
// between host and device memory are timed apart from the kernels.
struct CudaPhaseTimes {
    double upload = 0, project = 0, bin = 0, blend = 0, download = 0;             // forward
    double grads_upload = 0, backward_tiles = 0, reduce = 0, grads_download = 0;  // backward
    double forward_kernels() const { return project + bin + blend; }
    double backward_kernels() const { return backward_tiles + reduce; }
};

// Keeps its device buffers from call to call (they grow, never shrink), like RasterState on the CPU.
// Float only. Not thread-safe: one rasterizer per host thread.
class CudaRasterizer {
  public:
    CudaRasterizer();  // throws Error when the backend is not built or no GPU is usable
    ~CudaRasterizer();
    CudaRasterizer(const CudaRasterizer&) = delete;
    CudaRasterizer& operator=(const CudaRasterizer&) = delete;

    // Renders every map of RasterImages (the CPU backend's conventions and thresholds) into `images`.
    void forward(const Camera& camera, const SurfelBatch<float>& surfels,
                 const RasterSettings<float>& settings, RasterImages<float>& images);
    // Gradients of the surfels of the last forward from gradients on its maps (an empty map: zero).
    void backward(const RasterImageGrads<float>& grads, SurfelGrads<float>& out);

    // Per surfel of the last forward: its footprint (pixel box, normal, depth; unspecified where not
    // visible) and whether it reached a tile.
    void download_footprints(std::vector<SplatFootprint<float>>& footprints,
                             std::vector<std::uint8_t>& visible) const;

    std::size_t intersections() const;  // (surfel, tile) entries of the last forward
    const CudaPhaseTimes& phase_ms() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace lumigauss
