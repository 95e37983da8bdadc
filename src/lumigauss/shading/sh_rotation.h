#pragma once
// Rotation of degree-2 SH coefficients (environment lighting) by a 3x3 rotation matrix.
//
// Convention: rotating the lighting by R means the new environment shows in direction w what the old one
// showed in direction R^T w:  f'(w) = f(R^T w). (Rotating by R about +Z by +a moves a sun at azimuth b to
// azimuth b + a.) The coefficient map is linear and block-diagonal by band: band 0 is unchanged, band 1 is
// R itself in the (y, z, x) order of the basis, band 2 follows from writing the band-2 part as a traceless
// quadratic form w^T Q w, which rotates as Q' = R Q R^T (exact, no fitting).
#include <cmath>

#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

// The 9x9 coefficient matrix: new_coeffs[i] = sum_j m[i][j] * old_coeffs[j] (each RGB channel alike).
struct ShRotation {
    double m[kShCount][kShCount]{};
};

// Rotation by `radians` about the unit `axis`, right-handed (Rodrigues): R v = v cos a + (k x v) sin a
// + k (k.v)(1 - cos a).
template <typename T>
LG_HD inline Mat3<T> rotation_about_axis(Vec3<T> axis, T radians) {
    const Vec3<T> k = normalize(axis);
    const T c = std::cos(radians), s = std::sin(radians), t = 1 - c;
    return {{{c + t * k.x * k.x, t * k.x * k.y - s * k.z, t * k.x * k.z + s * k.y},
             {t * k.y * k.x + s * k.z, c + t * k.y * k.y, t * k.y * k.z - s * k.x},
             {t * k.z * k.x - s * k.y, t * k.z * k.y + s * k.x, c + t * k.z * k.z}}};
}

// The matrix that rotates the lighting by R (R must be a proper rotation).
ShRotation sh_rotation(const Mat3d& rotation);

// new = rot * old, per channel.
ShCoeffs<double> apply(const ShRotation& rot, const ShCoeffs<double>& sh);

// Convenience: apply(sh_rotation(rotation), sh).
ShCoeffs<double> rotate_sh(const ShCoeffs<double>& sh, const Mat3d& rotation);

}  // namespace lumigauss
