#pragma once
// What one photo sees: the landmark's primitives and materials plus that photo's pedestrians. Ray queries
// loop over every primitive with a bounding-box pre-test: the scenes hold well under a hundred primitives,
// so a BVH would not pay for itself.
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/synth/primitives.h"
#include "lumigauss/synth/texture.h"

namespace lumigauss::synth {

struct World {
    std::vector<Primitive> prims;
    std::vector<Material> materials;
};

// Offset that moves secondary rays off the surface they start on (metres; scenes are tens of metres).
inline constexpr double kRayEpsilon = 1e-4;

struct WorldHit {
    Hit hit;
    int prim = -1;
};

std::optional<WorldHit> trace(const World& world, const Ray& ray, double t_max = 1e30);

// Whether anything blocks the ray before t_max (shadow and visibility rays).
bool occluded(const World& world, const Ray& ray, double t_max = 1e30);

// The landmark: its static world (ground first) and the bounds of the building (ground excluded).
struct Landmark {
    std::string name;
    World world;
    Vec3d bbox_lo, bbox_hi;
    std::string description;
};

// The landmark scenes `synth` can build; throws Error for an unknown name.
Landmark build_landmark(const std::string& name);
std::vector<std::string> landmark_names();

}  // namespace lumigauss::synth
