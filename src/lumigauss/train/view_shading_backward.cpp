#include "lumigauss/train/view_shading_backward.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/shading/surfel_shading.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Surfels per chunk of the deterministic reductions: partial sums per chunk, added in chunk order.
constexpr std::size_t kChunk = 4096;

template <typename F>
void for_each_chunk(std::size_t n, F&& f) {
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t c = r.begin(); c < r.end(); ++c)
                              f(c, c * kChunk, std::min(n, (c + 1) * kChunk));
                      });
}

Vec4f raw_quaternion(const SurfelModel& model, std::size_t i) {
    const auto& q = model.param(ModelParam::Rotation);
    return {q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]};
}

// dL/d(raw quaternion) from dL/d(camera-flipped normal): n = flip * R(q/|q|)[:,2].
Vec4f normal_to_quaternion_grad(Vec4f raw, bool positive, Vec3f g_normal) {
    const Vec4f unit = normalize_quaternion(raw);
    Mat3f g_rot{};
    const float s = positive ? 1.0f : -1.0f;
    for (int a = 0; a < 3; ++a) g_rot.m[a][2] = s * g_normal[a];
    return normalize_quaternion_vjp(raw, rotation_from_unit_quaternion_vjp(unit, g_rot));
}

}  // namespace

ShCoeffs<float> shade_surfels_backward(GaussianModel& model, const ShCoeffs<float>& env, ShadingMode mode,
                                       const ViewNormals& normals, std::span<const float> g_colors) {
    const std::size_t n = model.size();
    const int channels = shading_channels(mode);
    if (normals.normal.size() != n || normals.positive_side.size() != n)
        throw Error("shade_surfels_backward: normals were computed for another model size");
    if (g_colors.size() != n * std::size_t(channels))
        throw Error("shade_surfels_backward: colour gradient has the wrong size");
    std::span<float> g_albedo = model.grad(ModelParam::Albedo);
    std::span<float> g_rot, g_pos, g_neg;
    if (uses_unshadowed(mode)) g_rot = model.grad(ModelParam::Rotation);
    if (uses_shadowed(mode)) {
        g_pos = model.grad(ModelParam::TransferPositive);
        g_neg = model.grad(ModelParam::TransferNegative);
    }
    const std::size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<ShCoeffs<double>> partial(chunks);
    for_each_chunk(n, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
        ShCoeffs<float> g_env_chunk{};
        float pos[kTransferCoeffs], neg[kTransferCoeffs];
        for (std::size_t i = begin; i < end; ++i) {
            const float* g = &g_colors[i * std::size_t(channels)];
            const Vec3f albedo = model.raw_albedo(i);
            const bool positive = normals.positive_side[i] != 0;
            const Vec3f normal = normals.normal[i];
            float gp[kTransferCoeffs]{}, gn[kTransferCoeffs]{};
            SurfelColourGrad<float> sg;
            if (uses_shadowed(mode)) {
                model.transfer_channel0(true, i, pos);
                model.transfer_channel0(false, i, neg);
            }
            if (mode == ShadingMode::Both) {
                sg = surfel_colour_both_vjp(env, albedo, normal, pos, neg, positive, g, gp, gn, g_env_chunk);
            } else if (mode == ShadingMode::Unshadowed) {
                sg = surfel_colour_unshadowed_vjp(env, albedo, normal, {g[0], g[1], g[2]}, g_env_chunk);
            } else {
                sg = surfel_colour_shadowed_vjp(env, albedo, pos, neg, positive, {g[0], g[1], g[2]}, gp, gn,
                                                g_env_chunk);
            }
            for (int c = 0; c < 3; ++c) g_albedo[3 * i + std::size_t(c)] += sg.albedo_raw[c];
            if (uses_unshadowed(mode)) {
                const Vec4f gq = normal_to_quaternion_grad(raw_quaternion(model, i), positive, sg.normal);
                for (int k = 0; k < 4; ++k) g_rot[4 * i + std::size_t(k)] += gq[k];
            }
            if (uses_shadowed(mode)) {
                // Channel 0 of the 27 stored floats: index 3k (see GaussianModel).
                for (int k = 0; k < kTransferCoeffs; ++k) {
                    g_pos[i * kTransferStored + std::size_t(3 * k)] += gp[k];
                    g_neg[i * kTransferStored + std::size_t(3 * k)] += gn[k];
                }
            }
        }
        partial[chunk] = g_env_chunk.cast<double>();
    });
    ShCoeffs<double> total{};
    for (const auto& p : partial)
        for (int k = 0; k < kShCount; ++k) total.c[k] = total.c[k] + p.c[k];
    return total.cast<float>();
}

}  // namespace lumigauss
