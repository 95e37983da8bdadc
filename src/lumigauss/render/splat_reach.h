#pragma once
// The exact region of pixels a splat can reach, for culling work per block of pixels.
//
// A pixel gets alpha >= kAlphaMin from a splat only where rho = min(rho_object, rho_screen) <= rho_cutoff
// (surfel_kernel.h): inside the ellipse rho_object = (p.x² + p.y²) / p.z² <= rho_cutoff, where the
// homogeneous hit p = dx pa + dy pb + pd is affine in the pixel offset (dx, dy) from the filter centre, or
// inside the screen filter's disk 2 (dx² + dy²) <= rho_cutoff. The projection bounds both by one rectangle;
// for thin, tilted splats (ground seen at a grazing angle, typical of trained outdoor scenes) most of that
// rectangle is empty. This header gives the exact x-extent of the region within a band of pixel rows.
//
// Written for a lane type L (math/lanes.h). Everything is relative to the filter centre.
#include "lumigauss/math/lanes.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::raster {

// The ellipse as Q(dx, dy) = a dx² + 2b dx dy + c dy² + 2d dx + 2e dy + f <= 0, i.e. |p.xy|² <= R p.z²,
// in centre-and-extent form, plus the filter disk.
template <typename L>
struct SplatReach {
    L x, y;                // the ellipse's centre
    L half_x, half_y;      // its half extents
    L slope;               // of the line of midpoints of its horizontal chords: x_mid = x + slope (dy - y)
    L half_width0;         // the half chord through the centre
    L t_right;             // dy - y of its rightmost point (the leftmost is at -t_right)
    L filter_radius;       // of the screen filter's disk
    LaneMask<L> definite;  // false where the ellipse is not bounded and well-conditioned: keep the box there
};

template <typename L>
LG_HD_INLINE SplatReach<L> make_splat_reach(Vec3<L> pa, Vec3<L> pb, Vec3<L> pd, L rho_cutoff) {
    const L R = rho_cutoff;
    // The region depends on p only up to a common factor: scale it to order 1 first, so that the products
    // below (fourth powers of focal length x scale x depth) neither overflow nor underflow.
    const auto magnitude = [](Vec3<L> v) LG_LAMBDA_INLINE {
        return lane_max(lane_max(lane_abs(v.x), lane_abs(v.y)), lane_abs(v.z));
    };
    const L scale =
        L(1) / lane_max(lane_max(magnitude(pa), magnitude(pb)), lane_max(magnitude(pd), L(1e-30f)));
    pa = scale * pa, pb = scale * pb, pd = scale * pd;
    const auto form = [&](Vec3<L> u, Vec3<L> v)
                          LG_LAMBDA_INLINE { return u.x * v.x + u.y * v.y - R * u.z * v.z; };
    const L a = form(pa, pa), b = form(pa, pb), c = form(pb, pb), d = form(pa, pd), e = form(pb, pd);
    const L f = form(pd, pd);
    const L det = a * c - b * b;
    SplatReach<L> r;
    // Only where the quadratic form is clearly definite (a nearly parabolic region: the disk about to cross
    // the camera plane) ...
    auto definite = (a > L(0)) & (c > L(0)) & (det > L(1e-4) * a * c);
    const L safe_det = lane_select(definite, det, L(1)), safe_a = lane_select(definite, a, L(1));
    const L safe_c = lane_select(definite, c, L(1));
    r.x = (b * e - c * d) / safe_det;
    r.y = (b * d - a * e) / safe_det;
    // ... and k, the ellipse's size (x - centre)ᵀ M (x - centre) <= k, is well above the rounding of the
    // difference it comes from. In exact arithmetic k >= R p.z² > 0 for a visible splat (the pixel of its
    // projected mean has p.xy = 0), but for R near 0 (opacity just above kAlphaMin) it is a small difference
    // of large terms. Elsewhere the rectangle stays.
    const L k = -(f + d * r.x + e * r.y);
    const L k_terms = lane_abs(f) + lane_abs(d * r.x) + lane_abs(e * r.y);
    definite = definite & (k > L(1e-3f) * k_terms) & lane_isfinite(k);
    r.definite = definite;
    const L safe_k = lane_select(definite, k, L(1));
    r.half_x = lane_sqrt(safe_k * safe_c / safe_det);
    r.half_y = lane_sqrt(safe_k * safe_a / safe_det);
    r.slope = -b / safe_a;
    r.half_width0 = lane_sqrt(safe_k / safe_a);
    r.t_right = -b / safe_c * r.half_x;
    r.filter_radius = lane_sqrt(lane_max(R, L(0)) / L(kFilterInvSquare));
    return r;
}

