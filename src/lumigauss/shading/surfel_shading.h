#pragma once
// Per-surfel colour and per-surfel transfer-function losses of the official LumiGauss, with VJPs
// (LG_HD, templated on the scalar, no allocation: the same code runs in the CPU and CUDA backends).
//
// Parameters of one surfel (research/lumigauss_official.md 2.1):
//   * raw albedo a (3 floats), activated as max(0, Y00 * a + 0.5) (`get_albedo`; no upper clamp);
//   * two transfer sets of 9 SH scalars, "positive" and "negative" side. The official code stores 27 floats
//     per side but only ever reads channel 0 ("no color bleeding", 2.1 and 11.1), so here a transfer set is
//     the 9 scalars of that channel; the caller extracts them from its storage. The positive set is used
//     when the surfel's local +z already faces the camera (multiplier +1), the negative one otherwise.
//   * the normal used below is the camera-flipped unit normal multiplier * R[:,2] (2.1), the one the
//     official `eval_sh_hemisphere` receives. The multiplier itself carries no gradient.
//
// Colour (3.2-3.4), per channel c, for H_c = E_c(n) (unshadowed) or S_c = sum_j T_j L_cj (shadowed):
//   rgb_c = max(0, albedo_c * max(H_c, 1e-5)^(1/2.2)).
// Gradient conventions follow shading/sh.h: coefficient gradients (transfer sets, environment) are ADDED
// into caller-provided outputs; per-call vector gradients (raw albedo, normal) are returned by value.
#include <cmath>

#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

namespace surfel_const {
// 3.4 step 1: clamp_min replaced a ReLU in the official "fix instabilities" commit, so that the power below
// never sees 0 (its derivative is infinite there).
inline constexpr double kIrradianceFloor = 1e-5;
inline constexpr double kInvGamma = 1.0 / 2.2;  // 3.4 step 2: pure power law, not the sRGB curve
inline constexpr double kAlbedoOffset = 0.5;    // get_albedo = max(0, Y00 * a + 0.5)
inline constexpr double kDirectionEps = 1e-7;   // 4.2: u / (|u| + 1e-7)
inline constexpr int kTransferSamples = 25;     // 4.2: directions per surfel per iteration
}  // namespace surfel_const

// Colour layout of the one-pass rasteriser: shadowed RGB in channels 0..2, unshadowed RGB in 3..5.
inline constexpr int kSurfelColourChannels = 6;
inline constexpr int kShadowedOffset = 0;
inline constexpr int kUnshadowedOffset = 3;

// ---------------------------------------------------------------------------------------------------------
// Building blocks

// The transfer set of the side facing the camera (works for const and mutable arrays alike).
template <typename P>
LG_HD constexpr P* select_transfer(bool positive_side, P* positive, P* negative) {
    return positive_side ? positive : negative;
}

template <typename T>
LG_HD constexpr Vec3<T> albedo_activation(Vec3<T> raw) {
    Vec3<T> r;
    for (int c = 0; c < 3; ++c) {
        const T v = T(sh_const::kY00) * raw[c] + T(surfel_const::kAlbedoOffset);
        r[c] = v <= T(0) ? T(0) : v;  // NaN passes through, as torch's clamp: the loss then reports it
    }
    return r;
}

// Gradient through the clamp passes only where the pre-activation is > 0 (ReLU-style; at exactly 0 the
// torch op could differ, a measure-zero case).
template <typename T>
LG_HD constexpr Vec3<T> albedo_activation_vjp(Vec3<T> raw, Vec3<T> g_albedo) {
    Vec3<T> g;
    for (int c = 0; c < 3; ++c) {
        const T v = T(sh_const::kY00) * raw[c] + T(surfel_const::kAlbedoOffset);
        g[c] = v > T(0) ? T(sh_const::kY00) * g_albedo[c] : T(0);
    }
    return g;
}

// max(H, 1e-5)^(1/2.2): the official "intensity", also what the scripts rasterise as an irradiance image.
template <typename T>
LG_HD inline T light_intensity(T h) {
    const T floor = T(surfel_const::kIrradianceFloor);
    return std::pow(h < floor ? floor : h, T(surfel_const::kInvGamma));  // NaN passes through
}

// 3.4, in the official order: clamp_min(H, 1e-5) -> ^(1/2.2) -> * albedo -> clamp_min(0).
template <typename T>
LG_HD inline T light_to_colour(T h, T albedo) {
    const T p = albedo * light_intensity(h);
    return p < T(0) ? T(0) : p;  // NaN passes through
}

