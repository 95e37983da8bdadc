#include "lumigauss/synth/pedestrians.h"

#include <cmath>
#include <vector>

#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

// Clothes: any fairly saturated colour; skin: a range of tones.
Vec3d clothes_colour(Rng& rng) {
    return {rng.uniform(0.05, 0.85), rng.uniform(0.05, 0.85), rng.uniform(0.05, 0.85)};
}
Vec3d skin_colour(Rng& rng) {
    return Vec3d{0.62, 0.45, 0.34} * rng.uniform(0.35, 1.1);
}

bool inside_footprint(const Landmark& l, double x, double y, double margin) {
    return x > l.bbox_lo.x - margin && x < l.bbox_hi.x + margin && y > l.bbox_lo.y - margin &&
           y < l.bbox_hi.y + margin;
}

void add_person(World& world, Rng& rng, double x, double y) {
    const double height = rng.uniform(1.55, 1.95);
    const int body = int(world.materials.size());
    world.materials.push_back(solid(clothes_colour(rng)));
    Primitive head;
    if (rng.bernoulli(0.6)) {
        const double r = rng.uniform(0.2, 0.3);
        Primitive torso = make_cylinder(x, y, r, 0.0, height - 0.25, body);
        torso.transient = true;
        world.prims.push_back(torso);
    } else {
        const double hx = rng.uniform(0.2, 0.3), hy = rng.uniform(0.15, 0.25);
        Primitive torso = make_box({x - hx, y - hy, 0.0}, {x + hx, y + hy, height - 0.25}, body);
        torso.transient = true;
        world.prims.push_back(torso);
    }
    world.materials.push_back(solid(skin_colour(rng)));
    head = make_sphere({x, y, height - 0.13}, 0.13, body + 1);
    head.transient = true;
    world.prims.push_back(head);
}

}  // namespace

int add_pedestrians(World& world, const Landmark& landmark, const Camera& camera, std::uint64_t seed,
                    int view_index) {
    Rng rng(seed, Stream::kTransient, std::uint64_t(view_index));
    const Vec3d eye = camera.center();
    const Vec3d forward = camera.rotation.row(2);
    const double fh = std::hypot(forward.x, forward.y);
    const Vec3d ahead{forward.x / fh, forward.y / fh, 0.0}, side{-ahead.y, ahead.x, 0.0};
    const Vec3d center = 0.5 * (landmark.bbox_lo + landmark.bbox_hi);
    const double to_landmark = std::hypot(center.x - eye.x, center.y - eye.y);
    const double half_width = 0.5 * camera.width / camera.fx;  // tan of the half horizontal field of view

    const int wanted = rng.uniform_int(2, 5);
    std::vector<Vec3d> placed;
    for (int attempt = 0; attempt < 40 && int(placed.size()) < wanted; ++attempt) {
        const double along = std::max(4.0, rng.uniform(0.15, 0.55) * to_landmark);
        const double across = rng.uniform(-0.8, 0.8) * along * half_width;
        const Vec3d p = eye + along * ahead + across * side;
        if (inside_footprint(landmark, p.x, p.y, 1.0)) continue;
        bool crowded = false;
        for (const Vec3d& q : placed) crowded = crowded || std::hypot(p.x - q.x, p.y - q.y) < 1.2;
        if (crowded) continue;
        placed.push_back(p);
        add_person(world, rng, p.x, p.y);
    }
    return int(placed.size());
}

}  // namespace lumigauss::synth
