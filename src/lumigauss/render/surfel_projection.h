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

#include "lumigauss/math/lanes.h"
#include "lumigauss/math/log_positive.h"
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

// The same view in another scalar type (both backends project in double from the float view).
template <typename To, typename From>
LG_HD inline PinholeView<To> cast_view(const PinholeView<From>& v) {
    return {v.rotation.template cast<To>(),
            v.translation.template cast<To>(),
            To(v.fx),
            To(v.fy),
            To(v.cx),
            To(v.cy),
            v.width,
            v.height};
}

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
// (These and the functions below are written for a lane type L, math/lanes.h: a scalar, or several
// surfels at once.)
template <typename L>
LG_HD_INLINE L conic_denominator(Vec3<L> tw, L c2) {
    return c2 * (tw.x * tw.x + tw.y * tw.y) - tw.z * tw.z;
}

template <typename L>
struct ConicBox {
    Vec2<L> center;
    L half_x, half_y;
};

template <typename L>
LG_HD_INLINE Vec2<L> conic_center(Vec3<L> tu, Vec3<L> tv, Vec3<L> tw, L c2, L d) {
    const Vec3<L> f{c2 / d, c2 / d, L(-1) / d};
    return {dot(f, hadamard(tu, tw)), dot(f, hadamard(tv, tw))};
}

template <typename L>
LG_HD_INLINE ConicBox<L> conic_box(Vec3<L> tu, Vec3<L> tv, Vec3<L> tw, L c2, L d) {
    const Vec3<L> f{c2 / d, c2 / d, L(-1) / d};
    ConicBox<L> box;
    box.center = conic_center(tu, tv, tw, c2, d);
    const L ex = box.center.x * box.center.x - dot(f, hadamard(tu, tu));
    const L ey = box.center.y * box.center.y - dot(f, hadamard(tv, tv));
    box.half_x = lane_sqrt(lane_max(ex, L(0)));
    box.half_y = lane_sqrt(lane_max(ey, L(0)));
    return box;
}

// The largest rho = min(rho_object, rho_screen) at which a surfel of this opacity still reaches alpha
// kAlphaMin: opacity * exp(-rho / 2) >= kAlphaMin. Negative when it never does. A hair of slack, so that
// work skipped on this bound is never work the exact alpha test would keep.
template <typename L>
LG_HD_INLINE L reach_rho(L opacity) {
    const L ratio = opacity / L(kAlphaMin);
    const auto reaches = ratio > L(1);
    const L rho = L(2) * log_positive(lane_select(reaches, ratio, L(1))) * L(1.0001) + L(1e-6);
    return lane_select(reaches, rho, L(-1));
}

// A world-to-camera rotation (of the view's scalar type V) applied to a vector of lanes.
template <typename L, typename V>
LG_HD_INLINE Vec3<L> rotate(const Mat3<V>& R, Vec3<L> v) {
    const auto row = [&](int r)
                         LG_LAMBDA_INLINE { return L(R(r, 0)) * v.x + L(R(r, 1)) * v.y + L(R(r, 2)) * v.z; };
    return {row(0), row(1), row(2)};
}

// True when a sphere (centre in camera space, squared radius) lies wholly in front of the near plane and
// wholly beyond one side of the view frustum widened by `margin` pixels. A cheap test that spares most
// off-screen surfels the exact projection below; it never rejects anything that exact bound would keep.
template <typename L, typename V>
LG_HD_INLINE LaneMask<L> sphere_outside_view(Vec3<L> c, L radius_sq, L margin, const PinholeView<V>& view) {
    const L front = c.z - L(kNearPlane);
    const auto in_front = (front > L(0)) & (front * front > radius_sq);  // cannot reach the camera plane
    // Each side is a plane through the camera centre, a.c >= 0 on the visible side (u >= -margin,
    // u <= W + margin, and likewise for v). Beyond it by more than the radius: a.c < -r |a|.
    const auto beyond = [&](L a_xy, L a_z, L xy) LG_LAMBDA_INLINE {
        const L d = a_xy * xy + a_z * c.z;
        return (d < L(0)) & (d * d > radius_sq * (a_xy * a_xy + a_z * a_z));
    };
    const L fx(view.fx), fy(view.fy);
    return in_front &
           (beyond(fx, L(view.cx) + margin, c.x) | beyond(-fx, L(V(view.width) - view.cx) + margin, c.x) |
            beyond(fy, L(view.cy) + margin, c.y) | beyond(-fy, L(V(view.height) - view.cy) + margin, c.y));
}