// Backward of light_to_colour; returns dL/dh and adds dL/dalbedo into g_albedo. torch's clamp_min passes
// the gradient where input >= bound; since albedo >= 0 and the intensity > 0, the outer clamp is never
// active except at exactly zero.
template <typename T>
LG_HD inline T light_to_colour_vjp(T h, T albedo, T g_rgb, T& g_albedo) {
    const T floor = T(surfel_const::kIrradianceFloor);
    const T intensity = light_intensity(h);
    const T g_p = albedo * intensity >= T(0) ? g_rgb : T(0);
    g_albedo += g_p * intensity;
    if (!(h >= floor)) return T(0);  // clamped: no gradient to the light
    // d/dh h^(1/2.2) = (1/2.2) h^(1/2.2) / h, with h >= 1e-5 here
    return g_p * albedo * T(surfel_const::kInvGamma) * intensity / h;
}

// Applies 3.4 to a light vector (three channels) and writes the colour.
template <typename T>
LG_HD inline Vec3<T> lights_to_colour(Vec3<T> light, Vec3<T> albedo) {
    return {light_to_colour(light.x, albedo.x), light_to_colour(light.y, albedo.y),
            light_to_colour(light.z, albedo.z)};
}

// Backward of lights_to_colour: returns dL/dlight, adds into g_albedo.
template <typename T>
LG_HD inline Vec3<T> lights_to_colour_vjp(Vec3<T> light, Vec3<T> albedo, Vec3<T> g_rgb, Vec3<T>& g_albedo) {
    Vec3<T> g_light;
    for (int c = 0; c < 3; ++c) g_light[c] = light_to_colour_vjp(light[c], albedo[c], g_rgb[c], g_albedo[c]);
    return g_light;
}

// ---------------------------------------------------------------------------------------------------------
// Colour of one surfel under one photo's environment (env = radiance SH L_cj, after the training noise of
// 3.5, which the caller adds once and shares between both modes).

// Unshadowed: albedo * max(E(n), 1e-5)^(1/2.2). `normal` is the camera-flipped unit normal.
template <typename T>
LG_HD inline Vec3<T> surfel_colour_unshadowed(const ShCoeffs<T>& env, Vec3<T> albedo_raw, Vec3<T> normal) {
    return lights_to_colour(irradiance(env, normal), albedo_activation(albedo_raw));
}

// Shadowed: albedo * max(T_side . L_c, 1e-5)^(1/2.2). No dependence on the normal (3.3).
template <typename T>
LG_HD inline Vec3<T> surfel_colour_shadowed(const ShCoeffs<T>& env, Vec3<T> albedo_raw,
                                            const T transfer_pos[kShCount], const T transfer_neg[kShCount],
                                            bool positive_side) {
    const T* transfer = select_transfer(positive_side, transfer_pos, transfer_neg);
    return lights_to_colour(shadowed_radiance(transfer, env), albedo_activation(albedo_raw));
}

// Both modes at once, in the rasteriser's 6-channel layout (shadowed RGB, then unshadowed RGB).
template <typename T>
LG_HD inline void surfel_colour_both(const ShCoeffs<T>& env, Vec3<T> albedo_raw, Vec3<T> normal,
                                     const T transfer_pos[kShCount], const T transfer_neg[kShCount],
                                     bool positive_side, T out[kSurfelColourChannels]) {
    const Vec3<T> s = surfel_colour_shadowed(env, albedo_raw, transfer_pos, transfer_neg, positive_side);
    const Vec3<T> u = surfel_colour_unshadowed(env, albedo_raw, normal);
    for (int c = 0; c < 3; ++c) {
        out[kShadowedOffset + c] = s[c];
        out[kUnshadowedOffset + c] = u[c];
    }
}

// Per-surfel gradients returned by the colour VJPs (the coefficient gradients are accumulated instead).
template <typename T>
struct SurfelColourGrad {
    Vec3<T> albedo_raw{};  // through albedo_activation
    Vec3<T> normal{};      // w.r.t. the camera-flipped unit normal; the caller chains to the quaternion
};

// Backward of surfel_colour_unshadowed. The official code does NOT detach the normal here (only inside the
// physical losses, 4.2 / 11.6), so the unshadowed photometric loss reaches the rotations.
template <typename T>
LG_HD inline SurfelColourGrad<T> surfel_colour_unshadowed_vjp(const ShCoeffs<T>& env, Vec3<T> albedo_raw,
                                                              Vec3<T> normal, Vec3<T> g_rgb,
                                                              ShCoeffs<T>& g_env) {
    const Vec3<T> light = irradiance(env, normal);
    Vec3<T> g_albedo{};
    const Vec3<T> g_light = lights_to_colour_vjp(light, albedo_activation(albedo_raw), g_rgb, g_albedo);
    irradiance_vjp_coeffs(normal, g_light, g_env);
    return {albedo_activation_vjp(albedo_raw, g_albedo), irradiance_vjp_normal(env, normal, g_light)};
}

