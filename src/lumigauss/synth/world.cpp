#include "lumigauss/synth/world.h"

#include <algorithm>

namespace lumigauss::synth {

namespace {

// Cheap slab rejection against a primitive's bounds before the exact test.
bool may_hit(const Primitive& p, const Ray& ray, double t_max) {
    double t0 = 0, t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        const double inv = 1.0 / ray.dir[a];  // +-inf for axis-parallel rays is handled by IEEE rules
        double ta = (p.lo[a] - ray.origin[a]) * inv, tb = (p.hi[a] - ray.origin[a]) * inv;
        if (ta > tb) std::swap(ta, tb);
        if (!(tb >= t0) || !(ta <= t1)) {
            // NaN from 0 * inf (origin exactly on a slab plane of a flat primitive): be conservative.
            if (ta != ta || tb != tb) continue;
            return false;
        }
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    return true;
}

}  // namespace

std::optional<WorldHit> trace(const World& world, const Ray& ray, double t_max) {
    std::optional<WorldHit> best;
    double nearest = t_max;
    for (int i = 0; i < int(world.prims.size()); ++i) {
        const Primitive& p = world.prims[i];
        if (!may_hit(p, ray, nearest)) continue;
        if (auto h = intersect(p, ray, kRayEpsilon * 0.01, nearest)) {
            nearest = h->t;
            best = WorldHit{*h, i};
        }
    }
    return best;
}

bool occluded(const World& world, const Ray& ray, double t_max) {
    for (const Primitive& p : world.prims) {
        if (!may_hit(p, ray, t_max)) continue;
        if (intersect(p, ray, 0.0, t_max)) return true;
    }
    return false;
}

}  // namespace lumigauss::synth
