#pragma once
// The view-dependent colour of a 3DGS splat exactly as the Inria code's eval_sh computes it (its SH_C0..SH_C3
// constants and term order, written out here independently of model/view_sh.h), + 0.5, clamped at 0: how
// the tests' own readers of exported files (ply-3dgs, spz) colour a splat.
#include <algorithm>

#include "lumigauss/math/vec.h"

namespace lumigauss::testing {

// `dc[c]` the DC coefficient of channel c; `rest(k, c)` coefficient k >= 1 of channel c; `d` the unit
// direction camera -> splat.
template <typename Rest>
Vec3d inria_sh_colour(int degree, const double dc[3], Rest rest, Vec3d d) {
    const double C0 = 0.28209479177387814, C1 = 0.4886025119029199;
    const double C2[] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                         0.5462742152960396};
    const double C3[] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                         -0.4570457994644658, 1.445305721320277, -0.5900435899266435};
    Vec3d out;
    for (int c = 0; c < 3; ++c) {
        const auto f = [&](int k) { return double(rest(k, c)); };
        const double x = d.x, y = d.y, z = d.z, xx = x * x, yy = y * y, zz = z * z;
        double v = C0 * dc[c];
        if (degree > 0) v += -C1 * y * f(1) + C1 * z * f(2) - C1 * x * f(3);
        if (degree > 1)
            v += C2[0] * x * y * f(4) + C2[1] * y * z * f(5) + C2[2] * (2 * zz - xx - yy) * f(6) +
                 C2[3] * x * z * f(7) + C2[4] * (xx - yy) * f(8);
        if (degree > 2)
            v += C3[0] * y * (3 * xx - yy) * f(9) + C3[1] * x * y * z * f(10) +
                 C3[2] * y * (4 * zz - xx - yy) * f(11) + C3[3] * z * (2 * zz - 3 * xx - 3 * yy) * f(12) +
                 C3[4] * x * (4 * zz - xx - yy) * f(13) + C3[5] * z * (xx - yy) * f(14) +
                 C3[6] * x * (xx - 3 * yy) * f(15);
        out[c] = std::max(0.0, v + 0.5);
    }
    return out;
}

}  // namespace lumigauss::testing
