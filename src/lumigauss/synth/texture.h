#pragma once
// Procedural albedo textures of the synthetic landmarks. Purely diffuse materials whose albedo varies in
// space (bricks with mortar, stripes, value noise, paving tiles), so that an albedo recovered by a
// relighting method can be compared pixel by pixel with the ground truth.
#include "lumigauss/math/vec.h"

namespace lumigauss::synth {

enum class Pattern {
    kSolid,    // base colour
    kBricks,   // running-bond bricks of size (scale_u, scale_v), mortar lines of colour alt
    kTiles,    // square paving tiles (stack bond), joints of colour alt
    kStripes,  // alternating stripes along u of width scale_u (base, alt)
    kNoise,    // smooth value noise of feature size scale_u blending base and alt
};

struct Material {
    Pattern pattern = Pattern::kSolid;
    Vec3d base{0.5, 0.5, 0.5};
    Vec3d alt{0.5, 0.5, 0.5};
    double scale_u = 1.0;
    double scale_v = 1.0;
    double variation = 0.0;  // per-brick / per-tile random brightness variation (relative)
};

Material solid(Vec3d colour);
Material bricks(Vec3d brick, Vec3d mortar, double width, double height, double variation);
Material tiles(Vec3d tile, Vec3d joint, double size, double variation);
Material stripes(Vec3d a, Vec3d b, double width);
Material noise(Vec3d a, Vec3d b, double feature_size);

// Linear albedo in [0, 1] at surface coordinates (u, v) in metres.
Vec3d albedo_at(const Material& m, double u, double v);

}  // namespace lumigauss::synth