// Backward of surfel_colour_shadowed: only the selected transfer set receives gradient; normal gradient 0.
template <typename T>
LG_HD inline SurfelColourGrad<T> surfel_colour_shadowed_vjp(const ShCoeffs<T>& env, Vec3<T> albedo_raw,
                                                            const T transfer_pos[kShCount],
                                                            const T transfer_neg[kShCount],
                                                            bool positive_side, Vec3<T> g_rgb,
                                                            T g_transfer_pos[kShCount],
                                                            T g_transfer_neg[kShCount], ShCoeffs<T>& g_env) {
    const T* transfer = select_transfer(positive_side, transfer_pos, transfer_neg);
    T* g_transfer = select_transfer(positive_side, g_transfer_pos, g_transfer_neg);
    const Vec3<T> light = shadowed_radiance(transfer, env);
    Vec3<T> g_albedo{};
    const Vec3<T> g_light = lights_to_colour_vjp(light, albedo_activation(albedo_raw), g_rgb, g_albedo);
    shadowed_radiance_vjp(transfer, env, g_light, g_transfer, g_env);
    return {albedo_activation_vjp(albedo_raw, g_albedo), Vec3<T>{}};
}

// Backward of surfel_colour_both. g_out is dL/d(6 channels); the albedo gradient sums both modes.
template <typename T>
LG_HD inline SurfelColourGrad<T> surfel_colour_both_vjp(const ShCoeffs<T>& env, Vec3<T> albedo_raw,
                                                        Vec3<T> normal, const T transfer_pos[kShCount],
                                                        const T transfer_neg[kShCount], bool positive_side,
                                                        const T g_out[kSurfelColourChannels],
                                                        T g_transfer_pos[kShCount],
                                                        T g_transfer_neg[kShCount], ShCoeffs<T>& g_env) {
    const Vec3<T> g_s{g_out[kShadowedOffset], g_out[kShadowedOffset + 1], g_out[kShadowedOffset + 2]};
    const Vec3<T> g_u{g_out[kUnshadowedOffset], g_out[kUnshadowedOffset + 1], g_out[kUnshadowedOffset + 2]};
    const SurfelColourGrad<T> gs =
        surfel_colour_shadowed_vjp(env, albedo_raw, transfer_pos, transfer_neg, positive_side, g_s,
                                   g_transfer_pos, g_transfer_neg, g_env);
    const SurfelColourGrad<T> gu = surfel_colour_unshadowed_vjp(env, albedo_raw, normal, g_u, g_env);
    return {gs.albedo_raw + gu.albedo_raw, gu.normal};
}

// ---------------------------------------------------------------------------------------------------------
// Physical losses on the transfer function (4.2, official `compute_sh_gauss_losses`).
//
// For each surfel, with its camera-selected transfer T (select_transfer) and its camera-flipped normal n,
// and each of its sampled directions w: t = sum_j T_j Y_j(w), c = max(0, n.w).
//   l_[0,1]       = mean_{t<0} t^2 + mean_{t>1} (t-1)^2   (each mean over the violating samples only)
//   l_consistency = mean (t - c)^2
//   l_shadow      = mean max(0, t - c)^2
// The official means run over ALL samples of ALL surfels at once (the tensors are flattened with
// view(-1)), not per surfel. So a surfel contributes sums and counts (TransferLossSums), the caller
// reduces them over every surfel, and turns the totals into losses (transfer_losses) and into the
// per-sum gradient scales (transfer_loss_scales) fed to transfer_loss_vjp.
// The normal is DETACHED in the official code (4.2, added in its "fix instabilities" commit), so these
// losses give no normal gradient and no VJP for it exists here.

// A direction the official way: u ~ Uniform([-1,1]^3), then u / (|u| + 1e-7). Cube-projected, full sphere,
// not uniform on the sphere (4.2). The caller owns the RNG and passes u.
template <typename T>
LG_HD inline Vec3<T> cube_normalized_direction(Vec3<T> u) {
    return u / (length(u) + T(surfel_const::kDirectionEps));
}

template <typename T>
struct TransferLossSums {
    T below_sq{};        // sum of t^2 over samples with t < 0
    T above_sq{};        // sum of (t - 1)^2 over samples with t > 1
    T consistency_sq{};  // sum of (t - c)^2 over all samples
    T shadow_sq{};       // sum of max(0, t - c)^2 over all samples
    long long below_count{};
    long long above_count{};
    long long samples{};

    LG_HD constexpr TransferLossSums& operator+=(const TransferLossSums& o) {
        below_sq += o.below_sq, above_sq += o.above_sq;
        consistency_sq += o.consistency_sq, shadow_sq += o.shadow_sq;
        below_count += o.below_count, above_count += o.above_count, samples += o.samples;
        return *this;
    }
};