// How far a surfel of reach `reach` = reach_rho(opacity) can be seen: its disk out to rho = disk_rho (the
// reach, or 3 sigma, which bounds the filter centre), then the screen filter's radius in pixels, within
// which rho_screen <= reach. The exact projection and the first cull (may_reach_view) both bound with it.
template <typename L>
struct ReachBound {
    L disk_rho, filter;
};
template <typename L>
LG_HD_INLINE ReachBound<L> reach_bound(L reach) {
    return {lane_max(reach, L(kSigmaCutoff * kSigmaCutoff)),
            lane_sqrt(lane_max(reach, L(0)) / L(kFilterInvSquare))};
}

// Everything the projection decides about a surfel, before its reachable region is rounded to pixels.
template <typename L>
struct ProjectionLanes {
    Vec3<L> tu, tv, tw;
    Vec2<L> center;
    Vec3<L> normal;
    L flip, depth, reach;
    LaneMask<L> conic_center;
    LaneMask<L> whole_image;  // the reachable disk crosses the camera plane: every pixel may be reached
    Vec2<L> lo, hi;           // otherwise the reachable region's bounds in pixels (pixel_rect rounds them)
};

// Projects a surfel (or several, one per lane) of reach `reach` = reach_rho(opacity), which the caller
// computes (a logarithm per surfel, which no pack instruction does). Returns where it can be seen: false
// where it is behind the near plane, exactly edge-on, too transparent to ever reach kAlphaMin, degenerate, or
// off-screen. Written without early returns (every test folds into the mask), so that it runs on packs of
// surfels; values in lanes that fail are unspecified.
//
// Two things are bounded separately. The screen low-pass filter is centred on the 3-sigma dual-conic box
// centre, as in the reference implementation. The pixels it may touch are bounded exactly: where
// opacity * exp(-rho/2) >= kAlphaMin, i.e. inside the ellipse rho_object <= reach_rho(opacity) or the
// filter disk rho_screen <= reach_rho(opacity). Nothing that reaches alpha 1/255 is cut off, so the image
// does not depend on the tile size, and no pixel is visited that cannot contribute.
template <typename L, typename V>
LG_HD_INLINE LaneMask<L> project_surfel_lanes(const SurfelGeometry<L>& g, L reach, const PinholeView<V>& view,
                                              ProjectionLanes<L>& out) {
    out.reach = reach;
    auto visible = reach > L(0);
    const Vec3<L> mean_cam = rotate(view.rotation, g.mean) +
                             Vec3<L>{L(view.translation.x), L(view.translation.y), L(view.translation.z)};
    visible = visible & (mean_cam.z > L(kNearPlane));
    // Everything the surfel can reach (reach_bound), plus one pixel for rounding.
    const L sigma = lane_max(g.scale_u, g.scale_v);
    const ReachBound<L> bound = reach_bound(reach);
    const L filter = bound.filter;
    visible = visible &
              lane_not(sphere_outside_view(mean_cam, bound.disk_rho * sigma * sigma, filter + L(1), view));
    const Mat3<L> R = rotation_from_unit_quaternion(normalize_quaternion(g.quat));
    const Vec3<L> a = rotate(view.rotation, g.scale_u * R.col(0));
    const Vec3<L> b = rotate(view.rotation, g.scale_v * R.col(1));
    const Vec3<L> n_cam = rotate(view.rotation, R.col(2));
    // The surfel faces the camera when its normal points back along the viewing ray.
    const L facing = -dot(mean_cam, n_cam);
    visible = visible & (facing != L(0));
    out.flip = lane_select(facing > L(0), L(1), L(-1));
    out.normal = out.flip * R.col(2);
    // Rows of K [a b mean_cam].
    const L fx(view.fx), fy(view.fy), cx(view.cx), cy(view.cy);
    out.tu = {fx * a.x + cx * a.z, fx * b.x + cx * b.z, fx * mean_cam.x + cx * mean_cam.z};
    out.tv = {fy * a.y + cy * a.z, fy * b.y + cy * b.z, fy * mean_cam.y + cy * mean_cam.z};
    out.tw = {a.z, b.z, mean_cam.z};
    out.depth = mean_cam.z;

    // Filter centre: the 3-sigma box's centre. When that disk crosses the camera plane (d3 >= 0) its box
    // is meaningless, and the projected mean (in front of the camera) centres the filter instead. Near the
    // boundary of that case (d3 -> 0-) the conic centre runs off to infinity; it is also the origin of the
    // per-pixel expansion (make_splat_geometry), where a far origin cancels catastrophically (a plaza
    // training run met a 1.2 m-deep surfel whose centre overflowed and made NaN gradients). Far outside
    // the image the filter cannot reach any pixel anyway, so the crossing-case centre is used there too.
    const L c2 = L(kSigmaCutoff * kSigmaCutoff);
    const L d3 = conic_denominator(out.tw, c2);
    const Vec2<L> conic = conic_center(out.tu, out.tv, out.tw, c2, d3);
    const L margin = L(V(2) * V(view.width + view.height));
    const auto near_image = (conic.x > -margin) & (L(V(view.width)) + margin > conic.x) &
                            (conic.y > -margin) & (L(V(view.height)) + margin > conic.y);
    out.conic_center = (d3 < L(0)) & near_image;
    out.center = {lane_select(out.conic_center, conic.x, out.tu.z / out.tw.z),
                  lane_select(out.conic_center, conic.y, out.tv.z / out.tw.z)};
    visible = visible & lane_isfinite(out.center.x) & lane_isfinite(out.center.y);

    // Pixels it can reach. When the reachable part of the disk crosses the camera plane its image is
    // unbounded: the whole image is visited and the per-pixel near test removes what lies behind.
    const L d_reach = conic_denominator(out.tw, reach);
    out.whole_image = lane_not(d_reach < L(0));
    const ConicBox<L> box = conic_box(out.tu, out.tv, out.tw, reach, d_reach);
    out.lo = {lane_min(box.center.x - box.half_x, out.center.x - filter),
              lane_min(box.center.y - box.half_y, out.center.y - filter)};
    out.hi = {lane_max(box.center.x + box.half_x, out.center.x + filter),
              lane_max(box.center.y + box.half_y, out.center.y + filter)};
    return visible;
}

