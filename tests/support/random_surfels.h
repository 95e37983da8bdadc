#pragma once
// Random small scenes for rasterizer tests: surfels scattered in front of a camera.
#include <random>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss::testing {

inline Camera test_camera(int width = 40, int height = 36) {
    Camera cam;
    cam.width = width, cam.height = height;
    cam.fx = 0.9 * width, cam.fy = 0.9 * width;
    cam.cx = 0.5 * width + 0.3, cam.cy = 0.5 * height - 0.2;  // slightly off-centre on purpose
    // A rotated camera: looks roughly along +z after a small tilt, with a translation.
    const Vec4<double> q = normalize_quaternion(Vec4<double>{1.0, 0.05, -0.08, 0.03});
    cam.rotation = rotation_from_unit_quaternion(q);
    cam.translation = {0.1, -0.2, 0.3};
    return cam;
}

struct RandomSceneOptions {
    int count = 12;
    int channels = 3;
    double min_depth = 2.0, max_depth = 6.0;
    double min_scale = 0.08, max_scale = 0.5;
    double min_opacity = 0.15, max_opacity = 0.95;
};

// Surfels whose centres lie inside the camera's view frustum (placed in camera space, then mapped to world).
template <typename T>
SurfelBatch<T> random_surfels(const Camera& cam, std::uint32_t seed, const RandomSceneOptions& o = {}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::normal_distribution<double> gauss(0.0, 1.0);
    SurfelBatch<T> s;
    s.channels = o.channels;
    s.resize(std::size_t(o.count));
    const Mat3d Rt = transpose(cam.rotation);
    for (int i = 0; i < o.count; ++i) {
        const double z = o.min_depth + (o.max_depth - o.min_depth) * uni(rng);
        const double px = (uni(rng) * 1.2 - 0.1) * cam.width, py = (uni(rng) * 1.2 - 0.1) * cam.height;
        const Vec3d p_cam{(px - cam.cx) / cam.fx * z, (py - cam.cy) / cam.fy * z, z};
        const Vec3d p_world = Rt * (p_cam - cam.translation);
        for (int k = 0; k < 3; ++k) s.means[3 * i + k] = T(p_world[k]);
        for (int k = 0; k < 4; ++k) s.quats[4 * i + k] = T(gauss(rng) * (0.5 + uni(rng)));
        for (int k = 0; k < 2; ++k)
            s.scales[2 * i + k] = T(o.min_scale + (o.max_scale - o.min_scale) * uni(rng));
        s.opacities[i] = T(o.min_opacity + (o.max_opacity - o.min_opacity) * uni(rng));
        for (int c = 0; c < o.channels; ++c) s.colors[std::size_t(i) * o.channels + c] = T(uni(rng));
    }
    return s;
}

template <typename To, typename From>
SurfelBatch<To> convert_batch(const SurfelBatch<From>& in) {
    SurfelBatch<To> out;
    out.channels = in.channels;
    const auto conv = [](const std::vector<From>& v) { return std::vector<To>(v.begin(), v.end()); };
    out.means = conv(in.means), out.quats = conv(in.quats), out.scales = conv(in.scales);
    out.opacities = conv(in.opacities), out.colors = conv(in.colors);
    return out;
}

}  // namespace lumigauss::testing
