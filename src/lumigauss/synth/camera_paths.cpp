#include "lumigauss/synth/camera_paths.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Vec3d rotate_about(Vec3d v, Vec3d axis, double angle) {
    // Rodrigues' formula.
    const double c = std::cos(angle), s = std::sin(angle);
    return c * v + s * cross(axis, v) + ((1 - c) * dot(axis, v)) * axis;
}

}  // namespace

Mat3d look_at_rotation(Vec3d eye, Vec3d target, double roll) {
    const Vec3d forward = normalize(target - eye);
    Vec3d right = normalize(cross(forward, Vec3d{0, 0, 1}));
    right = rotate_about(right, forward, roll);
    const Vec3d down = cross(forward, right);
    return {{right, down, forward}};
}

Camera make_tourist_camera(const Landmark& landmark, int width, int height, std::uint64_t seed,
                           int view_index) {
    Rng rng(seed, Stream::kCamera, std::uint64_t(view_index));
    const Vec3d lo = landmark.bbox_lo, hi = landmark.bbox_hi, extent = hi - lo;
    Camera cam;
    cam.width = width, cam.height = height;
    const double focal_35mm = 35.0 * rng.uniform(0.8, 1.2);  // +-20% around a 35 mm lens (36 mm film width)
    cam.fx = cam.fy = width * focal_35mm / 36.0;
    cam.cx = 0.5 * width, cam.cy = 0.5 * height;

    // Distance at which the bounding sphere fills the narrower field of view, then nearer or farther.
    const double radius = 0.5 * length(extent);
    const double half_fov = std::atan(0.5 * std::min(width / cam.fx, height / cam.fy));
    const double distance = radius / std::sin(half_fov) * rng.uniform(0.5, 1.0);

    // Azimuth measured from the front (-Y) towards +X; +-110 degrees covers the front and both sides.
    const double azimuth = rng.uniform(-110.0, 110.0) * kDeg;
    const bool raised = rng.bernoulli(0.3);  // a balcony, a wall, steps: a few metres up
    const double eye_height = raised ? rng.uniform(3.0, 3.0 + 0.5 * extent.z) : rng.uniform(1.5, 2.0);
    const Vec3d center = 0.5 * (lo + hi);
    const Vec3d eye{center.x + distance * std::sin(azimuth), center.y - distance * std::cos(azimuth),
                    eye_height};
    const Vec3d target{center.x + rng.uniform(-0.15, 0.15) * extent.x,
                       center.y + rng.uniform(-0.15, 0.15) * extent.y,
                       lo.z + rng.uniform(0.25, 0.5) * extent.z};
    const double roll = rng.uniform(-3.0, 3.0) * kDeg;

    cam.rotation = look_at_rotation(eye, target, roll);
    cam.translation = -(cam.rotation * eye);
    return cam;
}

Ray camera_ray(const Camera& camera, double px, double py) {
    const Vec3d d_cam{(px - camera.cx) / camera.fx, (py - camera.cy) / camera.fy, 1.0};
    return {camera.center(), normalize(transpose(camera.rotation) * d_cam)};
}

}  // namespace lumigauss::synth
