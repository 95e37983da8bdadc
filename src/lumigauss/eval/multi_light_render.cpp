#include "lumigauss/eval/multi_light_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {

MultiLightRenderer::MultiLightRenderer(const SurfelModel& model, RasterBackend backend,
                                       const SurfelSideRule& sides)
    : model_(model), renderer_(backend, sides) {}

void MultiLightRenderer::shade_pass(std::span<const ShCoeffs<float>> envs, const ViewNormals& normals,
                                    SurfelBatch<float>& batch) const {
    const std::size_t n = model_.size(), ch = 3 * envs.size();
    batch.channels = int(ch);
    batch.colors.resize(n * ch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            model_.transfer_channel0(true, i, pos);
            model_.transfer_channel0(false, i, neg);
            const Vec3f raw = model_.raw_albedo(i);
            const bool positive = normals.positive_side[i] != 0;
            for (std::size_t k = 0; k < envs.size(); ++k) {
                const Vec3f rgb = surfel_colour_shadowed(envs[k], raw, pos, neg, positive);
                for (int c = 0; c < 3; ++c) batch.colors[i * ch + 3 * k + std::size_t(c)] = rgb[c];
            }
        }
    });
}

std::vector<Image> MultiLightRenderer::render_shadowed(const Camera& camera,
                                                       std::span<const ShCoeffs<float>> envs) {
    std::vector<Image> out;
    out.reserve(envs.size());
    for (std::size_t first = 0; first < envs.size(); first += kLightsPerPass) {
        const std::span<const ShCoeffs<float>> pass =
            envs.subspan(first, std::min<std::size_t>(kLightsPerPass, envs.size() - first));
        const SurfelShader shade = [&](const ViewNormals& normals, SurfelBatch<float>& batch) {
            shade_pass(pass, normals, batch);
        };
        // The view's normals and geometry once; the later passes only re-shade and rasterize.
        const RasterImages<float>& images =
            first == 0 ? renderer_.render(model_, camera, shade) : renderer_.recolour(camera, shade);
        for (std::size_t k = 0; k < pass.size(); ++k) out.push_back(raster_channels(images, int(3 * k), 3));
    }
    return out;
}

}  // namespace lumigauss
