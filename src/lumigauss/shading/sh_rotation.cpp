#include "lumigauss/shading/sh_rotation.h"

namespace lumigauss {
namespace {

// Band 1: sum_m L_1m Y_1m(w) = kY1 * a.w with a = (L11, L1-1, L10) in xyz order; f(R^T w) = kY1 (R a).w.
void rotate_band1(const Mat3d& r, const double in[3], double out[3]) {
    const Vec3d a{in[2], in[0], in[1]};
    const Vec3d ra = r * a;
    out[0] = ra.y;
    out[1] = ra.z;
    out[2] = ra.x;
}

// Band 2 as a symmetric traceless quadratic form: sum_m L_2m Y_2m(w) = w^T Q w on the unit sphere
// (using 3z^2 - 1 = 2z^2 - x^2 - y^2 there). in/out = (L2-2, L2-1, L20, L21, L22).
Mat3d band2_to_form(const double in[5]) {
    using namespace sh_const;
    const double xy = kY2 * in[0] / 2, yz = kY2 * in[1] / 2, xz = kY2 * in[3] / 2;
    const double zonal = kY20 * in[2], sectoral = kY22 * in[4];
    return {{{-zonal + sectoral, xy, xz}, {xy, -zonal - sectoral, yz}, {xz, yz, 2 * zonal}}};
}

void form_to_band2(const Mat3d& q, double out[5]) {
    using namespace sh_const;
    out[0] = 2 * q(0, 1) / kY2;
    out[1] = 2 * q(1, 2) / kY2;
    out[2] = q(2, 2) / (2 * kY20);
    out[3] = 2 * q(0, 2) / kY2;
    out[4] = (q(0, 0) - q(1, 1)) / (2 * kY22);
}

// f(R^T w) = w^T (R Q R^T) w: the form rotates by conjugation, and stays symmetric and traceless.
void rotate_band2(const Mat3d& r, const double in[5], double out[5]) {
    form_to_band2(r * band2_to_form(in) * transpose(r), out);
}

}  // namespace

ShRotation sh_rotation(const Mat3d& rotation) {
    ShRotation rot;
    rot.m[0][0] = 1;
    // Columns of each band block are the images of the unit coefficient vectors.
    for (int j = 0; j < 3; ++j) {
        double e[3]{}, col[3];
        e[j] = 1;
        rotate_band1(rotation, e, col);
        for (int i = 0; i < 3; ++i) rot.m[1 + i][1 + j] = col[i];
    }
    for (int j = 0; j < 5; ++j) {
        double e[5]{}, col[5];
        e[j] = 1;
        rotate_band2(rotation, e, col);
        for (int i = 0; i < 5; ++i) rot.m[4 + i][4 + j] = col[i];
    }
    return rot;
}

ShCoeffs<double> apply(const ShRotation& rot, const ShCoeffs<double>& sh) {
    ShCoeffs<double> out;
    for (int i = 0; i < kShCount; ++i)
        for (int j = 0; j < kShCount; ++j) out.c[i] += rot.m[i][j] * sh.c[j];
    return out;
}

ShCoeffs<double> rotate_sh(const ShCoeffs<double>& sh, const Mat3d& rotation) {
    return apply(sh_rotation(rotation), sh);
}

}  // namespace lumigauss
