#pragma once
// Per-surfel, per-view preprocessing of the 2DGS rasterizer and its backward.
//
// A surfel is a disk P(u, v) = mean + s_u t_u u + s_v t_v v with [t_u t_v t_w] = R(q). For a pinhole
// camera with intrinsics K and world-to-camera [R_v | t], the 3x3 "ray transform"
//     T = K [R_v s_u t_u,  R_v s_v t_v,  R_v mean + t]
// maps (u, v, 1) to homogeneous pixel coordinates; its rows tu, tv, tw are all a pixel needs for the
// ray-splat intersection (surfel_kernel.h). Pixel (i, j) has centre (i + 0.5, j + 0.5) in COLMAP's image
// plane, so K is COLMAP's intrinsics unchanged.
#include <cmath>
#include <limits>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/render/raster_constants.h"

namespace lumigauss::raster {

template <typename T>
struct PinholeView {
    Mat3<T> rotation;  // world-to-camera
    Vec3<T> translation;
    T fx, fy, cx, cy;
    int width, height;
};

// Pixels a surfel may touch, clipped to the image (inclusive bounds).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    LG_HD constexpr bool empty() const { return x1 < x0 || y1 < y0; }
};

template <typename T>
struct ProjectedSurfel {
    Vec3<T> tu, tv, tw;  // rows of the ray transform T
    Vec2<T> center;      // centre of the screen low-pass filter (pixels)
    Vec3<T> normal;      // world-space unit normal, flipped to face the camera
    T flip;              // +1 or -1: the flip applied to t_w
    T depth;             // view-space z of the mean: the sort key
    T reach;             // reach_rho(opacity): rho beyond which alpha < kAlphaMin
    bool conic_center;   // true: centre of the dual-conic box; false: the disk crosses the camera plane
    PixelRect rect;
};

// Inputs of one surfel in the form the projection uses (scales and quaternion as given, not activated).
template <typename T>
struct SurfelGeometry {
    Vec3<T> mean;
    Vec4<T> quat;  // raw (unnormalised) quaternion w, x, y, z
    T scale_u, scale_v;
};

// Pixels whose centres x + 0.5, y + 0.5 lie in [lo, hi] (per axis), clipped to the image.
template <typename T>
LG_HD inline PixelRect pixel_rect(Vec2<T> lo, Vec2<T> hi, int width, int height) {
    PixelRect rect;
    const T fx0 = std::ceil(lo.x - T(0.5)), fx1 = std::floor(hi.x - T(0.5));
    const T fy0 = std::ceil(lo.y - T(0.5)), fy1 = std::floor(hi.y - T(0.5));
    if (!(fx1 >= 0 && fy1 >= 0 && fx0 <= T(width - 1) && fy0 <= T(height - 1)))
        return rect;  // empty (or NaN)
    rect.x0 = fx0 < 0 ? 0 : int(fx0);
    rect.y0 = fy0 < 0 ? 0 : int(fy0);
    rect.x1 = fx1 > T(width - 1) ? width - 1 : int(fx1);
    rect.y1 = fy1 > T(height - 1) ? height - 1 : int(fy1);
    return rect;
}

// The image of the disk u² + v² <= c2 has the dual conic C* = T diag(c2, c2, -1) Tᵀ; its bounding box
// follows from the tangent lines x = const and y = const. It is an ellipse, and the box valid, only when
// d = c2 (tw.x² + tw.y²) - tw.z² < 0: the whole disk lies in front of the camera plane.
template <typename T>
LG_HD inline T conic_denominator(Vec3<T> tw, T c2) {
    return c2 * (tw.x * tw.x + tw.y * tw.y) - tw.z * tw.z;
}

template <typename T>
struct ConicBox {
    Vec2<T> center;
    T half_x, half_y;
};

template <typename T>
LG_HD inline ConicBox<T> conic_box(Vec3<T> tu, Vec3<T> tv, Vec3<T> tw, T c2, T d) {
    const Vec3<T> f{c2 / d, c2 / d, T(-1) / d};
    ConicBox<T> box;
    box.center = {dot(f, hadamard(tu, tw)), dot(f, hadamard(tv, tw))};
    const T ex = box.center.x * box.center.x - dot(f, hadamard(tu, tu));
    const T ey = box.center.y * box.center.y - dot(f, hadamard(tv, tv));
    box.half_x = std::sqrt(ex > T(0) ? ex : T(0));
    box.half_y = std::sqrt(ey > T(0) ? ey : T(0));
    return box;
}

// The largest rho = min(rho_object, rho_screen) at which a surfel of this opacity still reaches alpha
// kAlphaMin: opacity * exp(-rho / 2) >= kAlphaMin. Negative when it never does. A hair of slack, so that
// work skipped on this bound is never work the exact alpha test would keep.
template <typename T>
LG_HD inline T reach_rho(T opacity) {
    const T ratio = opacity / T(kAlphaMin);
    return ratio > T(1) ? T(2) * std::log(ratio) * T(1.0001) + T(1e-6) : T(-1);
}

