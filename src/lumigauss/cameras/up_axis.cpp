#include "lumigauss/cameras/up_axis.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>

#include "lumigauss/cameras/ground_plane.h"
#include "lumigauss/math/symmetric_eigen.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss {

namespace {

// "X,Y,Z" with finite numbers (spaces allowed), or none.
std::optional<Vec3d> parse_vector(const std::string& text) {
    const auto v = parse_number_list(text, 3);
    if (!v) return std::nullopt;
    return Vec3d{(*v)[0], (*v)[1], (*v)[2]};
}

// The coordinate axis nearest to `v` (by the largest component), signed.
Vec3d nearest_axis(Vec3d v) {
    int best = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(v[a]) > std::abs(v[best])) best = a;
    Vec3d axis{};
    axis[best] = v[best] >= 0 ? 1 : -1;
    return axis;
}

Mat3d axis_panorama_frame(Vec3d axis) {
    const double half_pi = std::numbers::pi / 2;
    if (axis.z > 0.5) return Mat3d::identity();
    if (axis.z < -0.5) return rotation_about_axis(Vec3d{1, 0, 0}, std::numbers::pi);
    if (axis.y < -0.5) return rotation_about_axis(Vec3d{1, 0, 0}, half_pi);
    if (axis.y > 0.5) return rotation_about_axis(Vec3d{1, 0, 0}, -half_pi);
    if (axis.x > 0.5) return rotation_about_axis(Vec3d{0, 1, 0}, half_pi);
    return rotation_about_axis(Vec3d{0, 1, 0}, -half_pi);
}

// sum x x^T over the cameras' x axes (row 0 of each world-to-camera rotation): the up is the direction it
// is smallest along.
Mat3d x_axis_scatter(const std::vector<Mat3d>& world_to_camera) {
    Mat3d scatter{};
    for (const Mat3d& r : world_to_camera) {
        const Vec3d x = r.row(0);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) scatter(i, j) += x[i] * x[j];
    }
    return scatter;
}

}  // namespace

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
    const std::optional<Vec3d> v = parse_vector(text);
    if (!v) throw Error("up axis '" + text + "': expected one of +x, -x, +y, -y, +z, -z or a vector X,Y,Z");
    if (!(length(*v) > 0)) throw Error("up axis '" + text + "': the vector has no length");
    return normalize(*v);
}

Vec3d camera_up_direction(const std::vector<Mat3d>& world_to_camera) {
    Vec3d mean{};
    for (const Mat3d& r : world_to_camera) mean += -r.row(1);
    const Mat3d scatter = x_axis_scatter(world_to_camera);
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

Vec3d scene_up_direction(const std::vector<Mat3d>& world_to_camera, const std::vector<Vec3d>& camera_centres,
                         const std::vector<Vec3d>& points) {
    const Vec3d cameras_up = camera_up_direction(world_to_camera);
    if (!(length(cameras_up) > 0) || points.empty()) return cameras_up;
    const GroundPlane ground = find_ground_plane(points, camera_centres, cameras_up);
    if (!ground.found) return cameras_up;
    // sum x x^T + w (I - n n^T): its smallest eigenvector.
    const double w = kGroundUpWeight * double(world_to_camera.size());
    Mat3d m = x_axis_scatter(world_to_camera);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m(i, j) += w * ((i == j ? 1.0 : 0.0) - ground.normal[i] * ground.normal[j]);
    const Vec3d up = symmetric_eigen(m).vectors[0];
    return dot(up, cameras_up) < 0 ? -1.0 * up : up;
}

Vec3d estimate_up_axis(const std::vector<Camera>& cameras, const std::vector<Vec3d>& points) {
    if (cameras.empty()) throw Error("up axis auto: no camera to estimate it from");
    std::vector<Mat3d> rotations;
    std::vector<Vec3d> centres;
    for (const Camera& c : cameras) rotations.push_back(c.rotation), centres.push_back(c.center());
    const Vec3d up = scene_up_direction(rotations, centres, points);
    if (!(length(up) > 0))
        throw Error("up axis auto: the cameras' up vectors cancel out; give --up explicitly");
    return up;
}

std::string up_axis_name(Vec3d up) {
    const Vec3d axis = nearest_axis(up);
    if (length(up - axis) < 1e-9) {
        const char* names = "xyz";
        for (int a = 0; a < 3; ++a)
            if (axis[a] != 0) return std::string(axis[a] > 0 ? "+" : "-") + names[a];
    }
    char text[96];
    std::snprintf(text, sizeof text, "%.6f,%.6f,%.6f", up.x, up.y, up.z);
    return text;
}

Mat3d panorama_frame_for_up(Vec3d up) {
    if (!(length(up) > 0.5)) throw Error("panorama frame: the up vector has no length");
    up = normalize(up);
    const Vec3d axis = nearest_axis(up);
    const Vec3d turn = cross(axis, up);  // |turn| = sin of the angle; the nearest axis is < 55 deg away
    const Mat3d frame = axis_panorama_frame(axis);
    if (!(length(turn) > 1e-12)) return frame;
    return rotation_about_axis(normalize(turn), std::atan2(length(turn), dot(axis, up))) * frame;
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
