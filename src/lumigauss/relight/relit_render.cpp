#include "lumigauss/relight/relit_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {

static_assert(kRelitChannels <= kMaxChannels, "the CPU rasterizer blends at most kMaxChannels channels");

RelitRenderer::RelitRenderer(const SurfelModel& model, RasterBackend backend, const SurfelSideRule& sides)
    : model_(model), renderer_(backend, sides) {
    const std::size_t n = model.size();
    albedo_.resize(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f a = albedo_activation(model.raw_albedo(i));
        for (int c = 0; c < 3; ++c) albedo_[3 * i + std::size_t(c)] = a[c];
    }
}

void RelitRenderer::shade(const ShCoeffs<float>& env, const ViewNormals& normals, SurfelBatch<float>& batch) {
    const std::size_t n = model_.size();
    shade_surfels(model_, env, ShadingMode::Both, normals, shaded_);
    const std::size_t ch = std::size_t(kRelitChannels);
    batch.channels = kRelitChannels;
    batch.colors.resize(n * ch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            float* out = &batch.colors[i * ch];
            const float* both = &shaded_.colors[i * std::size_t(kSurfelColourChannels)];
            for (int c = 0; c < 3; ++c) {
                out[kRelitShadowed + c] = both[kShadowedOffset + c];
                out[kRelitUnshadowed + c] = both[kUnshadowedOffset + c];
                out[kRelitAlbedo + c] = albedo_[3 * i + std::size_t(c)];
            }
            model_.transfer_channel0(true, i, pos);
            model_.transfer_channel0(false, i, neg);
            const float* transfer = select_transfer(normals.positive_side[i] != 0, pos, neg);
            const Vec3f s = shadowed_radiance(transfer, env);
            const Vec3f u = irradiance(env, normals.normal[i]);
            for (int c = 0; c < 3; ++c) {
                out[kRelitIntensityShadowed + c] = light_intensity(s[c]);
                out[kRelitIntensityUnshadowed + c] = light_intensity(u[c]);
            }
        }
    });
}

const RasterImages<float>& RelitRenderer::render(const Camera& camera, const ShCoeffs<float>& env) {
    return renderer_.render(model_, camera, [&](const ViewNormals& normals, SurfelBatch<float>& batch) {
        shade(env, normals, batch);
    });
}

Image shadow_image(const Image& unshadowed, const Image& shadowed) {
    Image out(unshadowed.width, unshadowed.height, 1);
    for (std::size_t p = 0; p < out.pixels.size(); ++p) {
        const float* u = &unshadowed.pixels[3 * p];
        const float* s = &shadowed.pixels[3 * p];
        const float luma = 0.2126f * (u[0] - s[0]) + 0.7152f * (u[1] - s[1]) + 0.0722f * (u[2] - s[2]);
        out.pixels[p] = 1.0f - std::clamp(luma, 0.0f, 1000.0f);
    }
    return out;
}

float display_max(const std::vector<const Image*>& images) {
    float m = 1.0f;
    for (const Image* im : images)
        for (float v : im->pixels)
            if (v > m) m = v;  // NaN never compares greater
    return m;
}

Image divided(const Image& image, float divisor) {
    Image out = image;
    for (float& v : out.pixels) v /= divisor;
    return out;
}

Image over_background(const Image& colour, const Image& alpha, const Vec3f& background) {
    Image out = colour;
    for (std::size_t p = 0; p < alpha.pixels.size(); ++p)
        for (int c = 0; c < 3; ++c)
            out.pixels[3 * p + std::size_t(c)] += (1.0f - alpha.pixels[p]) * background[c];
    return out;
}

Image over_background_image(const Image& colour, const Image& alpha, const Image& background) {
    Image out = colour;
    for (std::size_t p = 0; p < alpha.pixels.size(); ++p)
        for (std::size_t c = 0; c < 3; ++c)
            out.pixels[3 * p + c] += (1.0f - alpha.pixels[p]) * background.pixels[3 * p + c];
    return out;
}

}  // namespace lumigauss