// The x-extent [x_lo, x_hi] of the reachable region within the band of offsets dy in [dy0, dy1] (dy0 <= dy1),
// slightly widened so that rounding never cuts a pixel the kernel reaches. Returns where it is not empty.
// Only for a definite r (r.definite); the band's lanes may be several bands of one splat.
template <typename L, typename S>
LG_HD_INLINE LaneMask<L> reach_in_band(const SplatReach<S>& r, L dy0, L dy1, L& x_lo, L& x_hi) {
    // Ellipse: chords are x_mid(t) +- w(t) with t = dy - y, w(t) = w0 sqrt(1 - (t / half_y)²); the right
    // end is concave in t, the left end convex, so over [t0, t1] each is extreme at the ellipse's
    // rightmost (leftmost) point if that lies in the band, else at an end of the band.
    const L hy(r.half_y), w0(r.half_width0), slope(r.slope), tr(r.t_right), hx(r.half_x);
    const L rf(r.filter_radius);
    // Margins for rounding, in both directions: relative to the sizes involved, plus a hundredth of a pixel.
    const L margin_x = L(S(1e-3) * (lane_abs(r.x) + r.half_x + r.filter_radius) + S(1e-2));
    const L margin_y = L(S(1e-3) * (lane_abs(r.y) + r.half_y + r.filter_radius) + S(1e-2));
    dy0 = dy0 - margin_y, dy1 = dy1 + margin_y;
    const L t0 = lane_max(dy0 - L(r.y), -hy), t1 = lane_min(dy1 - L(r.y), hy);
    const auto in_ellipse = t0 <= t1;
    const L inv_hy = L(1) / lane_max(hy, L(S(1e-30)));
    const auto chord = [&](L t) LG_LAMBDA_INLINE {
        const L u = t * inv_hy;
        return w0 * lane_sqrt(lane_max(L(1) - u * u, L(0)));
    };
    const L w_t0 = chord(t0), w_t1 = chord(t1);
    const L right = lane_select((tr >= t0) & (tr <= t1), hx, lane_max(slope * t0 + w_t0, slope * t1 + w_t1));
    const L left =
        lane_select((-tr >= t0) & (-tr <= t1), -hx, lane_min(slope * t0 - w_t0, slope * t1 - w_t1));
    // Filter disk: its chord at the band's offset nearest the centre.
    const L nearest = lane_min(lane_max(L(0), dy0), dy1);
    const auto in_disk = nearest * nearest <= rf * rf;
    const L w_disk = lane_sqrt(lane_max(rf * rf - nearest * nearest, L(0)));
    // Union (hull) of what is not empty, with a margin for rounding.
    const L inf(S(1e30));
    const L lo = lane_min(lane_select(in_ellipse, L(r.x) + left, inf), lane_select(in_disk, -w_disk, inf));
    const L hi = lane_max(lane_select(in_ellipse, L(r.x) + right, -inf), lane_select(in_disk, w_disk, -inf));
    x_lo = lo - margin_x, x_hi = hi + margin_x;
    return in_ellipse | in_disk;
}

}  // namespace lumigauss::raster
