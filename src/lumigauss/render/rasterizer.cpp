#include "lumigauss/render/rasterizer.h"

#include <algorithm>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cuda/rasterizer_cuda.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// The radius densification reads: half the larger side of the pixel box (0 for an empty box).
float footprint_radius(const raster::PixelRect& r) {
    return r.empty() ? 0.0f : 0.5f * float(std::max(r.x1 - r.x0 + 1, r.y1 - r.y0 + 1));
}

void fill_footprints(const std::vector<SplatFootprint<float>>& all, const std::vector<std::uint8_t>& visible,
                     SurfelFootprints& out) {
    const std::size_t n = visible.size();
    out.visible = visible;
    out.radius.assign(n, 0.0f);
    out.depth.assign(n, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        if (!visible[i]) continue;
        out.radius[i] = footprint_radius(all[i].rect);
        out.depth[i] = all[i].depth;
    }
}

class CpuRasterizer final : public Rasterizer {
  public:
    RasterBackend backend() const override { return RasterBackend::Cpu; }
    void forward(const Camera& camera, const SurfelBatch<float>& surfels,
                 const RasterSettings<float>& settings, RasterImages<float>& images) override {
        rasterize_forward_cpu(camera, surfels, settings, state_, images);
    }
    void backward(const SurfelBatch<float>& surfels, const RasterImageGrads<float>& grads,
                  SurfelGrads<float>& out) override {
        rasterize_backward_cpu(surfels, state_, grads, out);
    }
    void footprints(SurfelFootprints& out) const override {
        fill_footprints(state_.footprints, state_.visible, out);
    }
    std::size_t intersections() const override { return state_.intersections(); }

  private:
    RasterState<float> state_;
};

class CudaBackendRasterizer final : public Rasterizer {
  public:
    RasterBackend backend() const override { return RasterBackend::Cuda; }
    void forward(const Camera& camera, const SurfelBatch<float>& surfels,
                 const RasterSettings<float>& settings, RasterImages<float>& images) override {
        gpu_.forward(camera, surfels, settings, images);
    }
    void backward(const SurfelBatch<float>&, const RasterImageGrads<float>& grads,
                  SurfelGrads<float>& out) override {
        gpu_.backward(grads, out);  // the surfels of the forward are still on the device
    }
    void footprints(SurfelFootprints& out) const override {
        gpu_.download_footprints(footprints_, visible_);
        fill_footprints(footprints_, visible_, out);
    }
    std::size_t intersections() const override { return gpu_.intersections(); }

  private:
    mutable CudaRasterizer gpu_;
    mutable std::vector<SplatFootprint<float>> footprints_;
    mutable std::vector<std::uint8_t> visible_;
};

}  // namespace

const char* backend_name(RasterBackend backend) {
    return backend == RasterBackend::Cuda ? "cuda" : "cpu";
}

RasterBackend choose_backend(const std::string& name) {
    if (name == "cpu") return RasterBackend::Cpu;
    if (name == "auto") return cuda_backend_available() ? RasterBackend::Cuda : RasterBackend::Cpu;
    if (name == "cuda") {
        if (!cuda_backend_available()) throw Error("--backend cuda: " + cuda_backend_description());
        return RasterBackend::Cuda;
    }
    throw Error("--backend '" + name + "': use cpu, cuda or auto");
}

std::string backend_description(RasterBackend backend) {
    if (backend == RasterBackend::Cuda) return "cuda (" + cuda_backend_description() + ")";
    return "cpu";
}

RasterImages<float> Rasterizer::render(const Camera& camera, const SurfelBatch<float>& surfels,
                                       const RasterSettings<float>& settings) {
    RasterImages<float> images;
    forward(camera, surfels, settings, images);
    return images;
}

std::unique_ptr<Rasterizer> make_rasterizer(RasterBackend backend) {
    if (backend == RasterBackend::Cuda) return std::make_unique<CudaBackendRasterizer>();
    return std::make_unique<CpuRasterizer>();
}

}  // namespace lumigauss
