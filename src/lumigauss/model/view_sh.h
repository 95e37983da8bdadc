#pragma once
// View-dependent colour of 3DGS/2DGS models: real SH up to degree 3 in the convention of the Inria 3DGS
// code (Condon-Shortley signs on the odd-m terms, colour = 0.5 + sum, clamped at 0 by the caller).
// This is the appearance model of imported PLY files, not the lighting SH of shading/sh.h.
#include "lumigauss/math/vec.h"

namespace lumigauss {

inline constexpr int view_sh_coefficients(int degree) {
    return (degree + 1) * (degree + 1);
}

// The basis functions of degree <= `degree` at the unit direction `dir` (view_sh_coefficients(degree)
// values). They are orthonormal on the sphere, so the addition theorem holds: sum over m of the degree-l
// functions at a and at b is (2l + 1) / (4 pi) P_l(a . b).
template <typename T>
LG_HD inline void view_sh_basis(int degree, Vec3<T> dir, T basis[16]) {
    const T c0 = T(0.28209479177387814), c1 = T(0.4886025119029199);
    const T x = dir.x, y = dir.y, z = dir.z;
    basis[0] = c0;
    if (degree > 0) basis[1] = -c1 * y, basis[2] = c1 * z, basis[3] = -c1 * x;
    if (degree > 1) {
        const T xx = x * x, yy = y * y, zz = z * z;
        basis[4] = T(1.0925484305920792) * x * y;
        basis[5] = T(-1.0925484305920792) * y * z;
        basis[6] = T(0.31539156525252005) * (2 * zz - xx - yy);
        basis[7] = T(-1.0925484305920792) * x * z;
        basis[8] = T(0.5462742152960396) * (xx - yy);
        if (degree > 2) {
            basis[9] = T(-0.5900435899266435) * y * (3 * xx - yy);
            basis[10] = T(2.890611442640554) * x * y * z;
            basis[11] = T(-0.4570457994644658) * y * (4 * zz - xx - yy);
            basis[12] = T(0.3731763325901154) * z * (2 * zz - 3 * xx - 3 * yy);
            basis[13] = T(-0.4570457994644658) * x * (4 * zz - xx - yy);
            basis[14] = T(1.445305721320277) * z * (xx - yy);
            basis[15] = T(-0.5900435899266435) * x * (xx - 3 * yy);
        }
    }
}

// `sh` holds coefficient k of channel c at sh[3 * k + c]; `dir` is the unit direction camera -> surfel.
template <typename T>
LG_HD inline Vec3<T> eval_view_sh(int degree, const T* sh, Vec3<T> dir) {
    T basis[16];
    view_sh_basis(degree, dir, basis);
    Vec3<T> out{};
    for (int k = 0; k < view_sh_coefficients(degree); ++k)
        for (int c = 0; c < 3; ++c) out[c] += basis[k] * sh[3 * k + c];
    return out;
}

}  // namespace lumigauss