// What the most opaque surfel (opacity 1) can reach: project_surfel_lanes' bound for reach = reach_rho(1).
template <typename V>
inline ReachBound<V> opaque_reach() {
    return reach_bound(reach_rho(V(1)));
}

// A cheap first cull, for surfels (one per lane) given as stored: false where project_surfel_lanes is
// certainly false too. It makes the same near-plane, transparency and off-view tests without the rotation,
// the conic or the opacity's logarithm: the off-view sphere is the one of a surfel of opacity 1 (`opaque`),
// which bounds that of any opacity up to 1, since reach_rho grows with the opacity and sphere_outside_view
// only gets harder to pass with a larger radius or margin. At opacity 1 the two tests are the same one.
// Opacities above 1 are not bounded by it and are left to the exact test.
template <typename L, typename V>
LG_HD_INLINE LaneMask<L> may_reach_view(Vec3<L> mean, L scale_u, L scale_v, L opacity,
                                        const PinholeView<V>& view, const ReachBound<V>& opaque) {
    const Vec3<L> c = rotate(view.rotation, mean) +
                      Vec3<L>{L(view.translation.x), L(view.translation.y), L(view.translation.z)};
    const L sigma = lane_max(scale_u, scale_v);  // as project_surfel_lanes takes it (NaN where it is)
    const auto off_view =
        sphere_outside_view(c, L(opaque.disk_rho) * sigma * sigma, L(opaque.filter) + L(1), view);
    return (opacity > L(kAlphaMin)) & (c.z > L(kNearPlane)) & lane_not((opacity <= L(1)) & off_view);
}

// The pixels of a projection (one lane's values): the whole image, or its reachable region rounded.
template <typename T>
LG_HD inline PixelRect reachable_pixels(bool whole_image, Vec2<T> lo, Vec2<T> hi, int width, int height) {
    return whole_image ? PixelRect{0, 0, width - 1, height - 1} : pixel_rect(lo, hi, width, height);
}

