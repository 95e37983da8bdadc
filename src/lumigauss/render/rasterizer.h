#pragma once
// The surfel rasterizer behind one interface, whatever runs it: the CPU backend (render/cpu/, oneTBB) or the
// CUDA backend (render/cuda/). Nothing outside render/ names a backend; callers pick one by name
// (`--backend cpu|cuda|auto`) and get a Rasterizer.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss {

enum class RasterBackend { Cpu, Cuda };

const char* backend_name(RasterBackend backend);  // "cpu", "cuda"
// "cpu", "cuda" or "auto" (CUDA when this build has it and a GPU is usable, else the CPU). Throws Error
// for another name, and for "cuda" where the CUDA backend cannot run (saying why).
RasterBackend choose_backend(const std::string& name);
// One line naming the backend and, for CUDA, the GPU.
std::string backend_description(RasterBackend backend);

// What densification and the near-surfel rules read of each surfel in the last forward pass.
struct SurfelFootprints {
    std::vector<std::uint8_t> visible;  // 1 when it reached a pixel
    std::vector<float> radius;          // pixels: half the larger side of its pixel box; 0 when not visible
    std::vector<float> depth;           // depth of its centre in the camera; 0 when not visible
};

// Keeps what its last forward needs for the backward, and its buffers from call to call (loops over views).
// Float only. Not thread-safe: one rasterizer per thread of the caller.
class Rasterizer {
  public:
    virtual ~Rasterizer() = default;
    virtual RasterBackend backend() const = 0;

    // Every map of RasterImages (background included in the colour) into `images`.
    virtual void forward(const Camera& camera, const SurfelBatch<float>& surfels,
                         const RasterSettings<float>& settings, RasterImages<float>& images) = 0;
    // Gradients of the surfels of the last forward (`surfels` must be that forward's) from gradients on its
    // maps (an empty map: zero).
    virtual void backward(const SurfelBatch<float>& surfels, const RasterImageGrads<float>& grads,
                          SurfelGrads<float>& out) = 0;
    // The footprints of the last forward's surfels.
    virtual void footprints(SurfelFootprints& out) const = 0;
    // (surfel, tile) entries of the last forward.
    virtual std::size_t intersections() const = 0;

    // Convenience: a forward into fresh images.
    RasterImages<float> render(const Camera& camera, const SurfelBatch<float>& surfels,
                               const RasterSettings<float>& settings = {});
};

// Throws Error when the backend cannot run here (CUDA: not built, or no GPU).
std::unique_ptr<Rasterizer> make_rasterizer(RasterBackend backend);

}  // namespace lumigauss
