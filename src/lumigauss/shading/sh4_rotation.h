#pragma once
// Rotation of a degree-4 SH (the sky's residual, sh_degree4.h) by a 3x3 rotation, in the convention of
// sh_rotation.h: the rotated function shows in direction w what the old one showed in R^T w. A rotation
// keeps each band, so the rotated function is again a degree-4 SH; its coefficients are its projection onto
// the basis, integrated exactly by a product rule (5-point Gauss-Legendre in z, 10 equal steps in azimuth:
// exact for the degree-8 products of two degree-4 functions).
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

Sh4Coeffs<float> rotate_sh4(const Sh4Coeffs<float>& sh, const Mat3d& rotation);

}  // namespace lumigauss