// True when a sphere (centre in camera space, squared radius) lies wholly in front of the near plane and
// wholly beyond one side of the view frustum widened by `margin` pixels. A cheap test that spares most
// off-screen surfels the exact projection below; it never rejects anything that exact bound would keep.
template <typename T>
LG_HD inline bool sphere_outside_view(Vec3<T> c, T radius_sq, T margin, const PinholeView<T>& view) {
    const T front = c.z - T(kNearPlane);
    if (!(front > T(0) && front * front > radius_sq)) return false;  // may reach the camera plane
    // Each side is a plane through the camera centre, a.c >= 0 on the visible side (u >= -margin,
    // u <= W + margin, and likewise for v). Beyond it by more than the radius: a.c < -r |a|.
    const auto beyond = [&](T a_xy, T a_z, T xy) {
        const T d = a_xy * xy + a_z * c.z;
        return d < T(0) && d * d > radius_sq * (a_xy * a_xy + a_z * a_z);
    };
    return beyond(view.fx, view.cx + margin, c.x) ||
           beyond(-view.fx, T(view.width) + margin - view.cx, c.x) ||
           beyond(view.fy, view.cy + margin, c.y) || beyond(-view.fy, T(view.height) + margin - view.cy, c.y);
}

// Projects one surfel. Returns false when it cannot be seen (behind the near plane, exactly edge-on,
// too transparent to ever reach kAlphaMin, degenerate, or off-screen).
//
// Two things are bounded separately. The screen low-pass filter is centred on the 3-sigma dual-conic box
// centre, as in the reference implementation. The pixels it may touch are bounded exactly: where
// opacity * exp(-rho/2) >= kAlphaMin, i.e. inside the ellipse rho_object <= reach_rho(opacity) or the
// filter disk rho_screen <= reach_rho(opacity). Nothing that reaches alpha 1/255 is cut off, so the image
// does not depend on the tile size, and no pixel is visited that cannot contribute.
template <typename T>
LG_HD inline bool project_surfel(const SurfelGeometry<T>& g, T opacity, const PinholeView<T>& view,
                                 ProjectedSurfel<T>& out) {
    const T reach = reach_rho(opacity);
    if (!(reach > T(0))) return false;
    out.reach = reach;
    const Vec3<T> mean_cam = view.rotation * g.mean + view.translation;
    if (!(mean_cam.z > T(kNearPlane))) return false;
    // Everything the surfel can reach: its disk out to rho = reach (or 3 sigma, which bounds the filter
    // centre), then the screen filter's radius around that in pixels (plus one for rounding).
    const T sigma = g.scale_u > g.scale_v ? g.scale_u : g.scale_v;
    const T disk_sq =
        (reach > T(kSigmaCutoff * kSigmaCutoff) ? reach : T(kSigmaCutoff * kSigmaCutoff)) * sigma * sigma;
    if (sphere_outside_view(mean_cam, disk_sq, std::sqrt(reach / T(kFilterInvSquare)) + T(1), view))
        return false;
    const Mat3<T> R = rotation_from_unit_quaternion(normalize_quaternion(g.quat));
    const Vec3<T> a = view.rotation * (g.scale_u * R.col(0));
    const Vec3<T> b = view.rotation * (g.scale_v * R.col(1));
    const Vec3<T> n_cam = view.rotation * R.col(2);
    // The surfel faces the camera when its normal points back along the viewing ray.
    const T facing = -dot(mean_cam, n_cam);
    if (facing == T(0)) return false;
    out.flip = facing > 0 ? T(1) : T(-1);
    out.normal = out.flip * R.col(2);
    // Rows of K [a b mean_cam].
    out.tu = {view.fx * a.x + view.cx * a.z, view.fx * b.x + view.cx * b.z,
              view.fx * mean_cam.x + view.cx * mean_cam.z};
    out.tv = {view.fy * a.y + view.cy * a.z, view.fy * b.y + view.cy * b.z,
              view.fy * mean_cam.y + view.cy * mean_cam.z};
    out.tw = {a.z, b.z, mean_cam.z};
    out.depth = mean_cam.z;

    // Filter centre.
    const T c2 = T(kSigmaCutoff * kSigmaCutoff);
    const T d3 = conic_denominator(out.tw, c2);
    out.conic_center = d3 < 0;
    // When the 3-sigma disk crosses the camera plane its box is meaningless; the projected mean (in front of
    // the camera) centres the filter instead.
    out.center = out.conic_center ? conic_box(out.tu, out.tv, out.tw, c2, d3).center
                                  : Vec2<T>{out.tu.z / out.tw.z, out.tv.z / out.tw.z};
    // Near the boundary of that case (d3 -> 0-) the conic centre runs off to infinity. It is also the origin
    // of the per-pixel expansion (make_splat_geometry), where a far origin cancels catastrophically (a
    // plaza training run met a 1.2 m-deep surfel whose centre overflowed and made NaN gradients). Far
    // outside the image the filter cannot reach any pixel anyway, so the crossing-case centre is used.
    if (out.conic_center) {
        const T margin = T(2) * T(view.width + view.height);
        const T cx = out.center.x, cy = out.center.y;
        const T max_x = T(view.width) + margin, max_y = T(view.height) + margin;
        const bool near_image = cx > -margin && max_x > cx && cy > -margin && max_y > cy;
        if (!near_image) {
            out.conic_center = false;
            out.center = {out.tu.z / out.tw.z, out.tv.z / out.tw.z};
        }
    }
    if (!(std::isfinite(out.center.x) && std::isfinite(out.center.y))) return false;

    // Pixels it can reach.
    const T d_reach = conic_denominator(out.tw, reach);
    if (d_reach < 0) {
        const ConicBox<T> box = conic_box(out.tu, out.tv, out.tw, reach, d_reach);
        const T filter = std::sqrt(reach / T(kFilterInvSquare));  // rho_screen <= reach within this distance
        const auto lo = [](T a_, T b_) { return a_ < b_ ? a_ : b_; };
        const auto hi = [](T a_, T b_) { return a_ > b_ ? a_ : b_; };
        out.rect = pixel_rect<T>({lo(box.center.x - box.half_x, out.center.x - filter),
                                  lo(box.center.y - box.half_y, out.center.y - filter)},
                                 {hi(box.center.x + box.half_x, out.center.x + filter),
                                  hi(box.center.y + box.half_y, out.center.y + filter)},
                                 view.width, view.height);
    } else {
        // The reachable part of the disk crosses the camera plane: its image is unbounded, so the whole image
        // is visited and the per-pixel near test removes what lies behind.
        out.rect = {0, 0, view.width - 1, view.height - 1};
    }
    return !out.rect.empty();
}

