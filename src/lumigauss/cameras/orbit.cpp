#include "lumigauss/cameras/orbit.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/util/error.h"

namespace lumigauss {

Vec3d point_cloud_centre(const std::vector<Vec3f>& points) {
    if (points.empty()) throw Error("orbit: the scene has no SfM point to find its centre");
    Vec3d c{};
    std::vector<double> v(points.size());
    for (int a = 0; a < 3; ++a) {
        for (std::size_t i = 0; i < points.size(); ++i) v[i] = double(points[i][a]);
        const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
        std::nth_element(v.begin(), mid, v.end());
        c[a] = *mid;
    }
    return c;
}

void orbit_basis(Vec3d up, Vec3d& e1, Vec3d& e2) {
    const Vec3d u = normalize(up);
    // The coordinate axis least aligned with up, made perpendicular to it.
    int a = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(u[k]) < std::abs(u[a])) a = k;
    Vec3d axis{};
    axis[a] = 1;
    e1 = normalize(axis - dot(axis, u) * u);
    e2 = cross(u, e1);
}

Camera look_at(const Camera& intrinsics, Vec3d eye, Vec3d target, Vec3d up) {
    const Vec3d d = target - eye;
    if (!(length(d) > 0)) throw Error("look_at: the camera stands at its target");
    const Vec3d f = normalize(d);
    Vec3d right = cross(f, up);
    if (length(right) < 1e-9 * length(up)) {
        Vec3d e1, e2;
        orbit_basis(up, e1, e2);
        right = cross(f, e1);
    }
    right = normalize(right);
    const Vec3d down = cross(f, right);
    Camera c = intrinsics;
    c.rotation = {{right, down, f}};
    c.translation = -(c.rotation * eye);
    return c;
}

Orbit orbit_from_cameras(const std::vector<Camera>& cameras, Vec3d centre, Vec3d up) {
    if (cameras.empty()) throw Error("orbit: no camera to place the circle");
    Orbit o;
    o.centre = centre;
    o.up = normalize(up);
    Vec3d e1, e2;
    orbit_basis(o.up, e1, e2);
    double height = 0, radius = 0;
    for (const Camera& c : cameras) {
        const Vec3d off = c.center() - centre;
        const double h = dot(off, o.up);
        height += h;
        radius += length(off - h * o.up);
    }
    o.height = height / double(cameras.size());
    o.radius = radius / double(cameras.size());
    if (!(o.radius > 1e-9 * (1 + std::abs(o.height))))
        throw Error(
            "orbit: the scene's cameras stand on the up axis through its centre; no circle to follow");
    const Vec3d first = cameras.front().center() - centre;
    o.start_azimuth = std::atan2(dot(first, e2), dot(first, e1));
    return o;
}

std::string frame_name(const std::string& prefix, int k, int count) {
    int digits = 1;
    for (int v = std::max(count - 1, 0); v >= 10; v /= 10) ++digits;
    std::string n = std::to_string(k);
    const int width = std::max(3, digits);
    if (int(n.size()) < width) n.insert(0, std::size_t(width) - n.size(), '0');
    return prefix + n;
}

std::vector<NamedCamera> orbit_cameras(const Orbit& orbit, const Camera& intrinsics, int frames,
                                       const std::string& prefix) {
    if (frames < 1) throw Error("orbit: needs at least one frame");
    Vec3d e1, e2;
    orbit_basis(orbit.up, e1, e2);
    std::vector<NamedCamera> out;
    for (int k = 0; k < frames; ++k) {
        const double a = orbit.start_azimuth + 2 * std::numbers::pi * double(k) / double(frames);
        const Vec3d eye =
            orbit.centre + orbit.height * orbit.up + orbit.radius * (std::cos(a) * e1 + std::sin(a) * e2);
        out.push_back({frame_name(prefix, k, frames), look_at(intrinsics, eye, orbit.centre, orbit.up)});
    }
    return out;
}

}  // namespace lumigauss
