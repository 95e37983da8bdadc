#pragma once
// Per-pixel evaluation of one projected surfel (ray-splat intersection, low-pass filter, alpha) and its
// backward. Shared by the CPU rasterizer, the test reference and the CUDA backend.
#include <cmath>

#include "lumigauss/render/raster_constants.h"
#include "lumigauss/render/surfel_projection.h"

namespace lumigauss::raster {

template <typename T>
struct SplatSample {
    T alpha{};                   // min(kAlphaMax, opacity * gauss)
    T gauss{};                   // max of the object-space Gaussian and the screen-space filter
    T u{}, v{};                  // intersection in the surfel's (u, v) frame (object branch only)
    T z{};                       // depth of this contribution
    bool screen_branch = false;  // the screen low-pass filter won
    bool clamped = false;        // alpha hit kAlphaMax
};

// The pixel-surfel pair as the kernel sees it.
template <typename T>
struct SplatGeometry {
    Vec3<T> tu, tv, tw;
    Vec2<T> center;
    T opacity;
};

// Evaluates the surfel at pixel centre (px, py). Returns false when the pair does not contribute:
// the ray is parallel to the disk, the hit is nearer than the near plane, or alpha < kAlphaMin.
template <typename T>
LG_HD inline bool evaluate_splat(const SplatGeometry<T>& g, T px, T py, SplatSample<T>& s) {
    // The pixel's ray is the intersection of the planes x = px and y = py, pulled back to (u, v, 1).
    const Vec3<T> k = px * g.tw - g.tu;
    const Vec3<T> l = py * g.tw - g.tv;
    const Vec3<T> p = cross(k, l);
    if (p.z == T(0)) return false;
    s.u = p.x / p.z;
    s.v = p.y / p.z;
    const T rho_object = s.u * s.u + s.v * s.v;
    const T dx = g.center.x - px, dy = g.center.y - py;
    const T rho_screen = T(kFilterInvSquare) * (dx * dx + dy * dy);
    s.screen_branch = rho_screen < rho_object;
    const T rho = s.screen_branch ? rho_screen : rho_object;
    // The screen branch uses the centre depth (the pinned rasterizer of the official code): far from the
    // disk, or at grazing angles, the intersection depth is meaningless.
    s.z = s.screen_branch ? g.tw.z : g.tw.x * s.u + g.tw.y * s.v + g.tw.z;
    if (s.z < T(kNearPlane)) return false;
    s.gauss = std::exp(T(-0.5) * rho);
    const T a = g.opacity * s.gauss;
    s.clamped = a > T(kAlphaMax);
    s.alpha = s.clamped ? T(kAlphaMax) : a;
    return s.alpha >= T(kAlphaMin);
}

// Backward of evaluate_splat: adds the gradients from dL/dalpha and dL/dz to the surfel's accumulators.
// The alpha clamp is differentiated exactly (no gradient through a clamped alpha).
template <typename T>
LG_HD inline void evaluate_splat_vjp(const SplatGeometry<T>& g, T px, T py, const SplatSample<T>& s,
                                     T g_alpha, T g_z, ProjectedSurfelGrad<T>& acc, T& g_opacity) {
    if (s.clamped) g_alpha = T(0);
    g_opacity += s.gauss * g_alpha;
    const T g_gauss = g.opacity * g_alpha;
    if (s.screen_branch) {
        // gauss = exp(-|c - pix|^2)  =>  d gauss / d c = -2 (c - pix) gauss
        const T k2 = T(kFilterInvSquare) * s.gauss * g_gauss;
        acc.center.x -= k2 * (g.center.x - px);
        acc.center.y -= k2 * (g.center.y - py);
        acc.tw.z += g_z;
        return;
    }
    const Vec3<T> k = px * g.tw - g.tu;
    const Vec3<T> l = py * g.tw - g.tv;
    const Vec3<T> p = cross(k, l);
    // gauss = exp(-(u^2 + v^2) / 2), z = tw . (u, v, 1)
    const T g_u = -s.u * s.gauss * g_gauss + g_z * g.tw.x;
    const T g_v = -s.v * s.gauss * g_gauss + g_z * g.tw.y;
    const T inv_pz = T(1) / p.z;
    const Vec3<T> g_p{g_u * inv_pz, g_v * inv_pz, -(g_u * s.u + g_v * s.v) * inv_pz};
    const Vec3<T> g_k = cross(l, g_p);
    const Vec3<T> g_l = cross(g_p, k);
    acc.tu = acc.tu - g_k;
    acc.tv = acc.tv - g_l;
    acc.tw += px * g_k + py * g_l + g_z * Vec3<T>{s.u, s.v, T(1)};
}

// Depth mapping used by the distortion loss: m = f/(f-n) (1 - n/z), NDC-like in [0, 1).
template <typename T>
LG_HD inline T distortion_depth(T z) {
    const T n = T(kNearPlane), f = T(kFarPlane);
    return f / (f - n) * (T(1) - n / z);
}
template <typename T>
LG_HD inline T distortion_depth_derivative(T z) {
    const T n = T(kNearPlane), f = T(kFarPlane);
    return f * n / ((f - n) * z * z);
}

}  // namespace lumigauss::raster
