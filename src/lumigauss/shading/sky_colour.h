#pragma once
// The colour of the sky seen along a ray, from a photo's environment SH, in the model's display space
// (research/sky_and_floaters.md 3.1-3.2). LG_HD, templated on the scalar: the same code serves training,
// rendering, the tests and any device backend.
//
// A surfel of albedo a under irradiance E is drawn as a * max(E, 1e-5)^(1/2.2) (surfel_shading.h): with the
// photo model pixel = (exposure * rho/pi * E)^(1/2.2), a = (rho/pi)^(1/2.2) and the SH carries the exposure.
// In the same photo, a pixel that sees the sky in direction d shows (exposure * L(d))^(1/2.2), so with the
// same SH the sky is
//     S_c(d) = min(1, max(L_c(d), kSkyRadianceFloor)^(1/2.2)),   L_c(d) = sum_k env.c[k][c] Y_k(d),
// clipped at 1 as a camera clips it. No free scale: the sky pins the gauge between albedo and light that the
// surfel pixels alone leave open.
//
// A degree-2 SH cannot draw a sky with a sun: the sun's lobe dominates it and rings negative 90 degrees away,
// where a camera sees bright sky. So the sky radiance may add a per-photo residual R (degree 4, sh_degree4.h)
// that only the sky sees, never the surfels' shading: L_c(d) + R_c(d). Penalised towards 0 in training, it
// takes what the lighting cannot hold, and the lighting keeps what the surfels need.
#include <cmath>

#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"
#include "lumigauss/shading/surfel_shading.h"

namespace lumigauss {

// Radiance below this is drawn as this (the power's derivative is infinite at 0); also where the SH dips
// below zero, which a degree-2 fit of a sky with a sun does at the horizon.
inline constexpr double kSkyRadianceFloor = 1e-4;

// Display-space sky colour of one channel from its radiance.
template <typename T>
LG_HD inline T sky_channel(T radiance) {
    const T floor = T(kSkyRadianceFloor);
    const T s = std::pow(radiance < floor ? floor : radiance, T(surfel_const::kInvGamma));
    return s > T(1) ? T(1) : s;
}

// d sky_channel / d radiance: 0 where the floor or the clip at 1 holds the colour.
template <typename T>
LG_HD inline T sky_channel_derivative(T radiance) {
    if (!(radiance > T(kSkyRadianceFloor))) return T(0);
    const T s = std::pow(radiance, T(surfel_const::kInvGamma));
    return s >= T(1) ? T(0) : T(surfel_const::kInvGamma) * s / radiance;
}

// The sky's radiance along the unit world direction `dir`: the environment, plus the residual if given.
template <typename T>
LG_HD inline Vec3<T> sky_radiance(const ShCoeffs<T>& env, const Sh4Coeffs<T>* residual, Vec3<T> dir) {
    if (residual == nullptr) return eval_sh(env, dir);
    T y[kSh4Count];
    sh4_basis(dir, y);
    Vec3<T> r{};
    for (int k = 0; k < kShCount; ++k) r += y[k] * (env.c[k] + residual->c[k]);
    for (int k = kShCount; k < kSh4Count; ++k) r += y[k] * residual->c[k];
    return r;
}

// How much of the sky a ray sees, from the sines of the ray's depression below the horizon (up . dir < 0)
// where the sky starts to fade (start_sine) and where it is gone (end_sine > start_sine): 1 above the
// start, linear to 0 at the end. In an outdoor photo the ground hides the lower half of the environment,
// so a pixel well below the horizon that the surfels leave uncovered is a hole in the ground, not sky:
// drawn with the environment's lower half, holes were painted by light that no photo constrains, and the
// learned lights grew a bright floor to paint them. Just below the horizon lies the far field (ground
// beyond the reconstruction, distant buildings), which the environment may keep drawing.
template <typename T>
LG_HD inline T sky_visibility(Vec3<T> up, T start_sine, T end_sine, Vec3<T> dir) {
    const T depression = -dot(up, dir);
    if (!(depression > start_sine)) return T(1);
    if (!(depression < end_sine)) return T(0);
    return (end_sine - depression) / (end_sine - start_sine);
}

// The ground drawn where the sky has faded below the horizon: a surface of (activated) albedo `albedo`
// facing the unit `up`, lit by the environment without shadows, as a surfel of the ground is drawn
// (surfel_shading.h). A hole in the ground seen from a new viewpoint is then drawn as ground, not black.
template <typename T>
LG_HD inline Vec3<T> ground_colour(const ShCoeffs<T>& env, Vec3<T> up, Vec3<T> albedo) {
    return lights_to_colour(irradiance(env, up), albedo);
}

// Display-space colour of a sky radiance.
template <typename T>
LG_HD inline Vec3<T> sky_colour_of(Vec3<T> radiance) {
    return {sky_channel(radiance.x), sky_channel(radiance.y), sky_channel(radiance.z)};
}

// The sky colour along the unit world direction `dir` (environment only).
template <typename T>
LG_HD inline Vec3<T> sky_colour(const ShCoeffs<T>& env, Vec3<T> dir) {
    return sky_colour_of(eval_sh(env, dir));
}

// d colour / d radiance applied to g (per channel).
template <typename T>
LG_HD inline Vec3<T> sky_colour_of_vjp(Vec3<T> radiance, Vec3<T> g) {
    return {g.x * sky_channel_derivative(radiance.x), g.y * sky_channel_derivative(radiance.y),
            g.z * sky_channel_derivative(radiance.z)};
}

// Adds dL/denv (and dL/dresidual when g_residual is given) for dL/dradiance = g of sky_radiance.
template <typename T>
LG_HD inline void sky_radiance_vjp(Vec3<T> dir, Vec3<T> g, ShCoeffs<T>& g_env, Sh4Coeffs<T>* g_residual) {
    if (g_residual == nullptr) return eval_sh_vjp_coeffs(dir, g, g_env);
    T y[kSh4Count];
    sh4_basis(dir, y);
    for (int k = 0; k < kShCount; ++k) g_env.c[k] += y[k] * g;
    for (int k = 0; k < kSh4Count; ++k) g_residual->c[k] += y[k] * g;
}

// Adds dL/denv for dL/dcolour = g of sky_colour(env, dir).
template <typename T>
LG_HD inline void sky_colour_vjp(const ShCoeffs<T>& env, Vec3<T> dir, Vec3<T> g, ShCoeffs<T>& g_env) {
    sky_radiance_vjp(dir, sky_colour_of_vjp(eval_sh(env, dir), g), g_env,
                     static_cast<Sh4Coeffs<T>*>(nullptr));
}

}  // namespace lumigauss
