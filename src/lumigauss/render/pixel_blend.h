#pragma once
// Front-to-back compositing of one pixel (or one pack of pixels) and its backward, shared by every backend.
//
// A pixel blends the samples of the surfels covering it in depth order: w_i = alpha_i T_i with
// T_{i+1} = T_i (1 - alpha_i), into colour, expected depth, normal and the depth-distortion map, and records
// the median depth and its contributor. The backward walks the same samples back to front, recovering
// T_i = T_{i+1} / (1 - alpha_i) and keeping the blend of the samples behind (dotted with the incoming
// gradients), which is all dL/dalpha_i needs.
// L is a lane type (math/lanes.h): a scalar, or a pack of pixels on the CPU.
#include <cstdint>

#include "lumigauss/math/vec.h"
#include "lumigauss/render/raster_constants.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::raster {

// The running sums of the forward walk.
template <typename L, int C>
struct BlendPixel {
    LaneMask<L> live{};  // the pixel still blends (false once finished, and for a lane off the image)
    L trans{};           // transmittance in front of the next sample: start at 1
    L color[C]{}, depth{}, normal[3]{}, distortion{};
    L m1{}, m2{};  // sum w m and sum w m^2 of the mapped depth m (distortion)
    L median{};
    LaneIndex<L> median_entry{};  // sorted entry giving the median depth: start at -1
    LaneIndex<L> contributors{};  // rank of the last composited sample: start at 0
};

// Blends one sample into the pixel: `alpha` is 0 where the pair does not contribute, `entry` the sample's
// sorted-entry index and `rank` its position in the tile's list plus one. `channels` <= C colours are read.
// Returns where the sample was composited.
template <typename L, int C, typename T>
LG_HD_INLINE LaneMask<L> blend_sample(BlendPixel<L, C>& s, L alpha, L z, const T* color, int channels,
                                      Vec3<T> normal, LaneIndex<L> entry, LaneIndex<L> rank) {
    // A select, not a product with a 0/1 factor: it is on the chain of dependent operations from one sample
    // to the next.
    const L a = lane_select(s.live, alpha, L(0));
    const L t = s.trans;
    const L t_next = t * (L(1) - a);
    // A sample that would take T below the threshold finishes the pixel without being composited.
    // (a == 0 leaves t_next = t, which is at or above the threshold.)
    const auto stop = t_next < L(kTransmittanceMin);
    s.live = s.live & lane_not(stop);
    const L w = lane_select(stop, L(0), a * t);
    for (int c = 0; c < C; ++c) s.color[c] += w * L(c < channels ? color[c] : T(0));
    const auto composited = w > L(0);
    const L zc = lane_select(composited, z, L(1));  // z is arbitrary where the pair does not contribute
    s.depth += w * zc;
    for (int k = 0; k < 3; ++k) s.normal[k] += w * L(normal[k]);
    const L m = distortion_depth(zc);
    s.distortion += w * (m * m * (L(1) - t) + s.m2 - L(2) * m * s.m1);
    s.m1 += w * m;
    s.m2 += w * m * m;
    const auto median = lane_select(composited, t, L(0)) > L(0.5);
    s.median = lane_select(median, zc, s.median);
    s.median_entry = lane_select(median, entry, s.median_entry);
    s.contributors = lane_select(composited, rank, s.contributors);
    s.trans = lane_select(composited, t_next, t);
    return composited;
}

// The state of the backward walk, and the pixel's incoming gradients (zero where a map has none).
//
// dL/dalpha_i needs, for every map, this sample's value against the blend of the samples behind it:
// sum over maps of (value_i - behind_i) . dL/dmap. The incoming gradients are fixed for the whole walk, so
// instead of one "behind" blend per map (colours, normal, depth, alpha, distortion) the walk keeps their
// dot product with the gradients, which blends the same way: behind . g <- a (value . g) + (1 - a) behind .
// g.
template <typename L, int C>
struct BlendPixelBackward {
    L trans{};       // transmittance behind the sample being processed: T_final at first
    L behind_dot{};  // sum over maps of (blend of the samples behind) . dL/dmap
    L g_color[C]{}, g_normal[3]{}, g_depth{}, g_alpha{}, g_dist{}, g_median{};
    L bg_term{};  // T_final * (background . dL/dcolor)
    L a_total{};  // 1 - T_final
    L m1{}, m2{};
    LaneIndex<L> contributors{}, median_entry{};
};

