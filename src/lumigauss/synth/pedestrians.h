#pragma once
// Transient occluders: a few "pedestrians" (a capsule-like body with a head, or a box) standing between
// the camera and the landmark in some training photos. They occlude, cast sun shadows, appear in the
// ground-truth geometry passes and in gt/transient, and are excluded by the static-scene masks.
#include <cstdint>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

// Adds 2 to 5 pedestrians for photo `view_index` to `world` (primitives flagged transient, with their own
// materials); returns how many were placed.
int add_pedestrians(World& world, const Landmark& landmark, const Camera& camera, std::uint64_t seed,
                    int view_index);

}  // namespace lumigauss::synth
