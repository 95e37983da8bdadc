#pragma once
// The backward's (surfel, tile) gradient slots, shared by every backend: what the pixels of one tile send
// one surfel, in the kernel's own variables (surfel_kernel.h), and the per-surfel step that turns the sum
// of a surfel's slots into its gradients (through the projection's backward).
#include "lumigauss/render/pixel_blend.h"
#include "lumigauss/render/surfel_kernel.h"
#include "lumigauss/render/surfel_projection.h"

namespace lumigauss::raster {

// The values of a slot, in order.
struct GradSlot {
    static constexpr int kPa = 0, kPb = 3, kPd = 6, kTw = 9, kCenter = 12, kNormal = 14, kOpacity = 17,
                         kColor = 18;
    LG_HD static constexpr int values(int channels) { return kColor + channels; }
};

// What one pixel adds to the slot of the sample it just un-blended, into q[0, GradSlot::values(C)):
// the kernel's gradient terms `t`, the sample's blending weight times the pixel's normal and colour
// gradients (0 past the pixel's channels, as the walk's g_color is).
template <typename L, int C>
LG_HD_INLINE void slot_values(const SplatGradTerms<L>& t, const BlendSampleGrad<L>& r,
                              const BlendPixelBackward<L, C>& s, L* q) {
    using S = GradSlot;
    for (int m = 0; m < 3; ++m) {
        q[S::kPa + m] = t.dx * t.g_p[m];
        q[S::kPb + m] = t.dy * t.g_p[m];
        q[S::kPd + m] = t.g_p[m];
        q[S::kTw + m] = t.g_tw[m];
        q[S::kNormal + m] = r.w * s.g_normal[m];
    }
    q[S::kCenter] = t.g_center.x;
    q[S::kCenter + 1] = t.g_center.y;
    q[S::kOpacity] = t.g_opacity;
    for (int c = 0; c < C; ++c) q[S::kColor + c] = r.w * s.g_color[c];
}

// A visible surfel's gradients from the sum of its slots (colours: the sum's colour values as they are).
template <typename L>
struct SurfelSlotGrad {
    SurfelGeometryGrad<L> geometry;  // mean, quaternion, scales
    L opacity;
    Vec2<L> mean2d;  // dL/d(screen translation of the projected centre), pixels: for densification
};

// `sum(k)` is value k of the summed slot; `ps` the projection's state, `quat` and the scales the surfel's
// inputs as given. The expansion origin of the kernel is held fixed (to_ray_transform_grad).
template <typename L, typename V, typename Sum>
LG_HD_INLINE SurfelSlotGrad<L> surfel_grad_from_slots(Sum sum, const ProjectionVjpInputs<L>& ps, Vec4<L> quat,
                                                      L scale_u, L scale_v, const PinholeView<V>& view) {
    using S = GradSlot;
    const auto vec3 = [&](int k) LG_LAMBDA_INLINE { return Vec3<L>{sum(k), sum(k + 1), sum(k + 2)}; };
    SplatGrad<L> sg;
    sg.pa = vec3(S::kPa), sg.pb = vec3(S::kPb), sg.pd = vec3(S::kPd), sg.tw = vec3(S::kTw);
    sg.center = {sum(S::kCenter), sum(S::kCenter + 1)};
    sg.opacity = sum(S::kOpacity);
    ProjectedSurfelGrad<L> pg{};
    pg.normal = vec3(S::kNormal);
    SurfelSlotGrad<L> out;
    out.opacity = L(0);
    to_ray_transform_grad(ps.tu, ps.tv, ps.tw, ps.center, sg, pg, out.opacity);
    const SurfelGeometry<L> geometry{{L(0), L(0), L(0)}, quat, scale_u, scale_v};  // the mean: not read
    out.geometry = project_surfel_vjp_lanes(geometry, view, ps, pg);
    // A translation by delta pixels adds delta * tw.z to the third column of rows tu and tv. Like the
    // reference, it leaves out the low-pass branch.
    out.mean2d = {pg.tu.z * ps.tw.z, pg.tv.z * ps.tw.z};
    return out;
}

}  // namespace lumigauss::raster
