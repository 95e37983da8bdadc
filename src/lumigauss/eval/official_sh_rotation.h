#pragma once
// The SH rotations of the official SOL-NeRF evaluation (NeRF-OSR's `Rotation`, copied into LumiGauss as
// utils/sh_rotate_utils.py; research/lumigauss_official.md 6) in our convention.
//
// The official code rotates the 9 x 3 coefficients by left-multiplying 9 x 9 matrices rot_x(a), rot_y(a),
// rot_z(a) built for the basis of shading/sh.h (same order and signs). As active rotations of the lighting,
// i.e. the R of shading/sh_rotation.h with f'(w) = f(R^T w), they are (checked numerically by the research
// note, and against the official sparse matrices in tests/fast/eval_sol_nerf_test.cpp):
//   rot_z(a) = R(+z, +a)      rot_y(a) = R(+y, -a)      rot_x(a) = R(+x, -a)
// with R(axis, angle) right-handed (rotation_about_axis). rot_y sends +x towards +z, and rot_x(-90 deg)
// takes the panorama's zenith (+z of eval/official_sh_projection.h) to world -y, COLMAP's "up".
//
// The protocol's environment for a y-angle b is  rot_y(b) . rot_y(y0) . rot_x(x0) . rot_z(z0) . coeffs
// (the fixed alignment first, then the search angle), i.e. the one rotation
//   R(+y, -b) R(+y, -y0) R(+x, -x0) R(+z, z0).
#include "lumigauss/math/vec.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

Mat3d official_rot_x(double radians);
Mat3d official_rot_y(double radians);
Mat3d official_rot_z(double radians);

// Fixed alignment (x0, y0, z0) then the search angle b, in radians: the rotation above.
Mat3d official_environment_rotation(double x0, double y0, double z0, double b);

}  // namespace lumigauss
