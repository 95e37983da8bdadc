#pragma once
// Per-pixel evaluation of one projected surfel (ray-splat intersection, low-pass filter, alpha) and its
// backward. Shared by the CPU rasterizer, the test reference and the CUDA backend.
#include <cmath>
#include <limits>

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

// exp(x) for the kernel's arguments (x <= 0). Float: range reduction to 2^k exp(r), |r| <= ln2/2, and a
// degree-6 polynomial (Cephes expf coefficients, about 1 ulp) written without branches or libm calls so
// that loops over pixels vectorise; double: std::exp (references and finite-difference tests).
template <typename T>
LG_HD_INLINE T kernel_exp(T x) {
    if constexpr (sizeof(T) == sizeof(float)) {
        x = x < -87.0f ? -87.0f : x;
        const float round_magic = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
        const float k = (x * 1.44269504088896341f + round_magic) - round_magic;
        const float r = (x - k * 0.693359375f) - k * -2.12194440e-4f;
        float p = 1.9875691500e-4f;
        p = p * r + 1.3981999507e-3f;
        p = p * r + 8.3334519073e-3f;
        p = p * r + 4.1665795894e-2f;
        p = p * r + 1.6666665459e-1f;
        p = p * r + 5.0000001201e-1f;
        const float er = p * r * r + r + 1.0f;
        const int bits = (int(k) + 127) << 23;
        float scale;
        __builtin_memcpy(&scale, &bits, sizeof(float));
        return er * scale;
    } else {
        return std::exp(x);
    }
}

// The pixel-surfel pair as the kernel sees it. The ray of pixel (px, py) is the intersection of the planes
// k = px tw - tu and l = py tw - tv; their cross product, the homogeneous (u, v, 1) of the hit, is affine in
// the pixel. Expanded about the filter centre c (a fixed origin, so that the terms stay small near the splat
// and float keeps its precision):
//   k x l = dx (tv x tw) + dy (tw x tu) + (c.x tw - tu) x (c.y tw - tv) = dx pa + dy pb + pd,  d = pix - c.
template <typename T>
struct SplatGeometry {
    Vec3<T> pa, pb, pd;
    Vec3<T> tw;
    Vec2<T> center;
    T opacity;
    T rho_cutoff;  // opacity * exp(-rho/2) < kAlphaMin beyond this
};

template <typename T>
LG_HD inline SplatGeometry<T> make_splat_geometry(Vec3<T> tu, Vec3<T> tv, Vec3<T> tw, Vec2<T> center,
                                                  T opacity) {
    SplatGeometry<T> g;
    g.pa = cross(tv, tw);
    g.pb = cross(tw, tu);
    g.pd = cross(center.x * tw - tu, center.y * tw - tv);
    g.tw = tw;
    g.center = center;
    g.opacity = opacity;
    g.rho_cutoff = reach_rho(opacity);
    return g;
}

// Evaluates the surfel at pixel centre (px, py). Returns false when the pair does not contribute:
// the ray is parallel to the disk, the hit is nearer than the near plane, or alpha < kAlphaMin.
// Written without early returns (every test folds into the result) so that loops over pixels vectorise;
// a parallel ray makes u, v infinite or NaN, and every comparison below then fails.
template <typename T>
LG_HD_INLINE bool evaluate_splat(const SplatGeometry<T>& g, T px, T py, SplatSample<T>& s) {
    const T dx = px - g.center.x, dy = py - g.center.y;
    const Vec3<T> p = dx * g.pa + dy * g.pb + g.pd;
    const T inv_pz = T(1) / p.z;
    s.u = p.x * inv_pz;
    s.v = p.y * inv_pz;
    const T rho_object = s.u * s.u + s.v * s.v;
    const T rho_screen = T(kFilterInvSquare) * (dx * dx + dy * dy);
    s.screen_branch = rho_screen < rho_object;
    const T rho = s.screen_branch ? rho_screen : rho_object;
    // The screen branch uses the centre depth (the pinned rasterizer of the official code): far from the
    // disk, or at grazing angles, the intersection depth is meaningless.
    s.z = s.screen_branch ? g.tw.z : g.tw.x * s.u + g.tw.y * s.v + g.tw.z;
    // A ray parallel to the disk (p.z == 0) never contributes. The tests are folded into selects on
    // floats rather than ANDs of masks: that form vectorises with GCC.
    const T rho_checked = p.z != T(0) ? rho : std::numeric_limits<T>::infinity();
    const bool in_reach = rho_checked <= g.rho_cutoff;  // also false for NaN
    s.gauss = kernel_exp(T(-0.5) * (in_reach ? rho : T(0)));
    const T a = g.opacity * s.gauss;
    s.clamped = a > T(kAlphaMax);
    s.alpha = s.clamped ? T(kAlphaMax) : a;
    return (in_reach ? s.z : T(-1)) >= T(kNearPlane) && s.alpha >= T(kAlphaMin);
}

