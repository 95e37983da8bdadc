#pragma once
// Per-pixel evaluation of one projected surfel (ray-splat intersection, low-pass filter, alpha) and its
// backward. Shared by the CPU rasterizer, the test reference and the CUDA backend.
#include <cmath>
#include <limits>

#include "lumigauss/math/exp2_eighths.h"
#include "lumigauss/math/lanes.h"
#include "lumigauss/render/raster_constants.h"
#include "lumigauss/render/surfel_projection.h"

namespace lumigauss::raster {

// The kernel's formulas are written once for a lane type L (math/lanes.h): a scalar, or on the CPU a pack
// of eight pixels.

template <typename L>
struct SplatSample {
    L alpha{};                    // min(kAlphaMax, opacity * gauss)
    L gauss{};                    // max of the object-space Gaussian and the screen-space filter
    L u{}, v{};                   // intersection in the surfel's (u, v) frame (object branch only)
    L inv_pz{};                   // 1 / p.z of the homogeneous hit (the backward reuses it)
    L z{};                        // depth of this contribution
    LaneMask<L> screen_branch{};  // the screen low-pass filter won
    LaneMask<L> clamped{};        // alpha hit kAlphaMax
};

// exp(x) for the kernel's arguments (x <= 0). Float: exp(x) = 2^(n/8) exp(r) with |r| <= ln2/16, the first
// factor from an eight-entry table (exp2_eighths) and exp(r) from its degree-4 Taylor polynomial (truncation
// 1.3e-9, under the rounding). Checked over every float in [-87, 0]: at most 1.6 ulp off, 0.07 on average.
// Its chain of dependent operations is short, since it is on the tile loops' critical path (a degree-6
// polynomial over |r| <= ln2/2 was 1.0 ulp but 15 cycles longer: 4-6 % slower tiles with AVX2); no
// branches or libm calls, so that it vectorises. Double: std::exp (references and finite-difference tests).
template <typename L>
LG_HD_INLINE L kernel_exp(L x) {
    if constexpr (sizeof(lane_scalar_t<L>) == sizeof(float)) {
        x = lane_select(x < L(-87.0f), L(-87.0f), x);                 // exp(-87) is still a normal float
        const L shifted = x * L(11.5415603271f) + L(kExpRoundMagic);  // n = round(8 x / ln2), in the low bits
        const L n = shifted - L(kExpRoundMagic);
        // r = x - n ln2/8, ln2/8 in two parts (the first has 9 significant bits, so n times it is exact).
        const L r = (x - n * L(0.086669921875f)) - n * L(-2.65243050068e-5f);
        const L q = (r * L(1.0f / 24.0f) + L(1.0f / 6.0f)) * r + L(0.5f);
        const L er = (r * r * q + r) + L(1.0f);  // the 1 last: one rounding of the sum
        return er * exp2_eighths(shifted);
    } else {
        return lane_exp(x);
    }
}

// The pixel-surfel pair as the kernel sees it. The ray of pixel (px, py) is the intersection of the planes
// k = px tw - tu and l = py tw - tv; their cross product, the homogeneous (u, v, 1) of the hit, is affine in
// the pixel. Expanded about the filter centre c (a fixed origin, so that the terms stay small near the splat
// and float keeps its precision):
//   k x l = dx (tv x tw) + dy (tw x tu) + (c.x tw - tu) x (c.y tw - tv) = dx pa + dy pb + pd,  d = pix - c.
template <typename T>
struct alignas(16 * sizeof(lane_scalar_t<T>)) SplatGeometry {  // 16 values: a 64-byte cache line in float
    Vec3<T> pa, pb, pd;
    Vec3<T> tw;
    Vec2<T> center;
    T opacity;
    T rho_cutoff;  // opacity * exp(-rho/2) < kAlphaMin beyond this
};

// `rho_cutoff` is reach_rho(opacity), which the projection has already computed (ProjectedSurfel::reach).
template <typename T>
LG_HD inline SplatGeometry<T> make_splat_geometry(Vec3<T> tu, Vec3<T> tv, Vec3<T> tw, Vec2<T> center,
                                                  T opacity, T rho_cutoff) {
    SplatGeometry<T> g;
    g.pa = cross(tv, tw);
    g.pb = cross(tw, tu);
    g.pd = cross(center.x * tw - tu, center.y * tw - tv);
    g.tw = tw;
    g.center = center;
    g.opacity = opacity;
    g.rho_cutoff = rho_cutoff;
    return g;
}
template <typename T>
LG_HD inline SplatGeometry<T> make_splat_geometry(Vec3<T> tu, Vec3<T> tv, Vec3<T> tw, Vec2<T> center,
                                                  T opacity) {
    return make_splat_geometry(tu, tv, tw, center, opacity, reach_rho(opacity));
}

// The first half of evaluate_splat: where the ray of pixel centre(s) (px, py) hits the disk, which filter
// branch wins, the depth (s.u, s.v, s.inv_pz, s.screen_branch, s.z) and the kernel's rho. Returns where the
// pair is within reach: the ray is not parallel to the disk, rho <= rho_cutoff and the hit is not nearer
// than the near plane (a parallel ray makes u, v infinite or NaN, and every comparison then fails).
template <typename T, typename L>
LG_HD_INLINE LaneMask<L> splat_hit(const SplatGeometry<T>& g, L px, L py, SplatSample<L>& s, L& rho) {
    const L dx = px - L(g.center.x), dy = py - L(g.center.y);
    // Grouped so that each sum is two fused multiply-adds (left to right it was a product, a fused
    // multiply-add and an addition).
    const L p_x = dx * L(g.pa.x) + (dy * L(g.pb.x) + L(g.pd.x));
    const L p_y = dx * L(g.pa.y) + (dy * L(g.pb.y) + L(g.pd.y));
    const L p_z = dx * L(g.pa.z) + (dy * L(g.pb.z) + L(g.pd.z));
    s.inv_pz = L(1) / p_z;
    s.u = p_x * s.inv_pz;
    s.v = p_y * s.inv_pz;
    const L rho_object = s.u * s.u + s.v * s.v;
    const L rho_screen = L(kFilterInvSquare) * (dx * dx + dy * dy);
    s.screen_branch = rho_screen < rho_object;
    rho = lane_select(s.screen_branch, rho_screen, rho_object);
    // The screen branch uses the centre depth (the pinned rasterizer of the official code): far from the
    // disk, or at grazing angles, the intersection depth is meaningless.
    s.z = lane_select(s.screen_branch, L(g.tw.z), L(g.tw.x) * s.u + (L(g.tw.y) * s.v + L(g.tw.z)));
    // A ray parallel to the disk (p.z == 0) never contributes.
    const L rho_checked = lane_select(p_z != L(0), rho, L(std::numeric_limits<lane_scalar_t<L>>::infinity()));
    return (rho_checked <= L(g.rho_cutoff)) & (s.z >= L(kNearPlane));  // also false for NaN
}

// What the second half takes as the exponent where the pair is out of reach: any positive value (no real
// exponent -rho/2 is), so that the result is masked by the exponent's sign. Not -infinity: exp's underflow
// times the opacity gives subnormal floats, each of which costs the processor a slow assist (it made the
// tile loops 20 % slower); not NaN either: kernel_exp's float range reduction works on its argument's bits.
inline constexpr float kUnreachedExponent = 1.0f;

// The exponent the second half takes: -rho / 2 where `reached` (splat_hit's result, narrowed by whatever
// else the caller knows), else kUnreachedExponent.
template <typename L>
LG_HD_INLINE L splat_exponent(L rho, LaneMask<L> reached) {
    return lane_select(reached, L(-0.5) * rho, L(kUnreachedExponent));
}

// The second half: the kernel's value s.gauss = exp(exponent) and alpha = min(kAlphaMax, opacity * gauss).
// `exponent` is splat_exponent's (out of reach, gauss is a finite e, which the backward's zeroed terms
// need). Returns where the exponent is a real one and alpha >= kAlphaMin.
template <typename T, typename L>
LG_HD_INLINE LaneMask<L> splat_alpha(T opacity, L exponent, SplatSample<L>& s) {
    s.gauss = kernel_exp(exponent);
    const L a = L(opacity) * s.gauss;
    s.clamped = a > L(kAlphaMax);
    s.alpha = lane_select(s.clamped, L(kAlphaMax), a);
    return (exponent <= L(0)) & (s.alpha >= L(kAlphaMin));
}

// Evaluates the surfel at pixel centre(s) (px, py). The result (true, or the lanes) says where the pair
// contributes: not where the ray is parallel to the disk, the hit is nearer than the near plane, or
// alpha < kAlphaMin. Written without early returns (every test folds into the result) so that it runs on
// packs of pixels. (The CPU forward runs its two halves in separate loops: tile_forward.h.)
template <typename T, typename L>
LG_HD_INLINE LaneMask<L> evaluate_splat(const SplatGeometry<T>& g, L px, L py, SplatSample<L>& s) {
    L rho;
    const LaneMask<L> in_reach = splat_hit(g, px, py, s, rho);
    return splat_alpha(g.opacity, splat_exponent(rho, in_reach), s);
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
template <typename L>
struct SplatGradTerms {
    Vec3<L> g_p;   // dL/d(homogeneous hit p); dL/dpa = dx g_p, dL/dpb = dy g_p, dL/dpd = g_p
    L dx, dy;      // pixel - filter centre
    Vec3<L> g_tw;  // direct dependence through z
    Vec2<L> g_center;
    L g_opacity;
};

// Branch-free: both filter branches computed, one selected, and every value of the branch not taken
// zeroed before it can become inf * 0. `screen_branch` may also be set for pixels the pair does not
// reach: with g_alpha = g_z = 0 there, every term is then exactly 0 whatever u, v and p.z are. `smp` is
// what evaluate_splat returned for the same pixel.
template <typename T, typename L>
LG_HD_INLINE SplatGradTerms<L> splat_grad_terms(const SplatGeometry<T>& g, L px, L py,
                                                const SplatSample<L>& smp, LaneMask<L> screen_branch,
                                                L g_alpha, L g_z) {
    SplatGradTerms<L> t;
    // The alpha clamp is differentiated exactly: no gradient through a clamped alpha.
    const L ga = lane_select(smp.clamped, L(0), g_alpha);
    t.g_opacity = smp.gauss * ga;
    // gauss * dL/dgauss, which both branches scale.
    const L gauss_g = smp.gauss * (L(g.opacity) * ga);
    t.dx = px - L(g.center.x);
    t.dy = py - L(g.center.y);
    // Screen branch: gauss = exp(-|pix - c|^2), so d gauss / d c = 2 (pix - c) gauss; z = tw.z.
    const L k2 = lane_select(screen_branch, L(kFilterInvSquare) * gauss_g, L(0));
    t.g_center = {k2 * t.dx, k2 * t.dy};
    // Object branch: gauss = exp(-(u^2 + v^2) / 2), z = tw . (u, v, 1), (u, v) = (p.x, p.y) / p.z.
    const L u = lane_select(screen_branch, L(0), smp.u), v = lane_select(screen_branch, L(0), smp.v);
    const L g_u = lane_select(screen_branch, L(0), g_z * L(g.tw.x)) - u * gauss_g;
    const L g_v = lane_select(screen_branch, L(0), g_z * L(g.tw.y)) - v * gauss_g;
    const L inv_pz = lane_select(screen_branch, L(0), smp.inv_pz);
    t.g_p.x = g_u * inv_pz;
    t.g_p.y = g_v * inv_pz;
    t.g_p.z = -(u * t.g_p.x) - v * t.g_p.y;  // -(g_u u + g_v v) / p.z
    t.g_tw = {g_z * u, g_z * v, g_z};
    return t;
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

// Depth mapping used by the distortion loss: m = f/(f-n) (1 - n/z), NDC-like in [0, 1), and its derivative
// dm/dz = f n / ((f - n) z^2), from one reciprocal (the forward and the backward both use this, so that
// they agree on m to the bit).
template <typename T>
struct DistortionDepth {
    T m, dm_dz;
};
template <typename T>
LG_HD_INLINE DistortionDepth<T> distortion_depth_and_derivative(T z) {
    using S = lane_scalar_t<T>;
    const S n = S(kNearPlane), f = S(kFarPlane);
    const T inv_z = T(S(1)) / z;
    return {T(f / (f - n)) * (T(S(1)) - T(n) * inv_z), T(f * n / (f - n)) * inv_z * inv_z};
}
template <typename T>
LG_HD_INLINE T distortion_depth(T z) {
    return distortion_depth_and_derivative(z).m;
}

}  // namespace lumigauss::raster
