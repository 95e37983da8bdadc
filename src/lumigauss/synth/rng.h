#pragma once
// The scene generator's random streams: util/rng.h's generator, keyed by the purposes below so that the
// streams of different decisions never collide.
#include <cstdint>

#include "lumigauss/util/rng.h"

namespace lumigauss::synth {

using lumigauss::hash_keys;
using lumigauss::mix64;
using lumigauss::Rng;

// Purposes, so that streams for different decisions never collide.
enum class Stream : std::uint64_t {
    kScene = 1,
    kCondition,
    kCamera,
    kExposure,
    kAssignment,
    kTransient,
    kPixel,
    kPoint,
};

}  // namespace lumigauss::synth