// One surfel against a whole tile row of pixels (px0, px0 + 1, ..., px0 + kTileSize - 1), as arrays: the
// pass the CPU backend vectorises before it composites the contributing pixels one by one. A fixed width
// (no remainder loop) keeps short rows on the vector path; pixels outside [lo, hi] get alpha 0.
template <typename T>
struct RowSamples {
    T alpha[kTileSize];  // 0 where the pair does not contribute
    T z[kTileSize], u[kTileSize], v[kTileSize], gauss[kTileSize];
    T screen[kTileSize];   // 1 where the screen filter won
    T clamped[kTileSize];  // 1 where alpha hit kAlphaMax
};

// W (8 or 16) lanes starting at px0: callers use an 8-pixel window for boxes that fit in one, which halves
// the work on processors whose 16-wide vectors are two 8-wide halves.
template <int W = kTileSize, typename T>
LG_HD_INLINE void evaluate_splat_row(const SplatGeometry<T>& geometry, T px0, T py, int lo, int hi,
                                     RowSamples<T>& out) {
    const SplatGeometry<T> g = geometry;  // a local copy: the outputs cannot alias it, so the loop vectorises
    const T lo_t = T(lo), hi_t = T(hi);
    for (int i = 0; i < W; ++i) {
        SplatSample<T> s;
        const bool ok = evaluate_splat(g, px0 + T(i), py, s);
        const T a = ok ? s.alpha : T(0);
        const T a_lo = T(i) >= lo_t ? a : T(0);
        out.alpha[i] = T(i) <= hi_t ? a_lo : T(0);
        out.z[i] = s.z, out.u[i] = s.u, out.v[i] = s.v, out.gauss[i] = s.gauss;
        out.screen[i] = s.screen_branch ? T(1) : T(0);
        out.clamped[i] = s.clamped ? T(1) : T(0);
    }
}

// Gradient accumulators of one surfel over many pixels, in the kernel's own variables: the per-pixel work
// is three sums per component; to_ray_transform_grad converts them once per surfel.
template <typename T>
struct SplatGrad {
    Vec3<T> pa, pb, pd;
    Vec3<T> tw;  // direct dependence through z = tw . (u, v, 1)
    Vec2<T> center;
    T opacity{};
};

// What one pixel contributes to the surfel's kernel gradients, given dL/dalpha and dL/dz for the pair.
// Branch-free (both filter branches computed, one selected, and every value of the branch not taken
// zeroed before it can become inf * 0), so that it vectorises over pixels.
template <typename T>
struct SplatGradTerms {
    Vec3<T> g_p;   // dL/d(homogeneous hit p); dL/dpa = dx g_p, dL/dpb = dy g_p, dL/dpd = g_p
    T dx, dy;      // pixel - filter centre
    Vec3<T> g_tw;  // direct dependence through z
    Vec2<T> g_center;
    T g_opacity;
};