// The three official loss values (unweighted).
template <typename T>
struct TransferLosses {
    T range01{};
    T consistency{};
    T shadow{};
};

// Loss weights (4.5: lambda_[0,1] = 0.001, lambda_cons = 10 on NeRF-OSR, lambda_shadow = 10 in stage 3).
template <typename T>
struct TransferLossWeights {
    T range01{};
    T consistency{};
    T shadow{};
};

// d(weighted total loss) / d(each field of the reduced TransferLossSums).
template <typename T>
struct TransferLossScales {
    T below_sq{};
    T above_sq{};
    T consistency_sq{};
    T shadow_sq{};
};

// Transfer value t and clamped-cosine target c for one direction.
template <typename T>
LG_HD constexpr void transfer_sample(const T transfer[kShCount], Vec3<T> normal, Vec3<T> dir, T& t, T& c) {
    T y[kShCount];
    sh_basis(dir, y);
    t = T(0);
    for (int k = 0; k < kShCount; ++k) t += transfer[k] * y[k];
    const T d = dot(normal, dir);
    c = d > T(0) ? d : T(0);
}

// One surfel's contribution. dirs: its n_dirs sampled unit directions (cube_normalized_direction).
template <typename T>
LG_HD constexpr TransferLossSums<T> transfer_loss_sums(const T transfer[kShCount], Vec3<T> normal,
                                                       const Vec3<T>* dirs, int n_dirs) {
    TransferLossSums<T> s;
    for (int i = 0; i < n_dirs; ++i) {
        T t, c;
        transfer_sample(transfer, normal, dirs[i], t, c);
        if (t < T(0)) s.below_sq += t * t, ++s.below_count;
        if (t > T(1)) s.above_sq += (t - 1) * (t - 1), ++s.above_count;
        const T diff = t - c;
        s.consistency_sq += diff * diff;
        if (diff > T(0)) s.shadow_sq += diff * diff;
    }
    s.samples = n_dirs;
    return s;
}

// Loss values from the totals over all surfels. penalize_outside_range adds a term only if it has
// violating samples; the means of consistency and shadow are over every sample.
template <typename T>
LG_HD constexpr TransferLosses<T> transfer_losses(const TransferLossSums<T>& total) {
    TransferLosses<T> l;
    if (total.below_count > 0) l.range01 += total.below_sq / T(total.below_count);
    if (total.above_count > 0) l.range01 += total.above_sq / T(total.above_count);
    if (total.samples > 0) {
        l.consistency = total.consistency_sq / T(total.samples);
        l.shadow = total.shadow_sq / T(total.samples);
    }
    return l;
}

template <typename T>
LG_HD constexpr T weighted_transfer_loss(const TransferLosses<T>& l, const TransferLossWeights<T>& w) {
    return w.range01 * l.range01 + w.consistency * l.consistency + w.shadow * l.shadow;
}

// The counts are piecewise constant in the transfer, so the gradient of each mean is 1/count times the
// gradient of its sum.
template <typename T>
LG_HD constexpr TransferLossScales<T> transfer_loss_scales(const TransferLossSums<T>& total,
                                                           const TransferLossWeights<T>& w) {
    TransferLossScales<T> s;
    if (total.below_count > 0) s.below_sq = w.range01 / T(total.below_count);
    if (total.above_count > 0) s.above_sq = w.range01 / T(total.above_count);
    if (total.samples > 0) {
        s.consistency_sq = w.consistency / T(total.samples);
        s.shadow_sq = w.shadow / T(total.samples);
    }
    return s;
}

// Backward for one surfel: g_transfer[k] += dL/dT_k of the weighted loss, given the scales from the
// reduced totals. Same directions as the forward. The normal is detached (see above): no gradient.
template <typename T>
LG_HD constexpr void transfer_loss_vjp(const T transfer[kShCount], Vec3<T> normal, const Vec3<T>* dirs,
                                       int n_dirs, const TransferLossScales<T>& scales,
                                       T g_transfer[kShCount]) {
    for (int i = 0; i < n_dirs; ++i) {
        T t, c;
        transfer_sample(transfer, normal, dirs[i], t, c);
        const T diff = t - c;
        T g_t = 2 * scales.consistency_sq * diff;
        if (t < T(0)) g_t += 2 * scales.below_sq * t;
        if (t > T(1)) g_t += 2 * scales.above_sq * (t - 1);
        if (diff > T(0)) g_t += 2 * scales.shadow_sq * diff;
        T y[kShCount];
        sh_basis(dirs[i], y);
        for (int k = 0; k < kShCount; ++k) g_transfer[k] += g_t * y[k];
    }
}

}  // namespace lumigauss
