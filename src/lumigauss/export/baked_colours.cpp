#include "lumigauss/export/baked_colours.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

BakeShading parse_bake_shading(const std::string& text) {
    if (text == "shadowed") return BakeShading::Shadowed;
    if (text == "unshadowed") return BakeShading::Unshadowed;
    throw Error("--shading '" + text + "': use shadowed or unshadowed");
}

std::vector<float> bake_surfel_colours(const SurfelModel& model, const ShCoeffs<float>& env,
                                       BakeShading shading) {
    const std::size_t n = model.size();
    std::vector<float> out(3 * n);
    const auto& a = model.param(ModelParam::Albedo);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const Vec3f albedo{a[3 * i], a[3 * i + 1], a[3 * i + 2]};
            Vec3f rgb;
            if (shading == BakeShading::Shadowed) {
                model.transfer_channel0(true, i, pos);
                model.transfer_channel0(false, i, neg);
                rgb = surfel_colour_shadowed(env, albedo, pos, neg, true);
            } else {
                rgb = surfel_colour_unshadowed(env, albedo, model.normal(i));
            }
            for (int c = 0; c < 3; ++c) out[3 * i + std::size_t(c)] = std::clamp(rgb[c], 0.0f, 1.0f);
        }
    });
    return out;
}

}  // namespace lumigauss