// The sample is passed field by field (not as SplatSample) so that vectorised callers need not assemble
// structs with bool members per pixel.
template <typename T>
LG_HD_INLINE SplatGradTerms<T> splat_grad_terms(const SplatGeometry<T>& g, T px, T py, T sample_u, T sample_v,
                                                T gauss, bool screen_branch, bool clamped, T g_alpha, T g_z) {
    SplatGradTerms<T> t;
    // The alpha clamp is differentiated exactly: no gradient through a clamped alpha.
    const T ga = clamped ? T(0) : g_alpha;
    t.g_opacity = gauss * ga;
    const T g_gauss = g.opacity * ga;
    t.dx = px - g.center.x;
    t.dy = py - g.center.y;
    const bool obj = !screen_branch;
    // Screen branch: gauss = exp(-|pix - c|^2), so d gauss / d c = 2 (pix - c) gauss; z = tw.z.
    const T k2 = obj ? T(0) : T(kFilterInvSquare) * gauss * g_gauss;
    t.g_center = {k2 * t.dx, k2 * t.dy};
    // Object branch: gauss = exp(-(u^2 + v^2) / 2), z = tw . (u, v, 1), (u, v) = (p.x, p.y) / p.z.
    const T u = obj ? sample_u : T(0), v = obj ? sample_v : T(0);
    const T g_u = -u * gauss * g_gauss + (obj ? g_z * g.tw.x : T(0));
    const T g_v = -v * gauss * g_gauss + (obj ? g_z * g.tw.y : T(0));
    const T p_z = t.dx * g.pa.z + t.dy * g.pb.z + g.pd.z;
    const T inv_pz = obj ? T(1) / p_z : T(0);
    t.g_p = {g_u * inv_pz, g_v * inv_pz, -(g_u * u + g_v * v) * inv_pz};
    t.g_tw = {g_z * u, g_z * v, g_z};
    return t;
}

// Backward of evaluate_splat for one pixel: adds the gradients from dL/dalpha and dL/dz to `acc`.
template <typename T>
LG_HD inline void evaluate_splat_vjp(const SplatGeometry<T>& g, T px, T py, const SplatSample<T>& s,
                                     T g_alpha, T g_z, SplatGrad<T>& acc) {
    const SplatGradTerms<T> t =
        splat_grad_terms(g, px, py, s.u, s.v, s.gauss, s.screen_branch, s.clamped, g_alpha, g_z);
    acc.pa += t.dx * t.g_p;
    acc.pb += t.dy * t.g_p;
    acc.pd += t.g_p;
    acc.tw += t.g_tw;
    acc.center = acc.center + t.g_center;
    acc.opacity += t.g_opacity;
}

// Converts accumulated kernel gradients to gradients on the ray-transform rows (pa = tv x tw, pb = tw x tu,
// pd = k x l with k = c.x tw - tu, l = c.y tw - tv), the filter centre and the opacity. The expansion origin
// c is held fixed here: (u, v) does not depend on it, only the screen filter does (g.center).
template <typename T>
LG_HD inline void to_ray_transform_grad(Vec3<T> tu, Vec3<T> tv, Vec3<T> tw, Vec2<T> c, const SplatGrad<T>& g,
                                        ProjectedSurfelGrad<T>& out, T& g_opacity) {
    const Vec3<T> k = c.x * tw - tu, l = c.y * tw - tv;
    const Vec3<T> g_k = cross(l, g.pd), g_l = cross(g.pd, k);
    out.tu = out.tu + cross(g.pb, tw) - g_k;
    out.tv = out.tv + cross(tw, g.pa) - g_l;
    out.tw = out.tw + g.tw + cross(g.pa, tv) + cross(tu, g.pb) + c.x * g_k + c.y * g_l;
    out.center = out.center + g.center;
    g_opacity += g.opacity;
}

// Depth mapping used by the distortion loss: m = f/(f-n) (1 - n/z), NDC-like in [0, 1).
template <typename T>
LG_HD_INLINE T distortion_depth(T z) {
    const T n = T(kNearPlane), f = T(kFarPlane);
    return f / (f - n) * (T(1) - n / z);
}
template <typename T>
LG_HD_INLINE T distortion_depth_derivative(T z) {
    const T n = T(kNearPlane), f = T(kFarPlane);
    return f * n / ((f - n) * z * z);
}

}  // namespace lumigauss::raster
