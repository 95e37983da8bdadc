#pragma once
// Per-surfel shading terms from a degree-2 SH environment (LG_HD, templated on the scalar):
//   * unshadowed: Ramamoorthi-Hanrahan irradiance, exactly the official `eval_sh_hemisphere`;
//   * the SH projection of the clamped cosine lobe (what a fully unoccluded transfer function should be);
//   * shadowed: the PRT transfer dot product, exactly the official `eval_sh_shadowed`.
//
// Normalisation (research/lumigauss_official.md 3.2, nerfosr_protocol_and_data.md 3.3):
//   irradiance(L, n) = E(n) = sum_lm A_l L_lm Y_lm(n),  A_0 = pi, A_1 = 2pi/3, A_2 = pi/4,
// i.e. the physical irradiance  E(n) = integral L(w) max(0, n.w) dw  of the SH environment, NOT divided by
// pi. A Lambertian surface of albedo rho reflects rho * E / pi; LumiGauss (and NeRF-OSR) instead shade with
// albedo * max(E, 1e-5)^(1/2.2), with no 1/pi -- that step belongs to the caller, not here.
// The A_l are the Funk-Hecke eigenvalues of max(0, cos) for l <= 2, so the formula is exact for an
// environment that is itself of degree <= 2 (the lobe's l = 4, 6, ... bands meet zero coefficients); for a
// real environment it is the order-2 truncation (a few percent off for sharp suns).
//
// Constants: the official code uses the RH paper's rounded literals c1..c5 = 0.429043, 0.511664, 0.743125,
// 0.886227, 0.247708. We derive them from A_l and the full-precision basis constants instead (they differ
// by <= 1.3e-6 relative), so that irradiance(L, n) == sum_k L_k * cosine_lobe_sh(n)_k to rounding: the
// unshadowed and shadowed modes then live on exactly the same scale.
#include <numbers>

#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

namespace rh_const {
inline constexpr double kA0 = std::numbers::pi;
inline constexpr double kA1 = 2.0 * std::numbers::pi / 3.0;
inline constexpr double kA2 = std::numbers::pi / 4.0;
inline constexpr double kC1 = kA2 * sh_const::kY22;        // 0.4290428
inline constexpr double kC2 = kA1 * sh_const::kY1 / 2.0;   // 0.5116634
inline constexpr double kC3 = 3.0 * kA2 * sh_const::kY20;  // 0.7431239
inline constexpr double kC4 = kA0 * sh_const::kY00;        // 0.8862269
inline constexpr double kC5 = kA2 * sh_const::kY20;        // 0.2477080
}  // namespace rh_const

// E(n) per channel (see the normalisation above); n a unit normal.
template <typename T>
LG_HD constexpr Vec3<T> irradiance(const ShCoeffs<T>& sh, Vec3<T> n) {
    using namespace rh_const;
    const T x = n.x, y = n.y, z = n.z;
    const Vec3<T>* L = sh.c;
    // Same term grouping as eval_sh_hemisphere.
    Vec3<T> e = T(kC1) * (x * x - y * y) * L[8];
    e += T(kC3) * z * z * L[6];
    e += T(kC4) * L[0];
    e += -T(kC5) * L[6];
    e += 2 * T(kC1) * (x * y * L[4] + x * z * L[7] + y * z * L[5]);
    e += 2 * T(kC2) * (x * L[3] + y * L[1] + z * L[2]);
    return e;
}

// SH coefficients of the clamped cosine lobe max(0, n.w): out[k] = A_l(k) * Y_k(n) (Funk-Hecke; exact for
// bands l <= 2). sum_k L_k out[k] == irradiance(L, n).
template <typename T>
LG_HD constexpr void cosine_lobe_sh(Vec3<T> n, T out[kShCount]) {
    sh_basis(n, out);
    out[0] *= T(rh_const::kA0);
    for (int k = 1; k < 4; ++k) out[k] *= T(rh_const::kA1);
    for (int k = 4; k < kShCount; ++k) out[k] *= T(rh_const::kA2);
}

// Backward of irradiance w.r.t. the coefficients: g_sh.c[k] += dE/dL_k * g_out (accumulates). dE/dL_k is
// the cosine lobe, the same weight for all three channels.
template <typename T>
LG_HD constexpr void irradiance_vjp_coeffs(Vec3<T> n, Vec3<T> g_out, ShCoeffs<T>& g_sh) {
    T w[kShCount];
    cosine_lobe_sh(n, w);
    for (int k = 0; k < kShCount; ++k) g_sh.c[k] += w[k] * g_out;
}

// Backward of irradiance w.r.t. the normal (returned).
template <typename T>
LG_HD constexpr Vec3<T> irradiance_vjp_normal(const ShCoeffs<T>& sh, Vec3<T> n, Vec3<T> g_out) {
    using namespace rh_const;
    const T x = n.x, y = n.y, z = n.z;
    T l[kShCount];  // the per-coefficient gradient, reduced over the channels
    for (int k = 0; k < kShCount; ++k) l[k] = dot(g_out, sh.c[k]);
    const T c1 = T(kC1), c2 = T(kC2);
    const T gx = 2 * c1 * (l[8] * x + l[4] * y + l[7] * z) + 2 * c2 * l[3];
    const T gy = 2 * c1 * (-l[8] * y + l[4] * x + l[5] * z) + 2 * c2 * l[1];
    const T gz = 2 * T(kC3) * l[6] * z + 2 * c1 * (l[7] * x + l[5] * y) + 2 * c2 * l[2];
    return {gx, gy, gz};
}

// Shadowed (PRT) radiance transfer: S_c = sum_k transfer[k] * L_{c,k}, one transfer vector broadcast over the
// three channels (the official code uses the channel-0 row of the transfer SH). If transfer is the cosine
// lobe of n, this equals irradiance(L, n).
template <typename T>
LG_HD constexpr Vec3<T> shadowed_radiance(const T transfer[kShCount], const ShCoeffs<T>& env) {
    Vec3<T> s{};
    for (int k = 0; k < kShCount; ++k) s += transfer[k] * env.c[k];
    return s;
}

// Backward of shadowed_radiance: g_transfer[k] += <g_out, L_k>, g_env.c[k] += transfer[k] * g_out
// (both accumulate).
template <typename T>
LG_HD constexpr void shadowed_radiance_vjp(const T transfer[kShCount], const ShCoeffs<T>& env, Vec3<T> g_out,
                                           T g_transfer[kShCount], ShCoeffs<T>& g_env) {
    for (int k = 0; k < kShCount; ++k) {
        g_transfer[k] += dot(g_out, env.c[k]);
        g_env.c[k] += transfer[k] * g_out;
    }
}

// The constant environment whose irradiance is `e` for every normal: E = A_0 Y_00 L_00 = C4 L_00 (the other
// coefficients 0). A neutral grey sky for inspecting albedo, and the start of a light fit with no prior.
template <typename T>
LG_HD constexpr ShCoeffs<T> uniform_irradiance_environment(T e = T(1)) {
    ShCoeffs<T> sh{};
    const T l00 = e / T(rh_const::kC4);
    sh.c[0] = Vec3<T>{l00, l00, l00};
    return sh;
}

}  // namespace lumigauss
