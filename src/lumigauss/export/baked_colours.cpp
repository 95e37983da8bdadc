#include "lumigauss/export/baked_colours.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

BakeShading parse_bake_shading(const std::string& text) {
    if (text == "shadowed") return BakeShading::Shadowed;
    if (text == "unshadowed") return BakeShading::Unshadowed;
    throw Error("--shading '" + text + "': use shadowed or unshadowed");
}

SurfelSides bake_surfel_sides(const SurfelModel& model, const ShCoeffs<float>& env, BakeShading shading) {
    const std::size_t n = model.size();
    SurfelSides sides{std::vector<float>(3 * n), std::vector<float>(3 * n)};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const Vec3f albedo = model.raw_albedo(i);
            Vec3f front, back;
            if (shading == BakeShading::Shadowed) {
                model.transfer_channel0(true, i, pos);
                model.transfer_channel0(false, i, neg);
                front = surfel_colour_shadowed(env, albedo, pos, neg, true);
                back = surfel_colour_shadowed(env, albedo, pos, neg, false);
            } else {
                front = surfel_colour_unshadowed(env, albedo, model.normal(i));
                back = surfel_colour_unshadowed(env, albedo, -model.normal(i));
            }
            for (int c = 0; c < 3; ++c) {
                sides.positive[3 * i + std::size_t(c)] = front[c];
                sides.negative[3 * i + std::size_t(c)] = back[c];
            }
        }
    });
    return sides;
}

std::vector<float> seen_side_colours(const SurfelModel& model, const SurfelSides& sides,
                                     std::span<const Vec3d> cameras) {
    const std::size_t n = model.size();
    if (sides.positive.size() != 3 * n || sides.negative.size() != 3 * n)
        throw Error("seen_side_colours: the baked sides do not match the model");
    std::vector<float> out(sides.positive);
    const auto& xyz = model.param(ModelParam::Xyz);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            const Vec3d centre{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
            const Vec3d normal = model.normal(i).cast<double>();
            double front = 0, back = 0;
            for (const Vec3d& camera : cameras) {
                const Vec3d to_camera = camera - centre;
                const double distance = length(to_camera);
                if (!(distance > 0)) continue;
                const double cosine = dot(to_camera, normal) / distance;
                (cosine >= 0 ? front : back) += std::abs(cosine);
            }
            if (back > front)
                for (int c = 0; c < 3; ++c)
                    out[3 * i + std::size_t(c)] = sides.negative[3 * i + std::size_t(c)];
        }
    });
    return out;
}

}  // namespace lumigauss