// Projects one surfel. Returns false when it cannot be seen (see project_surfel_lanes) or reaches no pixel.
template <typename T>
LG_HD inline bool project_surfel(const SurfelGeometry<T>& g, T opacity, const PinholeView<T>& view,
                                 ProjectedSurfel<T>& out) {
    ProjectionLanes<T> p;
    const bool visible = project_surfel_lanes(g, reach_rho(opacity), view, p);
    out = {p.tu,           p.tv,
           p.tw,           p.center,
           p.normal,       p.flip,
           p.depth,        p.reach,
           p.conic_center, reachable_pixels(p.whole_image, p.lo, p.hi, view.width, view.height)};
    return visible && !out.rect.empty();
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

// What the backward of the projection reads of a projected surfel (one per lane).
template <typename L>
struct ProjectionVjpInputs {
    Vec3<L> tu, tv, tw;
    Vec2<L> center;
    L flip;
    LaneMask<L> conic_center;
};

// Backward of project_surfel for visible surfels, one per lane (recomputes what it needs from the inputs).
// Branch-free like the projection: both ways of placing the filter centre are differentiated and one is
// selected per lane.
template <typename L, typename V>
LG_HD_INLINE SurfelGeometryGrad<L> project_surfel_vjp_lanes(const SurfelGeometry<L>& g,
                                                            const PinholeView<V>& view,
                                                            const ProjectionVjpInputs<L>& p,
                                                            ProjectedSurfelGrad<L> grad) {
    // 1. Filter centre -> rows of T. Near the boundary of the conic branch (d -> 0-) the centre runs off to
    // infinity and its derivative with it; no pixel then uses the filter, so its gradient is exactly 0, and
    // leaving the chain out (not multiplying by that 0) keeps 0 * inf from turning into NaN.
    const L gx = grad.center.x, gy = grad.center.y;
    const auto use_conic = p.conic_center & ((gx != L(0)) | (gy != L(0)));
    {
        const L c2 = L(kSigmaCutoff * kSigmaCutoff);
        const Vec3<L> t{c2, c2, L(-1)};
        const L d = conic_denominator(p.tw, c2);
        // center.x = sum t_k tu_k tw_k / d,   d = sum t_k tw_k^2.
        for (int k = 0; k < 3; ++k) {
            const L tk_d = t[k] / d;
            const L g_tu = gx * tk_d * p.tw[k];
            const L g_tv = gy * tk_d * p.tw[k];
            const L g_tw = gx * (tk_d * p.tu[k] - p.center.x * L(2) * tk_d * p.tw[k]) +
                           gy * (tk_d * p.tv[k] - p.center.y * L(2) * tk_d * p.tw[k]);
            grad.tu[k] += lane_select(use_conic, g_tu, L(0));
            grad.tv[k] += lane_select(use_conic, g_tv, L(0));
            grad.tw[k] += lane_select(use_conic, g_tw, L(0));
        }
    }
    {
        // The projected mean centres the filter: center = (tu.z, tv.z) / tw.z, tw.z beyond the near plane.
        const auto use_mean = lane_not(p.conic_center);
        const L inv_w = L(1) / p.tw.z;
        grad.tu.z += lane_select(use_mean, gx * inv_w, L(0));
        grad.tv.z += lane_select(use_mean, gy * inv_w, L(0));
        grad.tw.z -= lane_select(use_mean, (gx * p.center.x + gy * p.center.y) * inv_w, L(0));
    }
    // 2. T = K M with M = [a b mean_cam] (columns): dL/dM = Kᵀ dL/dT.
    const auto column_grad = [&](int c) LG_LAMBDA_INLINE -> Vec3<L> {
        return {L(view.fx) * grad.tu[c], L(view.fy) * grad.tv[c],
                L(view.cx) * grad.tu[c] + L(view.cy) * grad.tv[c] + grad.tw[c]};
    };
    const Mat3<V> Rt = transpose(view.rotation);
    const Vec3<L> g_su_tu = rotate(Rt, column_grad(0));  // dL/d(s_u t_u) in world space
    const Vec3<L> g_sv_tv = rotate(Rt, column_grad(1));
    SurfelGeometryGrad<L> out;
    out.mean = rotate(Rt, column_grad(2));

    // 3. Scales, rotation columns, and the normal (flip is piecewise constant).
    const Vec4<L> q = normalize_quaternion(g.quat);
    const Mat3<L> R = rotation_from_unit_quaternion(q);
    out.scale_u = dot(R.col(0), g_su_tu);
    out.scale_v = dot(R.col(1), g_sv_tv);
    const Mat3<L> gR = Mat3<L>::from_columns(g.scale_u * g_su_tu, g.scale_v * g_sv_tv, p.flip * grad.normal);
    out.quat = normalize_quaternion_vjp(g.quat, rotation_from_unit_quaternion_vjp(q, gR));
    return out;
}

// Backward of project_surfel for one visible surfel.
template <typename T>
LG_HD inline SurfelGeometryGrad<T> project_surfel_vjp(const SurfelGeometry<T>& g, const PinholeView<T>& view,
                                                      const ProjectedSurfel<T>& p,
                                                      const ProjectedSurfelGrad<T>& grad) {
    return project_surfel_vjp_lanes(g, view, {p.tu, p.tv, p.tw, p.center, p.flip, p.conic_center}, grad);
}

}  // namespace lumigauss::raster