// Gradients reaching one projected surfel from the pixels.
template <typename T>
struct ProjectedSurfelGrad {
    Vec3<T> tu, tv, tw;
    Vec2<T> center;
    Vec3<T> normal;
};

template <typename T>
struct SurfelGeometryGrad {
    Vec3<T> mean;
    Vec4<T> quat;  // w.r.t. the raw quaternion (normalisation included)
    T scale_u, scale_v;
};

// Backward of project_surfel for a visible surfel (recomputes what it needs from the inputs).
template <typename T>
LG_HD inline SurfelGeometryGrad<T> project_surfel_vjp(const SurfelGeometry<T>& g, const PinholeView<T>& view,
                                                      const ProjectedSurfel<T>& p,
                                                      ProjectedSurfelGrad<T> grad) {
    // 1. Filter centre -> rows of T. Near the boundary of the conic branch (d -> 0-) the centre runs off to
    // infinity and its derivative with it; no pixel then uses the filter, so its gradient is exactly 0, and
    // skipping the chain keeps 0 * inf from turning into NaN.
    if (p.conic_center && (grad.center.x != T(0) || grad.center.y != T(0))) {
        const T c2 = T(kSigmaCutoff * kSigmaCutoff);
        const Vec3<T> t{c2, c2, T(-1)};
        const T d = conic_denominator(p.tw, c2);
        // center.x = sum t_k tu_k tw_k / d,   d = sum t_k tw_k^2.
        const T gx = grad.center.x, gy = grad.center.y;
        for (int k = 0; k < 3; ++k) {
            const T tk_d = t[k] / d;
            grad.tu[k] += gx * tk_d * p.tw[k];
            grad.tv[k] += gy * tk_d * p.tw[k];
            grad.tw[k] += gx * (tk_d * p.tu[k] - p.center.x * 2 * tk_d * p.tw[k]) +
                          gy * (tk_d * p.tv[k] - p.center.y * 2 * tk_d * p.tw[k]);
        }
    } else if (!p.conic_center) {
        const T inv_w = T(1) / p.tw.z;
        grad.tu.z += grad.center.x * inv_w;
        grad.tv.z += grad.center.y * inv_w;
        grad.tw.z -= (grad.center.x * p.center.x + grad.center.y * p.center.y) * inv_w;
    }
    // 2. T = K M with M = [a b mean_cam] (columns): dL/dM = Kᵀ dL/dT.
    const auto column_grad = [&](int c) -> Vec3<T> {
        return {view.fx * grad.tu[c], view.fy * grad.tv[c],
                view.cx * grad.tu[c] + view.cy * grad.tv[c] + grad.tw[c]};
    };
    const Mat3<T> Rt = transpose(view.rotation);
    const Vec3<T> g_su_tu = Rt * column_grad(0);  // dL/d(s_u t_u) in world space
    const Vec3<T> g_sv_tv = Rt * column_grad(1);
    SurfelGeometryGrad<T> out;
    out.mean = Rt * column_grad(2);

    // 3. Scales, rotation columns, and the normal (flip is piecewise constant).
    const Vec4<T> q = normalize_quaternion(g.quat);
    const Mat3<T> R = rotation_from_unit_quaternion(q);
    out.scale_u = dot(R.col(0), g_su_tu);
    out.scale_v = dot(R.col(1), g_sv_tv);
    const Mat3<T> gR = Mat3<T>::from_columns(g.scale_u * g_su_tu, g.scale_v * g_sv_tv, p.flip * grad.normal);
    out.quat = normalize_quaternion_vjp(g.quat, rotation_from_unit_quaternion_vjp(q, gR));
    return out;
}

}  // namespace lumigauss::raster
