#include "lumigauss/model/view_shading.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
int shading_channels(ShadingMode mode) {
    return mode == ShadingMode::Both ? kSurfelColourChannels : 3;
}

void compute_view_normals(const SurfelModel& model, const Camera& camera, ViewNormals& out,
                          const SurfelSideRule& rule) {
    const std::size_t n = model.size();
    out.normal.resize(n);
    out.positive_side.resize(n);
    const Mat3f w = camera.rotation.cast<float>();
    const Vec3f t = camera.translation.cast<float>();
    const auto& xyz = model.param(ModelParam::Xyz);
    const float grazing_sine = rule.grazing_sine();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const Vec3f axis = model.normal(i);
            const Vec3f p_view = w * Vec3f{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]} + t;
            const bool positive =
                sees_positive_side(-dot(w * axis, p_view), length(p_view), dot(axis, rule.up), grazing_sine);
            out.positive_side[i] = positive ? 1 : 0;
            out.normal[i] = positive ? axis : -axis;
        }
    });
}

void shade_surfels(const SurfelModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                   const ViewNormals& normals, SurfelBatch<float>& batch) {
    const std::size_t n = model.size();
    if (normals.normal.size() != n)
        throw Error("shade_surfels: normals were computed for another model size");
    const int channels = shading_channels(mode);
    batch.channels = channels;
    batch.colors.resize(n * std::size_t(channels));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            float* out = &batch.colors[i * std::size_t(channels)];
            const Vec3f albedo = model.raw_albedo(i);
            const bool positive = normals.positive_side[i] != 0;
            if (uses_shadowed(mode)) {
                model.transfer_channel0(true, i, pos);
                model.transfer_channel0(false, i, neg);
            }
            if (mode == ShadingMode::Both) {
                surfel_colour_both(env, albedo, normals.normal[i], pos, neg, positive, out);
                continue;
            }
            const Vec3f rgb = mode == ShadingMode::Unshadowed
                                  ? surfel_colour_unshadowed(env, albedo, normals.normal[i])
                                  : surfel_colour_shadowed(env, albedo, pos, neg, positive);
            for (int c = 0; c < 3; ++c) out[c] = rgb[c];
        }
    });
}

}  // namespace lumigauss
