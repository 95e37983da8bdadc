#pragma once
// Rendering a relightable model for a camera under a light: the one path from surfels to maps that relight,
// eval, fit-light, the viewer's scene info and the tests take (training runs the same steps one by one, for
// its timings and its backward). Per view: the camera-facing normals (view_shading.h), the activated
// geometry, the surfels' colours, then the rasterizer of the chosen backend (render/rasterizer.h).
#include <functional>
#include <memory>

#include "lumigauss/io/camera.h"
#include "lumigauss/model/surfel_model.h"
#include "lumigauss/model/view_shading.h"
#include "lumigauss/render/rasterizer.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// Writes the colours of every surfel for one view: batch.channels and batch.colors (the geometry is set).
using SurfelShader = std::function<void(const ViewNormals& normals, SurfelBatch<float>& batch)>;

// Keeps its buffers and its rasterizer from render to render (loops over views and lights). `sides` is the
// run's side rule (TrainedRun::side_rule; {} = official), so that every render shades as training did.
class ModelRenderer {
  public:
    explicit ModelRenderer(RasterBackend backend = RasterBackend::Cpu, const SurfelSideRule& sides = {});

    // `model` from `camera`, each surfel coloured by `shade`.
    const RasterImages<float>& render(const SurfelModel& model, const Camera& camera,
                                      const SurfelShader& shade, const RasterSettings<float>& settings = {});
    // `model` from `camera` under the environment radiance SH `env` in `mode` (shade_surfels), black
    // background as in training.
    const RasterImages<float>& render(const SurfelModel& model, const Camera& camera,
                                      const ShCoeffs<float>& env, ShadingMode mode,
                                      const RasterSettings<float>& settings = {});

    // The last render's model and camera again with other colours: its normals and geometry are reused,
    // only the shading and the rasterisation run (several lights per view). `model` must be unchanged since.
    const RasterImages<float>& recolour(const Camera& camera, const SurfelShader& shade,
                                        const RasterSettings<float>& settings = {});

    // What the last render computed: the view's normals and sides, the surfels as rasterized.
    const ViewNormals& normals() const { return normals_; }
    const SurfelBatch<float>& batch() const { return batch_; }
    Rasterizer& rasterizer() { return *rasterizer_; }

  private:
    std::unique_ptr<Rasterizer> rasterizer_;
    SurfelSideRule sides_;
    ViewNormals normals_;
    SurfelBatch<float> batch_;
    RasterImages<float> images_;
};

// One render into fresh maps: colour (3 or 6 channels), alpha, depth, normal, ...
RasterImages<float> render_with_environment(const SurfelModel& model, const Camera& camera,
                                            const ShCoeffs<float>& env, ShadingMode mode,
                                            RasterBackend backend = RasterBackend::Cpu,
                                            const SurfelSideRule& sides = {});

}  // namespace lumigauss
