#include "lumigauss/model/render_model.h"

namespace lumigauss {

ModelRenderer::ModelRenderer(RasterBackend backend, const SurfelSideRule& sides)
    : rasterizer_(make_rasterizer(backend)), sides_(sides) {}

const RasterImages<float>& ModelRenderer::render(const SurfelModel& model, const Camera& camera,
                                                 const SurfelShader& shade,
                                                 const RasterSettings<float>& settings) {
    compute_view_normals(model, camera, normals_, sides_);
    model.activated(batch_);
    shade(normals_, batch_);
    rasterizer_->forward(camera, batch_, settings, images_);
    return images_;
}

const RasterImages<float>& ModelRenderer::recolour(const Camera& camera, const SurfelShader& shade,
                                                   const RasterSettings<float>& settings) {
    shade(normals_, batch_);
    rasterizer_->forward(camera, batch_, settings, images_);
    return images_;
}

const RasterImages<float>& ModelRenderer::render(const SurfelModel& model, const Camera& camera,
                                                 const ShCoeffs<float>& env, ShadingMode mode,
                                                 const RasterSettings<float>& settings) {
    return render(
        model, camera,
        [&](const ViewNormals& normals, SurfelBatch<float>& batch) {
            shade_surfels(model, env, mode, normals, batch);
        },
        settings);
}

RasterImages<float> render_with_environment(const SurfelModel& model, const Camera& camera,
                                            const ShCoeffs<float>& env, ShadingMode mode,
                                            RasterBackend backend, const SurfelSideRule& sides) {
    ModelRenderer renderer(backend, sides);
    return renderer.render(model, camera, env, mode);
}

}  // namespace lumigauss