// What a composited sample receives.
template <typename L>
struct BlendSampleGrad {
    L g_alpha, g_z;  // dL/dalpha and dL/dz of the sample (0 where it was not composited)
    L w;             // its blending weight: dL/dcolor_c = w g_color_c, dL/dnormal_k = w g_normal_k
};

// What un-blending a sample needs that does not depend on the walk (only on the sample and the pixel's
// fixed gradients): its value in every map dotted with the map's gradient, and its mapped depth. (Split
// from unblend_sample so that its work can be scheduled apart from the walk's; the CPU backend measured it
// best inside the walk.)
template <typename L>
struct SampleValues {
    L value_dot;  // sum over maps of (the sample's value) . dL/dmap
    L m, dm_dz;   // distortion depth and its derivative
};

template <typename L, int C, typename T>
LG_HD_INLINE SampleValues<L> sample_values(const BlendPixelBackward<L, C>& s, LaneMask<L> composited,
                                           L z_sample, const T* color, int channels, Vec3<T> normal) {
    SampleValues<L> v;
    // The terms known from the entry alone come first, so that the chain of additions after z (the end
    // of the kernel's longest path) is short.
    v.value_dot = s.g_alpha;
    for (int c = 0; c < C; ++c) v.value_dot += L(c < channels ? color[c] : T(0)) * s.g_color[c];
    for (int k = 0; k < 3; ++k) v.value_dot += L(normal[k]) * s.g_normal[k];
    const L z = lane_select(composited, z_sample, L(1));  // any finite depth where it was not composited
    const DistortionDepth<L> mapped = distortion_depth_and_derivative(z);
    v.m = mapped.m;
    v.dm_dz = mapped.dm_dz;
    const L dist_w =
        (v.m * v.m * s.a_total + s.m2 - L(2) * v.m * s.m1) * s.g_dist;  // dL/dw of the distortion
    v.value_dot += z * s.g_depth + dist_w;
    return v;
}

// Un-blends one sample, back to front: `a` is its alpha where the forward composited it, else 0 (which
// leaves the state unchanged); `v` its sample_values.
template <typename L, int C>
LG_HD_INLINE BlendSampleGrad<L> unblend_sample(BlendPixelBackward<L, C>& s, L a, const SampleValues<L>& v,
                                               LaneIndex<L> entry) {
    const L one_minus_a = L(1) - a;
    // One division for both quotients: the CPU walk's loop had three per entry (this, the background
    // term's and the distortion's 1 / z) against some 65 other instructions, and each holds the divider for
    // several cycles.
    const L inv_one_minus_a = L(1) / one_minus_a;
    const L t_before = s.trans * inv_one_minus_a;
    const L w = a * t_before;
    const auto composited = a > L(0);
    BlendSampleGrad<L> out;
    out.w = w;
    out.g_alpha =
        lane_select(composited, t_before * (v.value_dot - s.behind_dot) - s.bg_term * inv_one_minus_a, L(0));
    const L g_median = lane_select(s.median_entry == entry, s.g_median, L(0));
    const L g_z = w * s.g_depth + g_median + L(2) * w * (v.m * s.a_total - s.m1) * s.g_dist * v.dm_dz;
    out.g_z = lane_select(composited, g_z, L(0));

    // Fold this sample into the blend behind the sample in front of it.
    s.behind_dot = a * v.value_dot + one_minus_a * s.behind_dot;
    s.trans = t_before;
    return out;
}

}  // namespace lumigauss::raster
