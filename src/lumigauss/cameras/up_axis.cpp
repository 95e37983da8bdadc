#include "lumigauss/cameras/up_axis.h"

#include <cctype>
#include <cmath>
#include <numbers>

#include "lumigauss/math/symmetric_eigen.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

Vec3d parse_up_axis(const std::string& text) {
    std::string s;
    for (char c : text) s += char(std::tolower(static_cast<unsigned char>(c)));
    double sign = 1;
    if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
        sign = s[0] == '-' ? -1 : 1;
        s = s.substr(1);
    }
    if (s == "x") return {sign, 0, 0};
    if (s == "y") return {0, sign, 0};
    if (s == "z") return {0, 0, sign};
    throw Error("up axis '" + text + "': expected one of +x, -x, +y, -y, +z, -z (or auto)");
}

Vec3d camera_up_direction(const std::vector<Mat3d>& world_to_camera) {
    Vec3d mean{};
    Mat3d scatter{};
    for (const Mat3d& r : world_to_camera) {
        mean += -r.row(1);
        const Vec3d x = r.row(0);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) scatter(i, j) += x[i] * x[j];
    }
    const double n = double(world_to_camera.size());
    if (!(length(mean) > 1e-9 * n)) return {};
    const SymmetricEigen e = symmetric_eigen(scatter);
    // Level x axes in at least two directions: the second eigenvalue is a real share of the scatter (an
    // x axis turned by t from the first direction adds sin^2 t).
    Vec3d up = e.values[1] > 0.05 * n ? e.vectors[0] : mean - dot(mean, e.vectors[2]) * e.vectors[2];
    if (!(length(up) > 1e-9)) return {};
    up = normalize(up);
    return dot(up, mean) < 0 ? -1.0 * up : up;
}

Vec3d estimate_up_axis(const std::vector<Camera>& cameras) {
    if (cameras.empty()) throw Error("up axis auto: no camera to estimate it from");
    Vec3d mean{};
    for (const Camera& c : cameras) mean += -c.rotation.row(1);
    int best = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(mean[a]) > std::abs(mean[best])) best = a;
    if (!(std::abs(mean[best]) > 1e-9 * double(cameras.size())))
        throw Error("up axis auto: the cameras' up vectors cancel out; give --up explicitly");
    Vec3d up{};
    up[best] = mean[best] > 0 ? 1 : -1;
    return up;
}

std::string up_axis_name(Vec3d up) {
    const char* names = "xyz";
    for (int a = 0; a < 3; ++a)
        if (std::abs(up[a]) > 0.5) return std::string(up[a] > 0 ? "+" : "-") + names[a];
    return "?";
}

Mat3d panorama_frame_for_up(Vec3d up) {
    const double half_pi = std::numbers::pi / 2;
    if (up.z > 0.5) return Mat3d::identity();
    if (up.z < -0.5) return rotation_about_axis(Vec3d{1, 0, 0}, std::numbers::pi);
    if (up.y < -0.5) return rotation_about_axis(Vec3d{1, 0, 0}, half_pi);
    if (up.y > 0.5) return rotation_about_axis(Vec3d{1, 0, 0}, -half_pi);
    if (up.x > 0.5) return rotation_about_axis(Vec3d{0, 1, 0}, half_pi);
    if (up.x < -0.5) return rotation_about_axis(Vec3d{0, 1, 0}, -half_pi);
    throw Error("panorama frame: the up vector is not a coordinate axis");
}

ShCoeffs<double> rotate_about_up(const ShCoeffs<double>& sh, Vec3d up, double degrees) {
    if (degrees == 0) return sh;
    return rotate_sh(sh, rotation_about_axis(up, degrees * std::numbers::pi / 180.0));
}

std::vector<double> spin_angles(int frames, double start_degrees) {
    std::vector<double> angles;
    for (int k = 0; k < frames; ++k) angles.push_back(start_degrees + 360.0 * double(k) / double(frames));
    return angles;
}

}  // namespace lumigauss
