#pragma once
// Real spherical harmonics of degree <= 2, written once for the CPU and CUDA backends (LG_HD, templated on
// the scalar: float in renderers, double in references and finite-difference tests).
//
// Basis, order and signs are those of the official LumiGauss `eval_sh_point` and NeRF-OSR `illuminate_vec`
// (research/lumigauss_official.md 3.1): no Condon-Shortley phase, polar axis = z of the frame the directions
// live in. Index k = 0..8 is (l,m) = (0,0),(1,-1),(1,0),(1,1),(2,-2),(2,-1),(2,0),(2,1),(2,2):
//   Y0 = 0.282095            Y1 = 0.488603 y        Y2 = 0.488603 z        Y3 = 0.488603 x
//   Y4 = 1.092548 xy         Y5 = 1.092548 yz       Y6 = 0.315392 (3z^2-1)
//   Y7 = 1.092548 xz         Y8 = 0.546274 (x^2-y^2)
// We use the full-precision values of these constants (below); the 6-digit literals of the official code
// differ from them by less than 1e-6 relative, far below float noise.
//
// The functions are polynomials in (x, y, z) exactly as written above (note 3z^2-1, not 2z^2-x^2-y^2), so
// their VJPs with respect to the direction are the gradients of those polynomials; callers feed unit
// directions and chain through their own normalisation.
//
// Gradient convention (shared by every *_vjp in shading/): gradients of coefficients, which are shared by
// many evaluations (one environment for all surfels of an image), are ADDED into the output the caller
// provides; gradients of directions/normals are returned by value.
#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

inline constexpr int kShCount = 9;  // degree 2: (2+1)^2 coefficients

namespace sh_const {
inline constexpr double kY00 = 0.28209479177387814;  // 1 / (2 sqrt(pi))
inline constexpr double kY1 = 0.4886025119029199;    // sqrt(3) / (2 sqrt(pi))
inline constexpr double kY2 = 1.0925484305920792;    // sqrt(15) / (2 sqrt(pi)): xy, yz, xz
inline constexpr double kY20 = 0.31539156525252005;  // sqrt(5) / (4 sqrt(pi))
inline constexpr double kY22 = 0.5462742152960396;   // sqrt(15) / (4 sqrt(pi))
}  // namespace sh_const

// Nine RGB coefficients. For an environment these are radiance coefficients L_lm (the SH text files);
// for a surfel's transfer function they are broadcast over the channels by the caller.
template <typename T>
struct ShCoeffs {
    Vec3<T> c[kShCount]{};

    template <typename U>
    LG_HD constexpr ShCoeffs<U> cast() const {
        ShCoeffs<U> r;
        for (int k = 0; k < kShCount; ++k) r.c[k] = c[k].template cast<U>();
        return r;
    }
};

// out[k] = Y_k(dir).
template <typename T>
LG_HD constexpr void sh_basis(Vec3<T> dir, T out[kShCount]) {
    using namespace sh_const;
    const T x = dir.x, y = dir.y, z = dir.z;
    out[0] = T(kY00);
    out[1] = T(kY1) * y;
    out[2] = T(kY1) * z;
    out[3] = T(kY1) * x;
    out[4] = T(kY2) * x * y;
    out[5] = T(kY2) * y * z;
    out[6] = T(kY20) * (3 * z * z - 1);
    out[7] = T(kY2) * x * z;
    out[8] = T(kY22) * (x * x - y * y);
}

// Backward of sh_basis: returns sum_k g[k] * grad Y_k(dir).
template <typename T>
LG_HD constexpr Vec3<T> sh_basis_vjp(Vec3<T> dir, const T g[kShCount]) {
    using namespace sh_const;
    const T x = dir.x, y = dir.y, z = dir.z;
    const T k1 = T(kY1), k2 = T(kY2);
    const T gx = k1 * g[3] + k2 * (g[4] * y + g[7] * z) + 2 * T(kY22) * g[8] * x;
    const T gy = k1 * g[1] + k2 * (g[4] * x + g[5] * z) - 2 * T(kY22) * g[8] * y;
    const T gz = k1 * g[2] + k2 * (g[5] * y + g[7] * x) + 6 * T(kY20) * g[6] * z;
    return {gx, gy, gz};
}

// Radiance in direction dir: sum_k c[k] Y_k(dir), per channel.
template <typename T>
LG_HD constexpr Vec3<T> eval_sh(const ShCoeffs<T>& sh, Vec3<T> dir) {
    T y[kShCount];
    sh_basis(dir, y);
    Vec3<T> r{};
    for (int k = 0; k < kShCount; ++k) r += y[k] * sh.c[k];
    return r;
}

// Backward of eval_sh w.r.t. the coefficients: g_sh.c[k] += Y_k(dir) * g_out (accumulates).
template <typename T>
LG_HD constexpr void eval_sh_vjp_coeffs(Vec3<T> dir, Vec3<T> g_out, ShCoeffs<T>& g_sh) {
    T y[kShCount];
    sh_basis(dir, y);
    for (int k = 0; k < kShCount; ++k) g_sh.c[k] += y[k] * g_out;
}

// Backward of eval_sh w.r.t. the direction (returned).
template <typename T>
LG_HD constexpr Vec3<T> eval_sh_vjp_dir(const ShCoeffs<T>& sh, Vec3<T> dir, Vec3<T> g_out) {
    T g[kShCount];
    for (int k = 0; k < kShCount; ++k) g[k] = dot(g_out, sh.c[k]);
    return sh_basis_vjp(dir, g);
}

}  // namespace lumigauss
