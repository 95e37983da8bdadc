#pragma once
// A two-sided surfel's colour as the view-dependent SH of the 3DGS PLY (model/view_sh.h), so that a baked
// file shows each side of a surfel to the cameras on that side, as the relightable render does.
//
// Seen along the unit direction d (camera -> surfel), a surfel with normal n shows colour
//     c(d) = M + H sign(s),   s = -d . n,   M = (positive + negative) / 2,   H = (positive - negative) / 2.
// The step is approximated by the odd polynomial p(s) that minimises the integral over [-1, 1] of
// |s| (sign(s) - p(s))^2: the weight |s| is the surfel's projected area, so grazing views (where a surfel
// covers nothing) matter least. Degree 1: p = 4/3 s. Degree 3: p = 2.4 s - 1.6 s^3 = 1.44 P1(s) - 0.64 P3(s).
// By the addition theorem, P_l(-d . n) = (-1)^l 4 pi / (2l + 1) sum_m Y_lm(d) Y_lm(n), so the coefficient of
// Y_lm(d) is -c_l 4 pi / (2l + 1) Y_lm(n) H for odd l, and the DC coefficient is (M - 0.5) / Y_00 (3DGS adds
// 0.5). The step has no even part: degree 2 holds degree 1's values and zero degree-2 coefficients.
// Degree 0 (one colour) is the side the cameras see more (baked_colours.h: seen_side_colours).
// A run's grazing rule (shading/surfel_side.h: a level surfel seen within a few degrees of its plane shows
// its upper side) is not baked: the expansion is smooth in s and blends both sides near s = 0 whatever the
// rule, and there a surfel covers least.
#include <span>
#include <vector>

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/surfel_model.h"

namespace lumigauss {

// Legendre coefficients c_1, c_3 of p above for an SH degree (0..3).
struct StepExpansion {
    double c1 = 0, c3 = 0;
};
StepExpansion step_expansion(int degree);

// Per surfel view_sh_coefficients(degree) x 3 values, coefficient-major (sh[(i * K + k) * 3 + c], the layout
// of model/splat_ply.h's ViewDependentSurfels). `cameras` (camera centres) only matter for degree 0. Throws
// Error when degree is outside 0..3 or `sides` does not match the model.
std::vector<float> two_sided_view_sh(const SurfelModel& model, const SurfelSides& sides, int degree,
                                     std::span<const Vec3d> cameras);

// What every writer of such values checks first: the degree is 0..3 and `values` holds
// view_sh_coefficients(degree) x 3 per surfel. Throws Error saying which does not hold.
void check_view_sh_size(std::size_t values, std::size_t surfels, int degree);

}  // namespace lumigauss
