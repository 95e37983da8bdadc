#pragma once
// Real spherical harmonics up to degree 4 (25 coefficients), for the sky's appearance only
// (sky_colour.h): a degree-2 environment cannot draw a sky with a sun in it, and its lighting must not be
// bent to try. Bands 0-2 are exactly sh.h's (same order, constants, no Condon-Shortley phase); bands 3 and 4
// follow the same convention: order m = -l..l, sin-type (y) terms for m < 0, cos-type (x) terms for m > 0.
#include "lumigauss/math/hd.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

inline constexpr int kSh4Count = 25;  // (4 + 1)^2

namespace sh_const {
inline constexpr double kY3m3 = 0.5900435899266435;  // sqrt(35/(2 pi)) / 4
inline constexpr double kY3m2 = 2.890611442640554;   // sqrt(105/pi) / 2
inline constexpr double kY3m1 = 0.4570457994644658;  // sqrt(21/(2 pi)) / 4
inline constexpr double kY30 = 0.3731763325901154;   // sqrt(7/pi) / 4
inline constexpr double kY32 = 1.445305721320277;    // sqrt(105/pi) / 4
inline constexpr double kY4m4 = 2.503342941796705;   // 3 sqrt(35/pi) / 4
inline constexpr double kY4m3 = 1.770130769779931;   // 3 sqrt(35/(2 pi)) / 4
inline constexpr double kY4m2 = 0.9461746957575601;  // 3 sqrt(5/pi) / 4
inline constexpr double kY4m1 = 0.6690465435572892;  // 3 sqrt(5/(2 pi)) / 4
inline constexpr double kY40 = 0.1057855469152043;   // 3 / (16 sqrt(pi))
inline constexpr double kY42 = 0.4730873478787800;   // 3 sqrt(5/pi) / 8
inline constexpr double kY44 = 0.6258357354491761;   // 3 sqrt(35/pi) / 16
}  // namespace sh_const

// Twenty-five RGB coefficients.
template <typename T>
struct Sh4Coeffs {
    Vec3<T> c[kSh4Count]{};
};

// out[k] = Y_k(dir), k < 25, for a unit direction.
template <typename T>
LG_HD constexpr void sh4_basis(Vec3<T> dir, T out[kSh4Count]) {
    using namespace sh_const;
    sh_basis(dir, out);
    const T x = dir.x, y = dir.y, z = dir.z;
    const T x2 = x * x, y2 = y * y, z2 = z * z;
    out[9] = T(kY3m3) * y * (3 * x2 - y2);
    out[10] = T(kY3m2) * x * y * z;
    out[11] = T(kY3m1) * y * (5 * z2 - 1);
    out[12] = T(kY30) * z * (5 * z2 - 3);
    out[13] = T(kY3m1) * x * (5 * z2 - 1);
    out[14] = T(kY32) * z * (x2 - y2);
    out[15] = T(kY3m3) * x * (x2 - 3 * y2);
    out[16] = T(kY4m4) * x * y * (x2 - y2);
    out[17] = T(kY4m3) * y * z * (3 * x2 - y2);
    out[18] = T(kY4m2) * x * y * (7 * z2 - 1);
    out[19] = T(kY4m1) * y * z * (7 * z2 - 3);
    out[20] = T(kY40) * (35 * z2 * z2 - 30 * z2 + 3);
    out[21] = T(kY4m1) * x * z * (7 * z2 - 3);
    out[22] = T(kY42) * (x2 - y2) * (7 * z2 - 1);
    out[23] = T(kY4m3) * x * z * (x2 - 3 * y2);
    out[24] = T(kY44) * (x2 * (x2 - 3 * y2) - y2 * (3 * x2 - y2));
}

}  // namespace lumigauss
