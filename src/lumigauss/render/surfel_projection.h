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

// Pixels a surfel may touch: its bounding square, clipped to the image (inclusive bounds).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    LG_HD constexpr bool empty() const { return x1 < x0 || y1 < y0; }
};

template <typename T>
struct ProjectedSurfel {
    Vec3<T> tu, tv, tw;  // rows of the ray transform T
    Vec2<T> center;      // centre of the bounding square and of the screen low-pass filter (pixels)
    T radius;            // half side of the bounding square (pixels)
    Vec3<T> normal;      // world-space unit normal, flipped to face the camera
    T flip;              // +1 or -1: the flip applied to t_w
    T depth;             // view-space z of the mean: the sort key
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

template <typename T>
LG_HD inline PixelRect pixel_rect_of_square(Vec2<T> c, T r, int width, int height) {
    // Pixel x is inside iff |x + 0.5 - c.x| <= r.
    PixelRect rect;
    if (!(r < T(1e7))) {  // the whole image (also catches infinities)
        rect = {0, 0, width - 1, height - 1};
        return rect;
    }
    const T fx0 = std::ceil(c.x - r - T(0.5)), fx1 = std::floor(c.x + r - T(0.5));
    const T fy0 = std::ceil(c.y - r - T(0.5)), fy1 = std::floor(c.y + r - T(0.5));
    if (fx1 < 0 || fy1 < 0 || fx0 > T(width - 1) || fy0 > T(height - 1)) return rect;  // empty
    rect.x0 = fx0 < 0 ? 0 : int(fx0);
    rect.y0 = fy0 < 0 ? 0 : int(fy0);
    rect.x1 = fx1 > T(width - 1) ? width - 1 : int(fx1);
    rect.y1 = fy1 > T(height - 1) ? height - 1 : int(fy1);
    return rect;
}

// Centre of the image of the c-sigma circle from its dual conic C* = T diag(c², c², -1) Tᵀ; valid when
// d = c²(tw.x² + tw.y²) - tw.z² < 0, i.e. the whole disk lies in front of the camera plane.
template <typename T>
LG_HD inline T conic_denominator(Vec3<T> tw) {
    const T c2 = T(kSigmaCutoff * kSigmaCutoff);
    return c2 * (tw.x * tw.x + tw.y * tw.y) - tw.z * tw.z;
}

// Projects one surfel. Returns false when it cannot be seen (behind the near plane, exactly edge-on,
// degenerate, or off-screen).
template <typename T>
LG_HD inline bool project_surfel(const SurfelGeometry<T>& g, const PinholeView<T>& view,
                                 ProjectedSurfel<T>& out) {
    const Vec3<T> mean_cam = view.rotation * g.mean + view.translation;
    if (!(mean_cam.z > T(kNearPlane))) return false;
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

    const T d = conic_denominator(out.tw);
    if (d < 0) {
        const T c2 = T(kSigmaCutoff * kSigmaCutoff);
        const Vec3<T> f{c2 / d, c2 / d, T(-1) / d};
        const Vec3<T> tutw = hadamard(out.tu, out.tw), tvtw = hadamard(out.tv, out.tw);
        out.center = {dot(f, tutw), dot(f, tvtw)};
        const T ex = out.center.x * out.center.x - dot(f, hadamard(out.tu, out.tu));
        const T ey = out.center.y * out.center.y - dot(f, hadamard(out.tv, out.tv));
        const T hx = std::sqrt(ex > T(1e-4) ? ex : T(1e-4));
        const T hy = std::sqrt(ey > T(1e-4) ? ey : T(1e-4));
        T r = hx > hy ? hx : hy;
        r = r > T(kMinRadius) ? r : T(kMinRadius);
        out.radius = std::ceil(r);
        out.conic_center = true;
    } else {
        // The 3-sigma disk crosses the camera plane: its image is unbounded (a hyperbola), so the box is the
        // whole image and the per-pixel near test removes what lies behind. The filter is centred on the
        // projected mean, which is in front of the camera.
        out.center = {out.tu.z / out.tw.z, out.tv.z / out.tw.z};
        out.radius = std::numeric_limits<T>::infinity();
        out.conic_center = false;
    }
    if (!(std::isfinite(out.center.x) && std::isfinite(out.center.y))) return false;
    out.rect = pixel_rect_of_square(out.center, out.radius, view.width, view.height);
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
    // 1. Filter centre -> rows of T.
    if (p.conic_center) {
        const T c2 = T(kSigmaCutoff * kSigmaCutoff);
        const Vec3<T> t{c2, c2, T(-1)};
        const T d = conic_denominator(p.tw);
        // center.x = sum t_k tu_k tw_k / d,   d = sum t_k tw_k^2.
        const T gx = grad.center.x, gy = grad.center.y;
        for (int k = 0; k < 3; ++k) {
            const T tk_d = t[k] / d;
            grad.tu[k] += gx * tk_d * p.tw[k];
            grad.tv[k] += gy * tk_d * p.tw[k];
            grad.tw[k] += gx * (tk_d * p.tu[k] - p.center.x * 2 * tk_d * p.tw[k]) +
                          gy * (tk_d * p.tv[k] - p.center.y * 2 * tk_d * p.tw[k]);
        }
    } else {
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
