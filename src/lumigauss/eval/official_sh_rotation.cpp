#include "lumigauss/eval/official_sh_rotation.h"

#include "lumigauss/shading/sh_rotation.h"

namespace lumigauss {

Mat3d official_rot_x(double radians) {
    return rotation_about_axis(Vec3d{1, 0, 0}, -radians);
}

Mat3d official_rot_y(double radians) {
    return rotation_about_axis(Vec3d{0, 1, 0}, -radians);
}

Mat3d official_rot_z(double radians) {
    return rotation_about_axis(Vec3d{0, 0, 1}, radians);
}

Mat3d official_environment_rotation(double x0, double y0, double z0, double b) {
    // sh_rotation(A) sh_rotation(B) = sh_rotation(A B): the matrix products compose like the rotations.
    return official_rot_y(b) * official_rot_y(y0) * official_rot_x(x0) * official_rot_z(z0);
}

}  // namespace lumigauss
