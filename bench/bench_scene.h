#pragma once
// A benchmark scene shaped like a trained outdoor model: surfels lying on the surfaces of a building and the
// ground in front of it (oriented in the surface, sized so that neighbours overlap as after training), seen
// by a camera framing the building.
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/render/raster_types.h"

namespace lumigauss::bench {

struct Plane {
    Vec3d origin, edge_u, edge_v;  // a parallelogram
    double area() const { return length(cross(edge_u, edge_v)); }
};

inline Camera bench_camera(int width, int height) {
    Camera cam;
    cam.width = width, cam.height = height;
    cam.fx = cam.fy = 0.9 * width;
    cam.cx = 0.5 * width, cam.cy = 0.5 * height;
    // At (0, -30, 8) in a z-up world, looking at (0, 0, 6): camera z forward, y down.
    const Vec3d eye{0, -30, 8}, target{0, 0, 6};
    const Vec3d fwd = normalize(target - eye);
    const Vec3d right = normalize(cross(fwd, Vec3d{0, 0, 1}));
    const Vec3d down = cross(fwd, right);
    cam.rotation = {{right, down, fwd}};  // rows: camera axes in world coordinates
    cam.translation = -(cam.rotation * eye);
    return cam;
}

// `count` surfels on a 16 x 12 x 14 m building and 60 x 40 m of ground. `overlap` scales the surfel size:
// about how many 1-sigma disks cover a point of a surface.
inline SurfelBatch<float> bench_surfels(std::size_t count, std::uint32_t seed = 1, double overlap = 3.0,
                                        int channels = 3) {
    const Plane planes[] = {
        {{-30, -25, 0}, {60, 0, 0}, {0, 40, 0}},  // ground
        {{-8, -6, 0}, {16, 0, 0}, {0, 0, 14}},    // front wall
        {{-8, -6, 0}, {0, 12, 0}, {0, 0, 14}},    // left wall
        {{8, -6, 0}, {0, 12, 0}, {0, 0, 14}},     // right wall
        {{-8, -6, 14}, {16, 0, 0}, {0, 12, 0}},   // roof
        {{-10, -8, 10}, {20, 0, 0}, {0, 4, 0}},   // overhang
    };
    double total = 0;
    for (const Plane& p : planes) total += p.area();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(0, 1);
    SurfelBatch<float> s;
    s.channels = channels;
    s.resize(count);
    std::size_t i = 0;
    for (const Plane& p : planes) {
        const std::size_t n =
            std::min(count - i, std::size_t(std::llround(double(count) * p.area() / total)));
        const double sigma = std::sqrt(overlap * p.area() / (double(n) * M_PI));
        const Vec3d tu = normalize(p.edge_u), tv = normalize(cross(cross(p.edge_u, p.edge_v), p.edge_u));
        for (std::size_t k = 0; k < n; ++k, ++i) {
            const Vec3d pos = p.origin + uni(rng) * p.edge_u + uni(rng) * p.edge_v;
            const double a = 2 * M_PI * uni(rng);  // random in-plane rotation
            const Vec3d u = std::cos(a) * tu + std::sin(a) * tv, v = cross(normalize(cross(tu, tv)), u);
            const Vec4<double> q = quaternion_from_rotation(Mat3d::from_columns(u, v, cross(u, v)));
            for (int c = 0; c < 3; ++c) s.means[3 * i + c] = float(pos[c]);
            for (int c = 0; c < 4; ++c) s.quats[4 * i + c] = float(q[c]);
            s.scales[2 * i] = float(sigma * (0.5 + uni(rng))),
                         s.scales[2 * i + 1] = float(sigma * (0.5 + uni(rng)));
            s.opacities[i] = float(0.3 + 0.69 * uni(rng));
            for (int c = 0; c < channels; ++c) s.colors[i * channels + c] = float(uni(rng));
        }
    }
    s.resize(i);
    return s;
}

// A benchmark's camera and surfels, made once per size for every benchmark of the program.
struct BenchFixture {
    Camera cam;
    SurfelBatch<float> surfels;
};
inline const BenchFixture& bench_fixture(int width, int height, int count) {
    static std::map<std::tuple<int, int, int>, BenchFixture> cache;
    auto& f = cache[{width, height, count}];
    if (f.surfels.size() == 0) f = {bench_camera(width, height), bench_surfels(std::size_t(count))};
    return f;
}

}  // namespace lumigauss::bench
