#include "lumigauss/synth/texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

// A value in [0, 1) fixed for an integer lattice cell.
double cell_hash(std::int64_t i, std::int64_t j, std::uint64_t salt = 0) {
    return double(hash_keys(salt, std::uint64_t(i), std::uint64_t(j)) >> 11) * 0x1.0p-53;
}

Vec3d lerp(Vec3d a, Vec3d b, double t) {
    return a + t * (b - a);
}

Vec3d clamp01(Vec3d c) {
    return {std::clamp(c.x, 0.0, 1.0), std::clamp(c.y, 0.0, 1.0), std::clamp(c.z, 0.0, 1.0)};
}

// Bricks and tiles: a grid of cells (optionally offset by half a cell every other row) with joints.
Vec3d masonry(const Material& m, double u, double v, bool running_bond) {
    constexpr double kJoint = 0.06;  // joint width as a fraction of the cell height
    const double fv = v / m.scale_v;
    const double row = std::floor(fv);
    const double shift = running_bond && std::fmod(std::abs(row), 2.0) == 1.0 ? 0.5 : 0.0;
    const double fu = u / m.scale_u + shift;
    const double col = std::floor(fu);
    const double joint_u = kJoint * m.scale_v / m.scale_u;
    if (fv - row < kJoint || fu - col < joint_u) return m.alt;
    const double jitter = 1.0 + m.variation * (2.0 * cell_hash(std::int64_t(col), std::int64_t(row)) - 1.0);
    return clamp01(jitter * m.base);
}

double smooth_noise(double u, double v, std::uint64_t salt) {
    const double fu = std::floor(u), fv = std::floor(v);
    const double tu = u - fu, tv = v - fv;
    const double su = tu * tu * (3 - 2 * tu), sv = tv * tv * (3 - 2 * tv);
    const auto i = std::int64_t(fu), j = std::int64_t(fv);
    const double a = cell_hash(i, j, salt), b = cell_hash(i + 1, j, salt);
    const double c = cell_hash(i, j + 1, salt), d = cell_hash(i + 1, j + 1, salt);
    return (a + (b - a) * su) * (1 - sv) + (c + (d - c) * su) * sv;
}

}  // namespace

Material solid(Vec3d colour) {
    return {Pattern::kSolid, colour, colour, 1.0, 1.0, 0.0};
}

Material bricks(Vec3d brick, Vec3d mortar, double width, double height, double variation) {
    return {Pattern::kBricks, brick, mortar, width, height, variation};
}

Material tiles(Vec3d tile, Vec3d joint, double size, double variation) {
    return {Pattern::kTiles, tile, joint, size, size, variation};
}

Material stripes(Vec3d a, Vec3d b, double width) {
    return {Pattern::kStripes, a, b, width, width, 0.0};
}

Material noise(Vec3d a, Vec3d b, double feature_size) {
    return {Pattern::kNoise, a, b, feature_size, feature_size, 0.0};
}

Vec3d albedo_at(const Material& m, double u, double v) {
    switch (m.pattern) {
        case Pattern::kSolid:
            return m.base;
        case Pattern::kBricks:
            return masonry(m, u, v, true);
        case Pattern::kTiles:
            return masonry(m, u, v, false);
        case Pattern::kStripes:
            return std::fmod(std::abs(std::floor(u / m.scale_u)), 2.0) == 0.0 ? m.base : m.alt;
        case Pattern::kNoise: {
            const double s = 1.0 / m.scale_u;
            const double n =
                0.65 * smooth_noise(u * s, v * s, 17) + 0.35 * smooth_noise(3.1 * u * s, 3.1 * v * s, 29);
            return lerp(m.base, m.alt, n);
        }
    }
    return m.base;
}

}  // namespace lumigauss::synth
